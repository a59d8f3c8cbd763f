// The command recorder: batches dispatches and copies into one command buffer, inserts a
// barrier only where a dispatch touches a buffer an earlier unbarriered one wrote (or
// writes one it read), and brackets each labelled dispatch with GPU timestamps. The
// commands are kept and written into the command buffer at Submit, once the pipelines they
// bind have built (on the build threads, side by side, while the run recorded).
#pragma once

#include <volk.h>

#include <array>
#include <cstdint>
#include <functional>
#include <set>
#include <string>
#include <type_traits>
#include <vector>

namespace mcd::vk {

class Buffer;
class Context;
class Kernel;

enum class Access { Read, Write, ReadWrite };

// A buffer bound at `slot`: the slot's named constant in the kernel's layout header
// (shaders/<family>/<kernel>.h), never a bare position.
struct Binding {
    uint32_t slot = 0;
    const Buffer *buffer = nullptr;
    Access access = Access::Read;
};

// The push constants of a kernel that declares none.
struct NoPush {};

struct DispatchTiming {
    std::string label;
    double gpuMs = 0;    // negative when the device has no timestamps
    std::string kernel;  // KernelDesc::name
    // The buffers bound, each counted whole: a Read binding's bytes read once, a Write
    // binding's written once, a ReadWrite binding's both. The traffic of a kernel that
    // touches each bound element once; more than that of one that touches part of a buffer.
    uint64_t bytesRead = 0, bytesWritten = 0;
    std::array<uint32_t, 3> groups{};  // the workgroup grid
};

class Recorder {
  public:
    explicit Recorder(Context &context);
    ~Recorder();
    Recorder(const Recorder &) = delete;
    Recorder &operator=(const Recorder &) = delete;

    // Every slot the kernel declares must be bound exactly once; `push` is the kernel's
    // push-constant struct from its layout header, whose size must be the kernel's.
    template <typename Push>
    void Dispatch(const Kernel &kernel, const std::string &label,
                  const std::vector<Binding> &bindings, const Push &push, uint32_t groupsX,
                  uint32_t groupsY = 1, uint32_t groupsZ = 1) {
        static_assert(std::is_trivially_copyable_v<Push> && !std::is_pointer_v<Push>,
                      "push constants are the layout header's struct, passed by value");
        DispatchBytes(kernel, label, bindings, &push,
                      std::is_empty_v<Push> ? 0 : uint32_t(sizeof(Push)), groupsX, groupsY,
                      groupsZ);
    }
    void Copy(const Buffer &src, const Buffer &dst, VkDeviceSize bytes,
              VkDeviceSize srcOffset = 0, VkDeviceSize dstOffset = 0);

    // Submit everything recorded and wait; the recorder can then be reused.
    void Submit();

    size_t DispatchCount() const { return recorded.size(); }
    size_t BarrierCount() const { return barriers; }
    // Per-dispatch GPU times of the last Submit().
    const std::vector<DispatchTiming> &Timings() const { return timings; }
    double TotalGpuMs() const;

  private:
    void DispatchBytes(const Kernel &kernel, const std::string &label,
                       const std::vector<Binding> &bindings, const void *push,
                       uint32_t pushBytes, uint32_t groupsX, uint32_t groupsY,
                       uint32_t groupsZ);
    // The command that binds the kernel's pipeline (waiting for its build), its buffers (a
    // push descriptor set, or a set from the recorder's pools, written now) and its push
    // constants.
    std::function<void(VkCommandBuffer)> BindResources(const Kernel &kernel,
                                                       const std::vector<Binding> &bindings,
                                                       const void *push);
    VkDescriptorSet AllocateSet(const Kernel &kernel);
    void Begin();
    void Touch(const Buffer *buffer, Access access);
    void BarrierIfNeeded(const std::vector<std::pair<const Buffer *, Access>> &uses);

    Context &context;
    // The commands since Begin, written into commandBuffer at Submit.
    std::vector<std::function<void(VkCommandBuffer)>> commands;
    VkCommandBuffer commandBuffer = VK_NULL_HANDLE;
    VkQueryPool queryPool = VK_NULL_HANDLE;
    uint32_t queryCapacity = 0;
    std::vector<VkDescriptorPool> descriptorPools;
    uint32_t setsInPool = 0;
    bool recording = false;

    std::set<VkBuffer> writtenSinceBarrier, readSinceBarrier;
    std::vector<DispatchTiming> recorded;  // since Begin, their times filled by Submit
    // Their push constants and specialization (for KeepDispatches).
    std::vector<std::pair<std::vector<uint8_t>, const Kernel *>> pushes;
    size_t barriers = 0;
    std::vector<DispatchTiming> timings;
};

}  // namespace mcd::vk
