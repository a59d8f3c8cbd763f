// Work one run leaves for later runs on the same frame. auto runs several methods and
// variants, each twice (the run and its SURE probe), on one frame whose layers differ between
// those runs in the colour alone; some of their work depends on other layers only (rhf's
// selection masks, from the histograms) and is computed once. The owner (auto) keeps the
// memo for one frame; an entry's key names everything its work depends on.
#pragma once

#include <fmt/format.h>

#include <cstdint>
#include <cstring>
#include <map>
#include <memory>
#include <string>

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
    size_t Size() const { return entries.size(); }

  private:
    std::map<std::string, std::shared_ptr<void>> entries;
};

// An image's identity in a memo key: its shape and a 64-bit hash (FNV-1a over the words) of
// its values, for data a run made anew (a tile's crop) rather than by address.
inline std::string MemoImageId(const Image &image) {
    uint64_t hash = 0xcbf29ce484222325ull;
    for (float v : image.data) {
        uint32_t word;
        std::memcpy(&word, &v, sizeof(word));
        hash = (hash ^ word) * 0x100000001b3ull;
    }
    return fmt::format("{}x{}x{} {:016x}", image.width, image.height, image.channels, hash);
}

}  // namespace mcd
