#include "host/vk/recorder.h"

#include <fmt/format.h>

#include "host/vk/buffer.h"
#include "host/vk/check.h"
#include "host/vk/context.h"
#include "host/vk/dispatch_count.h"
#include "host/vk/kernel.h"

namespace mcd::vk {
namespace {

constexpr uint32_t kMaxTimedDispatches = 4096;
constexpr uint32_t kSetsPerPool = 256;
// pivot.ratio: 7 buffers and a packed z, s, nu per channel (PIVOT_MAX_CHANNELS).
constexpr uint32_t kMaxBindings = 11;

}  // namespace

Recorder::Recorder(Context &context) : context(context) {}

Recorder::~Recorder() {
    VkDevice device = context.Device();
    if (commandBuffer) context.FreeCommandBuffer(commandBuffer);
    if (queryPool) vkDestroyQueryPool(device, queryPool, nullptr);
    for (VkDescriptorPool pool : descriptorPools)
        vkDestroyDescriptorPool(device, pool, nullptr);
}

void Recorder::Begin() {
    if (recording) return;
    if (context.Info().timestamps && !queryPool) {
        VkQueryPoolCreateInfo qi{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
        qi.queryType = VK_QUERY_TYPE_TIMESTAMP;
        qi.queryCount = 2 * kMaxTimedDispatches;
        MCD_VK(vkCreateQueryPool(context.Device(), &qi, nullptr, &queryPool));
        queryCapacity = kMaxTimedDispatches;
    }
    recording = true;
    commands.clear();
    recorded.clear();
    pushes.clear();
    barriers = 0;
    writtenSinceBarrier.clear();
    readSinceBarrier.clear();
}

void Recorder::BarrierIfNeeded(const std::vector<std::pair<const Buffer *, Access>> &uses) {
    bool hazard = false;
    for (auto [buffer, access] : uses) {
        VkBuffer handle = buffer->Handle();
        if (writtenSinceBarrier.count(handle)) hazard = true;  // RAW, WAW
        if (access != Access::Read && readSinceBarrier.count(handle)) hazard = true;  // WAR
    }
    if (!hazard) return;
    commands.push_back([](VkCommandBuffer cb) {
        VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
        barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
        barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT |
                                VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
        VkPipelineStageFlags stages =
            VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT;
        vkCmdPipelineBarrier(cb, stages, stages, 0, 1, &barrier, 0, nullptr, 0, nullptr);
    });
    ++barriers;
    writtenSinceBarrier.clear();
    readSinceBarrier.clear();
}

void Recorder::Touch(const Buffer *buffer, Access access) {
    if (access != Access::Write) readSinceBarrier.insert(buffer->Handle());
    if (access != Access::Read) writtenSinceBarrier.insert(buffer->Handle());
}

namespace {

// Every declared slot bound once: a slot bound twice or left out would read a stale buffer.
void CheckSlots(const Kernel &kernel, const std::string &label,
                const std::vector<Binding> &bindings) {
    std::vector<bool> bound(kernel.BindingCount(), false);
    for (const Binding &b : bindings) {
        if (b.slot >= kernel.BindingCount())
            throw Error(fmt::format("dispatch '{}': kernel {} has no binding slot {} (it "
                                    "declares {})",
                                    label, kernel.Name(), b.slot, kernel.BindingCount()),
                        ErrorKind::Internal);
        if (bound[b.slot])
            throw Error(fmt::format("dispatch '{}': kernel {}: slot {} is bound twice", label,
                                    kernel.Name(), b.slot),
                        ErrorKind::Internal);
        bound[b.slot] = true;
    }
    for (uint32_t slot = 0; slot < kernel.BindingCount(); ++slot)
        if (!bound[slot])
            throw Error(fmt::format("dispatch '{}': kernel {} takes {} buffers: slot {} is not "
                                    "bound",
                                    label, kernel.Name(), kernel.BindingCount(), slot),
                        ErrorKind::Internal);
    if (bindings.size() > kMaxBindings)
        throw Error(fmt::format("dispatch '{}': kernel {} takes {} buffers, more than the "
                                "recorder's {}",
                                label, kernel.Name(), bindings.size(), kMaxBindings),
                    ErrorKind::Internal);
}

// Each bound buffer exists, a texel binding is read only, and a storage binding fits the
// device's range.
void CheckBuffers(const Kernel &kernel, const std::string &label,
                  const std::vector<Binding> &bindings, const VkPhysicalDeviceLimits &limits) {
    for (const Binding &b : bindings) {
        if (!b.buffer || !b.buffer->Valid())
            throw Error(fmt::format("dispatch '{}': kernel {}: slot {} has no buffer", label,
                                    kernel.Name(), b.slot),
                        ErrorKind::Internal);
        if (kernel.IsTexel(b.slot) && b.access != Access::Read)
            throw Error(fmt::format("dispatch '{}': binding {} of kernel {} is a texel buffer, "
                                    "which kernels only read",
                                    label, b.slot, kernel.Name()),
                        ErrorKind::Internal);
        // Texel views have their own limit, checked when the view is made.
        if (!kernel.IsTexel(b.slot) && b.buffer->Bytes() > limits.maxStorageBufferRange)
            throw Error(fmt::format("dispatch '{}': buffer '{}' of {} bytes exceeds the "
                                    "device's storage buffer "
                                    "range of {} bytes; split the work",
                                    label, b.buffer->Name(), b.buffer->Bytes(),
                                    limits.maxStorageBufferRange),
                        ErrorKind::OutOfMemory);
    }
}

// The push constants' size, the slots, the grid and the buffers, before anything is
// recorded.
void CheckDispatch(const Kernel &kernel, const std::string &label,
                   const std::vector<Binding> &bindings, uint32_t pushBytes,
                   const uint32_t (&groups)[3], const VkPhysicalDeviceLimits &limits) {
    if (pushBytes != kernel.PushBytes())
        throw Error(fmt::format("dispatch '{}': kernel {} takes {} bytes of push constants, "
                                "got a struct of {}",
                                label, kernel.Name(), kernel.PushBytes(), pushBytes),
                    ErrorKind::Internal);
    CheckSlots(kernel, label, bindings);
    for (int i = 0; i < 3; ++i)
        if (groups[i] > limits.maxComputeWorkGroupCount[i])
            throw Error(
                fmt::format(
                    "dispatch '{}': {} workgroups along axis {} exceed the device limit {}",
                    label, groups[i], i, limits.maxComputeWorkGroupCount[i]),
                ErrorKind::OutOfMemory);
    CheckBuffers(kernel, label, bindings, limits);
}

}  // namespace

VkDescriptorSet Recorder::AllocateSet(const Kernel &kernel) {
    if (descriptorPools.empty() || setsInPool == kSetsPerPool) {
        VkDescriptorPoolSize sizes[2] = {
            {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, kSetsPerPool * kMaxBindings},
            {VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, kSetsPerPool * kMaxBindings}};
        VkDescriptorPoolCreateInfo pi{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
        pi.maxSets = kSetsPerPool;
        pi.poolSizeCount = 2;
        pi.pPoolSizes = sizes;
        VkDescriptorPool pool = VK_NULL_HANDLE;
        MCD_VK(vkCreateDescriptorPool(context.Device(), &pi, nullptr, &pool));
        descriptorPools.push_back(pool);
        setsInPool = 0;
    }
    VkDescriptorSetLayout setLayout = kernel.SetLayout();
    VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    ai.descriptorPool = descriptorPools.back();
    ai.descriptorSetCount = 1;
    ai.pSetLayouts = &setLayout;
    VkDescriptorSet set = VK_NULL_HANDLE;
    MCD_VK(vkAllocateDescriptorSets(context.Device(), &ai, &set));
    ++setsInPool;
    return set;
}

std::function<void(VkCommandBuffer)> Recorder::BindResources(
    const Kernel &kernel, const std::vector<Binding> &bindings, const void *push) {
    std::vector<VkDescriptorBufferInfo> infos(bindings.size());
    std::vector<VkWriteDescriptorSet> writes(bindings.size());
    std::vector<VkBufferView> views(bindings.size(), VK_NULL_HANDLE);
    for (uint32_t i = 0; i < bindings.size(); ++i) {
        writes[i] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
        writes[i].dstBinding = bindings[i].slot;
        writes[i].descriptorCount = 1;
        if (kernel.IsTexel(bindings[i].slot)) {
            views[i] = kernel.IsVec4(bindings[i].slot) ? bindings[i].buffer->Vec4View()
                                                       : bindings[i].buffer->FloatView();
            writes[i].descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
        } else {
            infos[i] = {bindings[i].buffer->Handle(), 0, VK_WHOLE_SIZE};
            writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        }
    }
    // The writes point into infos and views where they are used (the vectors move).
    auto point = [](std::vector<VkWriteDescriptorSet> &writes,
                    std::vector<VkDescriptorBufferInfo> &infos,
                    std::vector<VkBufferView> &views) {
        for (size_t i = 0; i < writes.size(); ++i) {
            bool texel = writes[i].descriptorType == VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
            writes[i].pTexelBufferView = texel ? &views[i] : nullptr;
            writes[i].pBufferInfo = texel ? nullptr : &infos[i];
        }
    };
    VkDescriptorSet set = VK_NULL_HANDLE;
    if (!context.Info().pushDescriptors) {
        set = AllocateSet(kernel);
        point(writes, infos, views);
        for (VkWriteDescriptorSet &w : writes) w.dstSet = set;
        vkUpdateDescriptorSets(context.Device(), uint32_t(writes.size()), writes.data(), 0,
                               nullptr);
    }
    const uint8_t *pushed = static_cast<const uint8_t *>(push);
    std::vector<uint8_t> constants(pushed, pushed + kernel.PushBytes());
    return [bind = &kernel, set, point, writes = std::move(writes), infos = std::move(infos),
            views = std::move(views),
            constants = std::move(constants)](VkCommandBuffer cb) mutable {
        vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, bind->Pipeline());
        if (set == VK_NULL_HANDLE) {
            point(writes, infos, views);
            vkCmdPushDescriptorSetKHR(cb, VK_PIPELINE_BIND_POINT_COMPUTE, bind->Layout(), 0,
                                      uint32_t(writes.size()), writes.data());
        } else {
            vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, bind->Layout(), 0, 1,
                                    &set, 0, nullptr);
        }
        if (!constants.empty())
            vkCmdPushConstants(cb, bind->Layout(), VK_SHADER_STAGE_COMPUTE_BIT, 0,
                               uint32_t(constants.size()), constants.data());
    };
}

void Recorder::DispatchBytes(const Kernel &kernel, const std::string &label,
                             const std::vector<Binding> &bindings, const void *push,
                             uint32_t pushBytes, uint32_t groupsX, uint32_t groupsY,
                             uint32_t groupsZ) {
    CheckDispatch(kernel, label, bindings, pushBytes, {groupsX, groupsY, groupsZ},
                  context.Limits());
    Begin();
    if (groupsX == 0 || groupsY == 0 || groupsZ == 0) return;
    CountDispatch(kernel.Name());

    std::vector<std::pair<const Buffer *, Access>> uses;
    for (const Binding &b : bindings) uses.push_back({b.buffer, b.access});
    BarrierIfNeeded(uses);
    uint32_t slot = uint32_t(recorded.size());
    bool timed = queryPool && slot < queryCapacity;
    commands.push_back([bind = BindResources(kernel, bindings, push), timed, slot,
                        queryPool = queryPool, groupsX, groupsY,
                        groupsZ](VkCommandBuffer cb) mutable {
        bind(cb);
        if (timed)
            vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, queryPool, 2 * slot);
        vkCmdDispatch(cb, groupsX, groupsY, groupsZ);
        if (timed)
            vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, queryPool,
                                2 * slot + 1);
    });
    // The traffic of the buffers bound, each whole, and what KeepDispatches keeps.
    DispatchTiming record{label, -1, kernel.Name(), 0, 0, {groupsX, groupsY, groupsZ}};
    for (const Binding &b : bindings) {
        if (b.access != Access::Write) record.bytesRead += b.buffer->Bytes();
        if (b.access != Access::Read) record.bytesWritten += b.buffer->Bytes();
    }
    recorded.push_back(std::move(record));
    const uint8_t *pushed = static_cast<const uint8_t *>(push);
    pushes.push_back({std::vector<uint8_t>(pushed, pushed + pushBytes), &kernel});
    for (auto [buffer, access] : uses) Touch(buffer, access);
}

void Recorder::Copy(const Buffer &src, const Buffer &dst, VkDeviceSize bytes,
                    VkDeviceSize srcOffset, VkDeviceSize dstOffset) {
    if (srcOffset + bytes > src.Bytes() || dstOffset + bytes > dst.Bytes())
        throw Error(fmt::format("copy of {} bytes from '{}' to '{}' overruns a buffer", bytes,
                                src.Name(), dst.Name()),
                    ErrorKind::Internal);
    Begin();
    if (bytes == 0) return;
    BarrierIfNeeded({{&src, Access::Read}, {&dst, Access::Write}});
    VkBufferCopy region{srcOffset, dstOffset, bytes};
    commands.push_back([region, from = src.Handle(), to = dst.Handle()](VkCommandBuffer cb) {
        vkCmdCopyBuffer(cb, from, to, 1, &region);
    });
    Touch(&src, Access::Read);
    Touch(&dst, Access::Write);
}

void Recorder::Submit() {
    timings.clear();
    if (!recording) return;
    recording = false;
    if (!commandBuffer) commandBuffer = context.AllocateCommandBuffer();
    MCD_VK(vkResetCommandBuffer(commandBuffer, 0));
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    MCD_VK(vkBeginCommandBuffer(commandBuffer, &bi));
    if (queryPool) vkCmdResetQueryPool(commandBuffer, queryPool, 0, 2 * queryCapacity);
    // Binding a pipeline waits for its build.
    for (const auto &command : commands) command(commandBuffer);
    commands.clear();
    MCD_VK(vkEndCommandBuffer(commandBuffer));
    context.SubmitAndWait(commandBuffer);
    uint32_t timed = queryPool ? uint32_t(std::min<size_t>(recorded.size(), queryCapacity)) : 0;
    std::vector<uint64_t> stamps(2 * size_t(timed));
    if (timed > 0)
        MCD_VK(vkGetQueryPoolResults(context.Device(), queryPool, 0, 2 * timed,
                                     stamps.size() * sizeof(uint64_t), stamps.data(),
                                     sizeof(uint64_t),
                                     VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
    double period = context.Limits().timestampPeriod;
    bool keep = KeepingDispatches();
    for (size_t i = 0; i < recorded.size(); ++i) {
        if (i < timed)
            recorded[i].gpuMs = double(stamps[2 * i + 1] - stamps[2 * i]) * period * 1e-6;
        timings.push_back(recorded[i]);
        if (keep)
            KeepDispatch(
                {recorded[i], std::move(pushes[i].first), pushes[i].second->Specialization()});
    }
    for (VkDescriptorPool pool : descriptorPools)
        vkResetDescriptorPool(context.Device(), pool, 0);
    if (!descriptorPools.empty()) {
        for (size_t i = 1; i < descriptorPools.size(); ++i)
            vkDestroyDescriptorPool(context.Device(), descriptorPools[i], nullptr);
        descriptorPools.resize(1);
    }
    setsInPool = 0;
}

double Recorder::TotalGpuMs() const {
    double total = 0;
    for (const DispatchTiming &t : timings) total += t.gpuMs > 0 ? t.gpuMs : 0;
    return total;
}

}  // namespace mcd::vk
