// Splitting a host loop over rows among the machine's cores.
#pragma once

#include <algorithm>
#include <cstddef>
#include <functional>

namespace mcd {

// Calls work(begin, end) on disjoint parts covering [0, n), each on its own thread, when
// `cost` (about the operations of the whole loop) pays for the threads; otherwise once
// over [0, n) on the calling thread. Each index is handled as in one serial loop, so the
// work's results do not depend on the split as long as no index reads what another one
// writes. `work` must not throw.
void ParallelFor(int n, size_t cost, const std::function<void(int, int)> &work);

// Calls work(begin, end) on disjoint ranges covering the values [0, n), in blocks split as
// ParallelFor splits them; `costPerValue` about the operations per value. Every range but
// the last is whole 64-bit words of a std::vector<bool>, so parts may write one.
inline void ParallelValues(size_t n, size_t costPerValue,
                           const std::function<void(size_t, size_t)> &work) {
    constexpr size_t kBlock = 4096;
    static_assert(kBlock % 64 == 0, "blocks split a std::vector<bool> at its words");
    const int blocks = int((n + kBlock - 1) / kBlock);
    ParallelFor(blocks, n * costPerValue, [&](int begin, int end) {
        work(size_t(begin) * kBlock, std::min(n, size_t(end) * kBlock));
    });
}

// std::memcpy(dst, src, bytes) split among the cores where it is large: a copy into memory
// first touched (a buffer's fresh pages) spends most of its time in the page faults, which
// the cores then take side by side. The regions must not overlap.
void ParallelCopy(void *dst, const void *src, size_t bytes);

// For tests: every ParallelFor while this lives splits into `parts` (at most n) parts,
// whatever the cost and the machine's cores; 0 restores the default.
class ForceParallelParts {
  public:
    explicit ForceParallelParts(int parts);
    ~ForceParallelParts();
    ForceParallelParts(const ForceParallelParts &) = delete;
    ForceParallelParts &operator=(const ForceParallelParts &) = delete;

  private:
    int previous;
};

}  // namespace mcd
