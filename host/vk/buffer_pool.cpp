#include "host/vk/buffer_pool.h"

#include <algorithm>

namespace mcd::vk {

void DestroyPooled(VkDevice device, PooledBuffer &buffer) {
    if (buffer.mapped) vkUnmapMemory(device, buffer.memory);
    if (buffer.buffer) vkDestroyBuffer(device, buffer.buffer, nullptr);
    if (buffer.memory) vkFreeMemory(device, buffer.memory, nullptr);
    buffer = {};
}

BufferPool::~BufferPool() {
    Trim();
}

std::optional<PooledBuffer> BufferPool::Take(VkDeviceSize bytes) {
    std::lock_guard<std::mutex> lock(mutex);
    stats.liveBytes += bytes;
    // The most recently kept of this size: its pages are the likeliest still in cache.
    auto match = std::find_if(kept.rbegin(), kept.rend(),
                              [&](const PooledBuffer &b) { return b.bytes == bytes; });
    if (match != kept.rend()) {
        PooledBuffer found = *match;
        kept.erase(std::next(match).base());
        stats.keptBytes -= bytes;
        ++stats.reused;
        return found;
    }
    // A fresh allocation: free the least recently kept until everything held fits the most
    // the live buffers ever held.
    stats.highWater = std::max(stats.highWater, stats.liveBytes);
    while (!kept.empty() && stats.liveBytes + stats.keptBytes > stats.highWater) {
        stats.keptBytes -= kept.front().bytes;
        Free(kept.front());
        kept.pop_front();
    }
    ++stats.fresh;
    return std::nullopt;
}

void BufferPool::Forget(VkDeviceSize bytes) {
    std::lock_guard<std::mutex> lock(mutex);
    stats.liveBytes -= std::min(stats.liveBytes, bytes);
}

void BufferPool::Give(PooledBuffer buffer) {
    std::lock_guard<std::mutex> lock(mutex);
    stats.liveBytes -= std::min(stats.liveBytes, buffer.bytes);
    if (!keep) {
        Free(buffer);
        return;
    }
    stats.keptBytes += buffer.bytes;
    kept.push_back(buffer);
}

void BufferPool::Trim() {
    std::lock_guard<std::mutex> lock(mutex);
    for (PooledBuffer &buffer : kept) Free(buffer);
    kept.clear();
    stats.keptBytes = 0;
}

BufferPool::Stats BufferPool::GetStats() const {
    std::lock_guard<std::mutex> lock(mutex);
    return stats;
}

void BufferPool::Free(PooledBuffer &buffer) {
    DestroyPooled(device, buffer);
    ++stats.freed;
}

}  // namespace mcd::vk
