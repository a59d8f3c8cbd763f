// The command recorder: batches dispatches and copies into one command buffer, inserts a
// barrier only where a dispatch touches a buffer an earlier unbarriered one wrote (or
// writes one it read), and brackets each labelled dispatch with GPU timestamps.
#pragma once

#include <volk.h>

#include <cstdint>
#include <set>
#include <string>
#include <vector>

namespace mcd::vk {

class Buffer;
class Context;
class Kernel;

enum class Access { Read, Write, ReadWrite };

struct Binding {
    const Buffer *buffer = nullptr;
    Access access = Access::Read;
};

struct DispatchTiming {
    std::string label;
    double gpuMs = 0;  // negative when the device has no timestamps
};

class Recorder {
  public:
    explicit Recorder(Context &context);
    ~Recorder();
    Recorder(const Recorder &) = delete;
    Recorder &operator=(const Recorder &) = delete;

    // Bindings go to slots 0..n-1 in order; `push` is the kernel's push-constant struct.
    void Dispatch(const Kernel &kernel, const std::string &label,
                  const std::vector<Binding> &bindings, const void *push, uint32_t groupsX,
                  uint32_t groupsY = 1, uint32_t groupsZ = 1);
    void Copy(const Buffer &src, const Buffer &dst, VkDeviceSize bytes,
              VkDeviceSize srcOffset = 0, VkDeviceSize dstOffset = 0);

    // Submit everything recorded and wait; the recorder can then be reused.
    void Submit();

    size_t DispatchCount() const { return labels.size(); }
    size_t BarrierCount() const { return barriers; }
    // Per-dispatch GPU times of the last Submit().
    const std::vector<DispatchTiming> &Timings() const { return timings; }
    double TotalGpuMs() const;

  private:
    void Begin();
    void Touch(const Buffer *buffer, Access access);
    void BarrierIfNeeded(const std::vector<std::pair<const Buffer *, Access>> &uses);

    Context &context;
    VkCommandBuffer commandBuffer = VK_NULL_HANDLE;
    VkQueryPool queryPool = VK_NULL_HANDLE;
    uint32_t queryCapacity = 0;
    std::vector<VkDescriptorPool> descriptorPools;
    uint32_t setsInPool = 0;
    bool recording = false;

    std::set<VkBuffer> writtenSinceBarrier, readSinceBarrier;
    std::vector<std::string> labels;
    size_t barriers = 0;
    std::vector<DispatchTiming> timings;
};

}  // namespace mcd::vk
