#include "host/common/parallel.h"

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstring>
#include <thread>
#include <vector>

namespace mcd {
namespace {

std::atomic<int> forcedParts{0};

// Below this many operations a thread costs more than it saves.
constexpr size_t kMinCost = size_t(1) << 21;

}  // namespace

void ParallelFor(int n, size_t cost, const std::function<void(int, int)> &work) {
    if (n <= 0) return;
    int parts = forcedParts.load();
    if (parts <= 0) {
        parts = std::clamp(int(std::thread::hardware_concurrency()), 1, 8);
        if (cost < kMinCost) parts = 1;
    }
    parts = std::min(parts, n);
    std::vector<std::thread> threads;
    threads.reserve(size_t(parts));
    for (int t = 1; t < parts; ++t)
        threads.emplace_back(work, int(int64_t(n) * t / parts),
                             int(int64_t(n) * (t + 1) / parts));
    work(0, int(int64_t(n) / parts));
    for (std::thread &thread : threads) thread.join();
}

void ParallelCopy(void *dst, const void *src, size_t bytes) {
    // Blocks of 1 MiB: a thread faults a run of pages in order.
    constexpr size_t kBlock = size_t(1) << 20;
    const int blocks = int((bytes + kBlock - 1) / kBlock);
    ParallelFor(blocks, bytes / 4, [&](int begin, int end) {
        const size_t first = size_t(begin) * kBlock;
        const size_t last = std::min(bytes, size_t(end) * kBlock);
        std::memcpy(static_cast<char *>(dst) + first, static_cast<const char *>(src) + first,
                    last - first);
    });
}

ForceParallelParts::ForceParallelParts(int parts) : previous(forcedParts.exchange(parts)) {}

ForceParallelParts::~ForceParallelParts() {
    forcedParts.store(previous);
}

}  // namespace mcd
