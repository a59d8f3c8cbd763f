// A compute kernel: pipeline built from embedded SPIR-V with specialization constants,
// a descriptor layout of N buffers (bindings 0..N-1: storage buffers, or read-only float
// texel buffers where the desc says so) and a push-constant block. The layouts are made at
// once; the pipeline on the context's build threads (Context::Builds), waited for by
// Pipeline(), or behind the builds asked for now where it is made ahead of its use.
#pragma once

#include <volk.h>

#include <cstddef>
#include <cstdint>
#include <future>
#include <string>
#include <utility>
#include <vector>

namespace mcd::vk {

class Context;

struct KernelDesc {
    std::string name;  // for errors, timings and the cache key
    const uint32_t *code = nullptr;
    size_t codeBytes = 0;
    uint32_t bindingCount = 0;  // buffers at bindings 0..bindingCount-1
    uint32_t pushBytes = 0;
    std::vector<std::pair<uint32_t, int32_t>> specialization;  // constant_id, value
    // Bit i set: binding i is a read-only uniform texel buffer of floats (samplerBuffer in
    // GLSL), not a storage buffer.
    uint32_t texelBindings = 0;
    // Bit i set (with its texel bit): binding i is read as vec4 texels (RGBA32F), one fetch
    // for four adjacent floats.
    uint32_t vec4Bindings = 0;
};

std::string KernelKey(const KernelDesc &desc);

class Kernel {
  public:
    // `ahead`: made before a run records it (Context::PrepareKernel), its build queued
    // behind the others until Hasten.
    Kernel(Context &context, const KernelDesc &desc, bool ahead = false);
    ~Kernel();
    Kernel(const Kernel &) = delete;
    Kernel &operator=(const Kernel &) = delete;

    const std::string &Name() const { return name; }
    // Made ahead of its use, and not yet asked for by a run.
    bool Ahead() const { return ahead; }
    // The build queued with the others asked for now, if it has not started.
    void Hasten();
    // Waits for the build (makes it here if no build thread has started it); throws its
    // error if it failed.
    VkPipeline Pipeline() const;
    VkPipelineLayout Layout() const { return layout; }
    VkDescriptorSetLayout SetLayout() const { return setLayout; }
    uint32_t BindingCount() const { return bindingCount; }
    uint32_t PushBytes() const { return pushBytes; }
    bool IsTexel(uint32_t binding) const { return (texelBindings >> binding) & 1u; }
    bool IsVec4(uint32_t binding) const { return (vec4Bindings >> binding) & 1u; }
    const std::vector<std::pair<uint32_t, int32_t>> &Specialization() const {
        return specialization;
    }

  private:
    void Build(std::vector<uint32_t> code);
    void Release();

    Context &context;
    std::string name;
    uint32_t bindingCount = 0, pushBytes = 0, texelBindings = 0, vec4Bindings = 0;
    std::vector<std::pair<uint32_t, int32_t>> specialization;  // constant_id, value
    VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
    VkPipelineLayout layout = VK_NULL_HANDLE;
    VkPipeline pipeline = VK_NULL_HANDLE;
    std::shared_future<void> built;
    uint64_t ticket = 0;
    bool ahead = false;
};

}  // namespace mcd::vk
