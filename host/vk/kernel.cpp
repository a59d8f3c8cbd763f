#include "host/vk/kernel.h"

#include <fmt/format.h>

#include <chrono>
#include <cstring>

#include "host/vk/check.h"
#include "host/vk/context.h"

namespace mcd::vk {

std::string KernelKey(const KernelDesc &desc) {
    std::string key = fmt::format("{}@{}", desc.name, static_cast<const void *>(desc.code));
    for (auto [id, value] : desc.specialization) key += fmt::format(":{}={}", id, value);
    if (desc.texelBindings) key += fmt::format(":texel={:x}", desc.texelBindings);
    if (desc.vec4Bindings) key += fmt::format(":vec4={:x}", desc.vec4Bindings);
    return key;
}

Kernel::Kernel(Context &context, const KernelDesc &desc, bool ahead)
    : context(context),
      name(desc.name),
      bindingCount(desc.bindingCount),
      pushBytes(desc.pushBytes),
      texelBindings(desc.texelBindings),
      vec4Bindings(desc.vec4Bindings),
      specialization(desc.specialization),
      ahead(ahead) {
    VkDevice device = context.Device();
    if (pushBytes > context.Limits().maxPushConstantsSize)
        throw Error(fmt::format("kernel {}: {} bytes of push constants exceed the device's {}",
                                name, pushBytes, context.Limits().maxPushConstantsSize),
                    ErrorKind::Device);
    try {
        std::vector<VkDescriptorSetLayoutBinding> bindings(bindingCount);
        for (uint32_t i = 0; i < bindingCount; ++i) {
            bindings[i].binding = i;
            bindings[i].descriptorType = IsTexel(i) ? VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER
                                                    : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
            bindings[i].descriptorCount = 1;
            bindings[i].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
        }
        VkDescriptorSetLayoutCreateInfo li{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
        if (context.Info().pushDescriptors)
            li.flags = VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR;
        li.bindingCount = bindingCount;
        li.pBindings = bindings.data();
        MCD_VK(vkCreateDescriptorSetLayout(device, &li, nullptr, &setLayout));

        VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, pushBytes};
        VkPipelineLayoutCreateInfo pli{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
        pli.setLayoutCount = 1;
        pli.pSetLayouts = &setLayout;
        pli.pushConstantRangeCount = pushBytes > 0 ? 1 : 0;
        pli.pPushConstantRanges = &range;
        MCD_VK(vkCreatePipelineLayout(device, &pli, nullptr, &layout));
    } catch (...) {
        Release();
        throw;
    }
    // The SPIR-V copied: the build may outlive the caller's blob.
    std::vector<uint32_t> code((desc.codeBytes + 3) / 4);
    if (desc.codeBytes > 0) std::memcpy(code.data(), desc.code, desc.codeBytes);
    built = context.Builds().Run(
        [this, code = std::move(code)]() mutable { Build(std::move(code)); }, ahead, &ticket);
}

void Kernel::Hasten() {
    if (ahead) context.Builds().Hasten(ticket);
    ahead = false;
}

void Kernel::Build(std::vector<uint32_t> code) {
    VkDevice device = context.Device();
    VkShaderModuleCreateInfo mi{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    mi.codeSize = code.size() * sizeof(uint32_t);
    mi.pCode = code.data();
    VkShaderModule module = VK_NULL_HANDLE;
    MCD_VK(vkCreateShaderModule(device, &mi, nullptr, &module));
    std::vector<VkSpecializationMapEntry> entries;
    std::vector<int32_t> values;
    for (auto [id, value] : specialization) {
        entries.push_back({id, uint32_t(values.size() * sizeof(int32_t)), sizeof(int32_t)});
        values.push_back(value);
    }
    VkSpecializationInfo si{uint32_t(entries.size()), entries.data(),
                            values.size() * sizeof(int32_t), values.data()};
    VkComputePipelineCreateInfo ci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    ci.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    ci.stage.module = module;
    ci.stage.pName = "main";
    ci.stage.pSpecializationInfo = entries.empty() ? nullptr : &si;
    ci.layout = layout;
    auto start = std::chrono::steady_clock::now();
    VkResult result =
        vkCreateComputePipelines(device, context.PipelineCache(), 1, &ci, nullptr, &pipeline);
    context.NotePipelineBuilt(
        name, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    vkDestroyShaderModule(device, module, nullptr);
    if (result != VK_SUCCESS) {
        pipeline = VK_NULL_HANDLE;
        ThrowVkError(result, fmt::format("vkCreateComputePipelines({})", name).c_str(),
                     __FILE__, __LINE__);
    }
}

VkPipeline Kernel::Pipeline() const {
    // Once built, no lookup: a bind neither locks the pool nor scans its queues.
    if (ticket && built.wait_for(std::chrono::seconds(0)) != std::future_status::ready)
        context.Builds().RunHere(ticket);
    built.get();
    return pipeline;
}

Kernel::~Kernel() {
    // A build no thread has started is dropped, not made: a run failed or cancelled after
    // preparing kernels does not hold up the context's teardown for builds it will not use.
    if (ticket) context.Builds().Drop(ticket);
    if (built.valid()) built.wait();
    Release();
}

void Kernel::Release() {
    VkDevice device = context.Device();
    if (pipeline) vkDestroyPipeline(device, pipeline, nullptr);
    if (layout) vkDestroyPipelineLayout(device, layout, nullptr);
    if (setLayout) vkDestroyDescriptorSetLayout(device, setLayout, nullptr);
    pipeline = VK_NULL_HANDLE;
    layout = VK_NULL_HANDLE;
    setLayout = VK_NULL_HANDLE;
}

}  // namespace mcd::vk
