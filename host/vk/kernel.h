// A compute kernel: pipeline built from embedded SPIR-V with specialization constants,
// a descriptor layout of N storage buffers (bindings 0..N-1) and a push-constant block.
#pragma once

#include <volk.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace mcd::vk {

class Context;

struct KernelDesc {
    std::string name;  // for errors, timings and the cache key
    const uint32_t *code = nullptr;
    size_t codeBytes = 0;
    uint32_t bindingCount = 0;  // storage buffers at bindings 0..bindingCount-1
    uint32_t pushBytes = 0;
    std::vector<std::pair<uint32_t, int32_t>> specialization;  // constant_id, value
};

std::string KernelKey(const KernelDesc &desc);

class Kernel {
  public:
    Kernel(Context &context, const KernelDesc &desc);
    ~Kernel();
    Kernel(const Kernel &) = delete;
    Kernel &operator=(const Kernel &) = delete;

    const std::string &Name() const { return name; }
    VkPipeline Pipeline() const { return pipeline; }
    VkPipelineLayout Layout() const { return layout; }
    VkDescriptorSetLayout SetLayout() const { return setLayout; }
    uint32_t BindingCount() const { return bindingCount; }
    uint32_t PushBytes() const { return pushBytes; }

  private:
    void Release();

    Context &context;
    std::string name;
    uint32_t bindingCount = 0, pushBytes = 0;
    VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
    VkPipelineLayout layout = VK_NULL_HANDLE;
    VkPipeline pipeline = VK_NULL_HANDLE;
};

}  // namespace mcd::vk
