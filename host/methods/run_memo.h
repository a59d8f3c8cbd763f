// Work one run leaves for later runs on the same frame. auto runs several methods and
// variants, each twice (the run and its SURE probe), on one frame whose layers differ between
// those runs in the colour alone; some of their work depends on other layers only (rhf's
// selection masks and the histograms' unusable values) or on the same colour twice (rhf's
// finest scale at one scale and at two) and is computed once. The owner (auto) keeps the
// memo for one frame; an entry's key names everything its work depends on.
#pragma once

#include <fmt/format.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "host/common/parallel.h"
#include "host/image.h"

namespace mcd {

class RunMemo {
  public:
    // The entry under `key`, or nullptr. The key's owner knows its type.
    template <class T>
    T *Find(const std::string &key) const {
        auto it = entries.find(key);
        return it == entries.end() ? nullptr : static_cast<T *>(it->second.get());
    }
    // Keep `entry` under `key` for the memo's life; returns it.
    template <class T>
    T &Add(const std::string &key, std::shared_ptr<T> entry) {
        T &kept = *entry;
        entries[key] = std::move(entry);
        return kept;
    }
    // Move `other`'s entries into this memo (one under a key this memo holds replaces it).
    void Merge(RunMemo &&other) {
        for (auto &entry : other.entries) entries[entry.first] = std::move(entry.second);
        other.entries.clear();
    }
    size_t Size() const { return entries.size(); }
    // How many entries' keys start with `prefix` (a kind of work, as its owner names it).
    size_t CountWithPrefix(const std::string &prefix) const {
        return size_t(std::count_if(entries.begin(), entries.end(), [&](const auto &entry) {
            return entry.first.compare(0, prefix.size(), prefix) == 0;
        }));
    }

  private:
    std::map<std::string, std::shared_ptr<void>> entries;
};

// FNV-1a's 64-bit offset basis and prime.
constexpr uint64_t kMemoHashBasis = 0xcbf29ce484222325ull, kMemoHashPrime = 0x100000001b3ull;

// The FNV-1a hash of `words`, four interleaved lanes (word i into lane i % 4) folded in
// order: the multiplies of the lanes overlap where one chain would wait on each.
inline uint64_t MemoWordsHash(const float *words, size_t n) {
    constexpr uint64_t kBasis = kMemoHashBasis, kPrime = kMemoHashPrime;
    uint64_t lane[4] = {kBasis, kBasis, kBasis, kBasis};
    size_t i = 0;
    for (; i + 4 <= n; i += 4)
        for (int k = 0; k < 4; ++k) {
            uint32_t word;
            std::memcpy(&word, words + i + k, sizeof(word));
            lane[k] = (lane[k] ^ word) * kPrime;
        }
    for (; i < n; ++i) {
        uint32_t word;
        std::memcpy(&word, words + i, sizeof(word));
        lane[0] = (lane[0] ^ word) * kPrime;
    }
    uint64_t hash = kBasis;
    for (uint64_t h : lane) hash = (hash ^ h) * kPrime;
    return hash;
}

// An image's identity in a memo key: its shape and a 64-bit hash of its values (blocks of
// words hashed by MemoWordsHash side by side, their hashes folded in order, so the same
// for any split among threads), for data a run made anew (a tile's crop) rather than by
// address.
inline std::string MemoImageId(const Image &image) {
    constexpr size_t kBlock = size_t(1) << 16;
    const size_t n = image.data.size(), blocks = (n + kBlock - 1) / kBlock;
    std::vector<uint64_t> hashes(blocks);
    ParallelFor(int(blocks), n * 2, [&](int begin, int end) {
        for (int b = begin; b < end; ++b) {
            const size_t first = size_t(b) * kBlock;
            hashes[size_t(b)] =
                MemoWordsHash(image.data.data() + first, std::min(kBlock, n - first));
        }
    });
    uint64_t hash = kMemoHashBasis;
    for (uint64_t h : hashes) hash = (hash ^ h) * kMemoHashPrime;
    return fmt::format("{}x{}x{} {:016x}", image.width, image.height, image.channels, hash);
}

}  // namespace mcd
