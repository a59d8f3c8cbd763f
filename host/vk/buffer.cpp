#include "host/vk/buffer.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstring>
#include <utility>

#include "host/common/parallel.h"
#include "host/vk/check.h"
#include "host/vk/context.h"

namespace mcd::vk {
namespace {

struct RawBuffer {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    bool hostVisible = false;
};

RawBuffer CreateRaw(Context &context, VkDeviceSize bytes, VkBufferUsageFlags usage,
                    VkMemoryPropertyFlags required, VkMemoryPropertyFlags preferred,
                    VkMemoryPropertyFlags avoided = 0) {
    RawBuffer raw;
    VkBufferCreateInfo bi{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    bi.size = bytes;
    bi.usage = usage;
    bi.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    MCD_VK(vkCreateBuffer(context.Device(), &bi, nullptr, &raw.buffer));
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(context.Device(), raw.buffer, &req);
    VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    ai.allocationSize = req.size;
    try {
        ai.memoryTypeIndex =
            context.FindMemoryType(req.memoryTypeBits, required, preferred, avoided);
        MCD_VK(vkAllocateMemory(context.Device(), &ai, nullptr, &raw.memory));
        MCD_VK(vkBindBufferMemory(context.Device(), raw.buffer, raw.memory, 0));
    } catch (...) {
        if (raw.memory) vkFreeMemory(context.Device(), raw.memory, nullptr);
        vkDestroyBuffer(context.Device(), raw.buffer, nullptr);
        throw;
    }
    VkPhysicalDeviceMemoryProperties props;
    vkGetPhysicalDeviceMemoryProperties(context.PhysicalDevice(), &props);
    raw.hostVisible = props.memoryTypes[ai.memoryTypeIndex].propertyFlags &
                      VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    return raw;
}

void DestroyRaw(Context &context, RawBuffer &raw) {
    if (raw.buffer) vkDestroyBuffer(context.Device(), raw.buffer, nullptr);
    if (raw.memory) vkFreeMemory(context.Device(), raw.memory, nullptr);
    raw = {};
}

// A fresh device buffer of allocBytes, mapped when its memory is host-visible and the
// context maps buffers.
PooledBuffer CreateDeviceBuffer(Context &context, VkDeviceSize allocBytes) {
    // Unified memory (CPU devices, integrated GPUs): map device memory directly. Discrete
    // GPUs: plain VRAM, not the small host-visible BAR window, and stage transfers.
    VkPhysicalDeviceType type = context.Info().type;
    bool unified =
        type == VK_PHYSICAL_DEVICE_TYPE_CPU || type == VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU;
    VkMemoryPropertyFlags preferred = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
    if (unified)
        preferred |= VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    RawBuffer raw = CreateRaw(
        context, allocBytes,
        VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT |
            VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
        0, preferred, unified ? 0 : VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT);
    PooledBuffer made{raw.buffer, raw.memory, nullptr, allocBytes};
    if (raw.hostVisible && !context.StagesTransfers()) {
        try {
            MCD_VK(
                vkMapMemory(context.Device(), made.memory, 0, VK_WHOLE_SIZE, 0, &made.mapped));
        } catch (...) {
            DestroyPooled(context.Device(), made);
            throw;
        }
    }
    return made;
}

// A buffer of allocBytes from the pool, or fresh; when the device is out of memory with
// buffers kept, they are freed and the allocation tried again.
PooledBuffer TakeBuffer(Context &context, VkDeviceSize allocBytes) {
    BufferPool &pool = context.Pool();
    if (std::optional<PooledBuffer> kept = pool.Take(allocBytes)) return *kept;
    try {
        try {
            return CreateDeviceBuffer(context, allocBytes);
        } catch (const Error &e) {
            if (e.Kind() != ErrorKind::OutOfMemory || pool.GetStats().keptBytes == 0) throw;
            pool.Trim();
            return CreateDeviceBuffer(context, allocBytes);
        }
    } catch (...) {
        pool.Forget(allocBytes);
        throw;
    }
}

}  // namespace

Buffer::Buffer(Context &context, VkDeviceSize bytes, std::string name)
    : context(&context), bytes(bytes), name(std::move(name)) {
    // Zero-sized buffers are invalid in Vulkan; keep one word so empty images still bind.
    // The buffer itself is whole vec4 texels, so that any buffer binds as a vec4 view.
    PooledBuffer taken = TakeBuffer(context, AllocBytes());
    buffer = taken.buffer;
    memory = taken.memory;
    mapped = taken.mapped;
    context.NoteAllocation(this->name, bytes > 0 ? bytes : 4);
    if (context.PoisonsBuffers()) {
        try {
            Poison();
        } catch (...) {
            Release();
            throw;
        }
    }
}

void Buffer::Poison() {
    if (mapped) {
        std::memset(mapped, 0xff, AllocBytes());
        return;
    }
    context->SubmitAndWait([&](VkCommandBuffer cb) {
        vkCmdFillBuffer(cb, buffer, 0, VK_WHOLE_SIZE, 0xffffffffu);
    });
}

Buffer::~Buffer() {
    Release();
}

Buffer::Buffer(Buffer &&other) noexcept {
    *this = std::move(other);
}

Buffer &Buffer::operator=(Buffer &&other) noexcept {
    if (this != &other) {
        Release();
        context = std::exchange(other.context, nullptr);
        buffer = std::exchange(other.buffer, VK_NULL_HANDLE);
        memory = std::exchange(other.memory, VK_NULL_HANDLE);
        bytes = std::exchange(other.bytes, 0);
        mapped = std::exchange(other.mapped, nullptr);
        floatView = std::exchange(other.floatView, VK_NULL_HANDLE);
        vec4View = std::exchange(other.vec4View, VK_NULL_HANDLE);
        name = std::move(other.name);
    }
    return *this;
}

void Buffer::Release() {
    if (!context) return;
    if (buffer) context->NoteRelease(bytes > 0 ? bytes : 4);
    // Views are made for this buffer's size in bytes: the next user makes its own.
    if (floatView) vkDestroyBufferView(context->Device(), floatView, nullptr);
    if (vec4View) vkDestroyBufferView(context->Device(), vec4View, nullptr);
    if (buffer) context->Pool().Give({buffer, memory, mapped, AllocBytes()});
    buffer = VK_NULL_HANDLE;
    memory = VK_NULL_HANDLE;
    mapped = nullptr;
    floatView = VK_NULL_HANDLE;
    vec4View = VK_NULL_HANDLE;
    context = nullptr;
}

VkBufferView Buffer::FloatView() const {
    return View(VK_FORMAT_R32_SFLOAT, 1, "floats", floatView);
}

VkBufferView Buffer::Vec4View() const {
    // The allocation is rounded up to whole texels (the constructor).
    return View(VK_FORMAT_R32G32B32A32_SFLOAT, 4, "vec4 texels", vec4View);
}

VkBufferView Buffer::View(VkFormat format, int floatsPerTexel, const char *unit,
                          VkBufferView &view) const {
    if (view || !buffer) return view;
    VkDeviceSize texelBytes = floatsPerTexel * sizeof(float);
    VkDeviceSize elements = std::max<VkDeviceSize>((bytes + texelBytes - 1) / texelBytes, 1);
    if (elements > context->Limits().maxTexelBufferElements)
        throw Error(fmt::format("buffer '{}' of {} {} exceeds the device's {} texel buffer "
                                "elements; split the work",
                                name, elements, unit, context->Limits().maxTexelBufferElements),
                    ErrorKind::OutOfMemory);
    VkBufferViewCreateInfo vi{VK_STRUCTURE_TYPE_BUFFER_VIEW_CREATE_INFO};
    vi.buffer = buffer;
    vi.format = format;
    vi.offset = 0;
    vi.range = elements * texelBytes;
    MCD_VK(vkCreateBufferView(context->Device(), &vi, nullptr, &view));
    return view;
}

void Buffer::Upload(const void *data, size_t byteCount, size_t byteOffset) {
    if (byteOffset > bytes || byteCount > bytes - byteOffset)
        throw Error(fmt::format("upload of {} bytes at {} overruns buffer '{}' of {} bytes",
                                byteCount, byteOffset, name, bytes),
                    ErrorKind::Internal);
    if (byteCount == 0) return;
    if (mapped) {
        ParallelCopy(static_cast<char *>(mapped) + byteOffset, data, byteCount);
        return;
    }
    Staging &staging = context->StagingFor(false);
    for (size_t done = 0; done < byteCount;) {
        size_t chunk = std::min<size_t>(byteCount - done, Staging::kChunk);
        void *ptr = staging.Reserve(*context, chunk);
        std::memcpy(ptr, static_cast<const char *>(data) + done, chunk);
        context->SubmitAndWait([&](VkCommandBuffer cb) {
            VkBufferCopy region{0, byteOffset + done, chunk};
            vkCmdCopyBuffer(cb, staging.Handle(), buffer, 1, &region);
        });
        done += chunk;
    }
}

void Buffer::Download(void *data, size_t byteCount, size_t byteOffset) const {
    if (byteOffset > bytes || byteCount > bytes - byteOffset)
        throw Error(fmt::format("download of {} bytes at {} overruns buffer '{}' of {} bytes",
                                byteCount, byteOffset, name, bytes),
                    ErrorKind::Internal);
    if (byteCount == 0) return;
    if (mapped) {
        ParallelCopy(data, static_cast<const char *>(mapped) + byteOffset, byteCount);
        return;
    }
    Staging &staging = context->StagingFor(true);
    for (size_t done = 0; done < byteCount;) {
        size_t chunk = std::min<size_t>(byteCount - done, Staging::kChunk);
        void *ptr = staging.Reserve(*context, chunk);
        context->SubmitAndWait([&](VkCommandBuffer cb) {
            VkBufferCopy region{byteOffset + done, 0, chunk};
            vkCmdCopyBuffer(cb, buffer, staging.Handle(), 1, &region);
        });
        std::memcpy(static_cast<char *>(data) + done, ptr, chunk);
        done += chunk;
    }
}

void *Staging::Reserve(Context &context, VkDeviceSize wanted) {
    wanted = std::min(wanted, kChunk);
    if (buffer && bytes >= wanted) return mapped;
    Release(context);
    // Grow in powers of two (from 1 MiB) so that a run's rising sizes allocate a few times.
    VkDeviceSize size = VkDeviceSize(1) << 20;
    while (size < wanted) size *= 2;
    size = std::min(size, kChunk);
    RawBuffer raw = CreateRaw(
        context, size,
        download ? VK_BUFFER_USAGE_TRANSFER_DST_BIT : VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
        VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT,
        download ? VK_MEMORY_PROPERTY_HOST_CACHED_BIT : 0);
    try {
        MCD_VK(vkMapMemory(context.Device(), raw.memory, 0, VK_WHOLE_SIZE, 0, &mapped));
    } catch (...) {
        DestroyRaw(context, raw);
        throw;
    }
    buffer = raw.buffer;
    memory = raw.memory;
    bytes = size;
    ++allocations;
    return mapped;
}

void Staging::Release(Context &context) {
    if (mapped) vkUnmapMemory(context.Device(), memory);
    if (buffer) vkDestroyBuffer(context.Device(), buffer, nullptr);
    if (memory) vkFreeMemory(context.Device(), memory, nullptr);
    buffer = VK_NULL_HANDLE;
    memory = VK_NULL_HANDLE;
    mapped = nullptr;
    bytes = 0;
}

}  // namespace mcd::vk
