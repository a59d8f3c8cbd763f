// RAII storage buffer. Memory is device-local where the device has it; uploads and
// downloads map it directly when it is also host-visible (lavapipe, unified memory) and
// go through a staging buffer otherwise.
#pragma once

#include <volk.h>

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

}  // namespace mcd::vk
