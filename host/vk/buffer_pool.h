// Freed buffers kept for the next buffer of the same size. Fresh device memory is faulted
// and zeroed page by page the first time a kernel writes it (lavapipe maps each allocation
// anew, a discrete driver clears it), and a run frees and allocates buffers of the same
// sizes over and over (candidates, tiles, strips). The pool never makes the context hold
// more than the most its live buffers ever held together: before a fresh allocation it
// frees kept buffers, least recently kept first, until the kept, the live and the new
// bytes fit that mark. No kernel may rely on what a buffer holds before it writes it: a
// reused buffer holds what its last user left (Vulkan promises fresh memory no contents
// either); ContextOptions::poisonBuffers fills every buffer handed out with NaN to check.
#pragma once

#include <volk.h>

#include <cstddef>
#include <deque>
#include <mutex>
#include <optional>

namespace mcd::vk {

// A buffer and its own memory, mapped when its memory is host-visible and mapping is used.
struct PooledBuffer {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    void *mapped = nullptr;
    VkDeviceSize bytes = 0;  // the allocation's size, the key of reuse
};

class BufferPool {
  public:
    struct Stats {
        size_t fresh = 0, reused = 0, freed = 0;
        VkDeviceSize liveBytes = 0, keptBytes = 0, highWater = 0;
    };

    // Off: every Give frees at once (the pool only counts).
    explicit BufferPool(bool keep = true) : keep(keep) {}
    BufferPool(const BufferPool &) = delete;
    BufferPool &operator=(const BufferPool &) = delete;
    ~BufferPool();

    // Set the device whose buffers the pool frees (before the first Take).
    void SetDevice(VkDevice device) { this->device = device; }
    void SetKeep(bool keep) { this->keep = keep; }
    // A kept buffer of exactly `bytes`, most recently kept first; nullopt: the caller
    // allocates a fresh one, for which room has been made (kept buffers freed as needed).
    // Either way the bytes count as live until Give.
    std::optional<PooledBuffer> Take(VkDeviceSize bytes);
    // A fresh allocation the caller could not make after all: no longer live.
    void Forget(VkDeviceSize bytes);
    // A buffer no longer used (no submission in flight reads it): kept, or freed when the
    // pool is off.
    void Give(PooledBuffer buffer);
    // Free every kept buffer (the context's end, or memory wanted elsewhere).
    void Trim();
    Stats GetStats() const;

  private:
    void Free(PooledBuffer &buffer);

    VkDevice device = VK_NULL_HANDLE;
    bool keep = true;
    mutable std::mutex mutex;
    std::deque<PooledBuffer> kept;  // least recently kept at the front
    Stats stats;
};

// Free a buffer and its memory (unmapping it first).
void DestroyPooled(VkDevice device, PooledBuffer &buffer);

}  // namespace mcd::vk
