// RAII storage buffer. Memory is device-local where the device has it; uploads and
// downloads map it directly when it is also host-visible (lavapipe, unified memory) and
// go through the context's staging buffers otherwise. A freed buffer goes to the context's
// pool (host/vk/buffer_pool.h) for the next buffer of its size: a buffer's contents before
// its user writes them are undefined.
#pragma once

#include <volk.h>

#include <algorithm>
#include <cstddef>
#include <string>
#include <vector>

namespace mcd::vk {

class Context;

class Buffer {
  public:
    Buffer() = default;
    Buffer(Context &context, VkDeviceSize bytes, std::string name);
    ~Buffer();
    Buffer(Buffer &&other) noexcept;
    Buffer &operator=(Buffer &&other) noexcept;
    Buffer(const Buffer &) = delete;
    Buffer &operator=(const Buffer &) = delete;

    VkBuffer Handle() const { return buffer; }
    VkDeviceSize Bytes() const { return bytes; }
    const std::string &Name() const { return name; }
    bool Valid() const { return buffer != VK_NULL_HANDLE; }
    // Whether transfers map its memory (else they go through the context's staging buffers).
    bool Mapped() const { return mapped != nullptr; }
    // The whole buffer as a read-only texel buffer of floats (created on first use).
    // Kernels read through it where loads dominate: lavapipe gathers texel fetches as
    // vectors but loads storage buffers one lane at a time. It is not free: lavapipe
    // compiles a kernel variant per class of bound buffer sizes, so it pays in kernels of
    // few dispatches (rhf, pivot, the SWT) and cost the DWT kernels (many small dispatches
    // in the adaptive sampler) 40x in recompiles, for no measured gain, so they keep
    // storage buffers.
    VkBufferView FloatView() const;
    // The same as texels of four floats (RGBA32F; created on first use): one fetch reads
    // floats 4i..4i+3 (a last partial texel reads past the floats, within the allocation).
    VkBufferView Vec4View() const;

    void Upload(const void *data, size_t byteCount, size_t byteOffset = 0);
    void Download(void *data, size_t byteCount, size_t byteOffset = 0) const;
    void UploadFloats(const std::vector<float> &values) {
        Upload(values.data(), values.size() * sizeof(float));
    }
    std::vector<float> DownloadFloats(size_t count, size_t floatOffset = 0) const {
        std::vector<float> values(count);
        Download(values.data(), count * sizeof(float), floatOffset * sizeof(float));
        return values;
    }

  private:
    void Release();
    // The allocation's size: the bytes asked for (one word at least) in whole vec4 texels.
    VkDeviceSize AllocBytes() const {
        return (std::max<VkDeviceSize>(bytes, 4) + 15) / 16 * 16;
    }
    void Poison();
    // The texel view of the given format, made once into `view`.
    VkBufferView View(VkFormat format, int floatsPerTexel, const char *unit,
                      VkBufferView &view) const;

    Context *context = nullptr;
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkDeviceSize bytes = 0;
    void *mapped = nullptr;
    mutable VkBufferView floatView = VK_NULL_HANDLE, vec4View = VK_NULL_HANDLE;
    std::string name;
};

// A host-visible buffer for transfers between the host and device memory it cannot map,
// mapped for its life: a context keeps one per direction (Context::StagingFor) and grows it
// as transfers ask, to at most kChunk bytes; larger transfers go through it in chunks.
class Staging {
  public:
    static constexpr VkDeviceSize kChunk = VkDeviceSize(64) << 20;

    explicit Staging(bool download) : download(download) {}
    Staging(const Staging &) = delete;
    Staging &operator=(const Staging &) = delete;
    ~Staging() = default;  // the context releases it (Release) before its device goes

    // Mapped memory of at least min(bytes, kChunk) bytes; the buffer grows when smaller.
    void *Reserve(Context &context, VkDeviceSize bytes);
    VkBuffer Handle() const { return buffer; }
    VkDeviceSize Bytes() const { return bytes; }
    // How many times its memory was allocated (tests: reuse, not one per transfer).
    int Allocations() const { return allocations; }
    void Release(Context &context);

  private:
    bool download;
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    void *mapped = nullptr;
    VkDeviceSize bytes = 0;
    int allocations = 0;
};

}  // namespace mcd::vk
