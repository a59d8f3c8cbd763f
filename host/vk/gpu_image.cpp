#include "host/vk/gpu_image.h"

#include <fmt/format.h>

#include "host/error.h"

namespace mcd::vk {

GpuImage::GpuImage(Context &context, int width, int height, int channels, std::string name)
    : buffer(context, VkDeviceSize(width) * height * channels * sizeof(float), std::move(name)),
      width(width),
      height(height),
      channels(channels) {}

void GpuImage::Upload(const Image &image) {
    if (image.width != width || image.height != height || image.channels != channels)
        throw Error(fmt::format("upload of a {}x{}x{} image into GPU image '{}' of {}x{}x{}",
                                image.width, image.height, image.channels, buffer.Name(), width,
                                height, channels),
                    ErrorKind::Internal);
    buffer.UploadFloats(image.data);
}

Image GpuImage::Download() const {
    Image image(width, height, channels);
    buffer.Download(image.data.data(), image.data.size() * sizeof(float));
    return image;
}

void CheckView(const ImageView &view, int width, int height, int channels, const char *what) {
    if (!view.buffer || !view.buffer->Valid())
        throw Error(fmt::format("{}: no buffer bound", what), ErrorKind::Internal);
    if (width <= 0 || height <= 0 || channels <= 0)
        throw Error(fmt::format("{}: empty region {}x{}x{}", what, width, height, channels),
                    ErrorKind::Internal);
    if (view.stride < width || (channels > 1 && view.plane < view.stride * height))
        throw Error(
            fmt::format("{}: stride {} / plane {} of buffer '{}' too small for {}x{}", what,
                        view.stride, view.plane, view.buffer->Name(), width, height),
            ErrorKind::Internal);
    VkDeviceSize last = VkDeviceSize(channels - 1) * view.plane +
                        VkDeviceSize(height - 1) * view.stride + VkDeviceSize(width);
    if (last * sizeof(float) > view.buffer->Bytes())
        throw Error(
            fmt::format("{}: a {}x{}x{} region overruns buffer '{}' ({} bytes)", what, width,
                        height, channels, view.buffer->Name(), view.buffer->Bytes()),
            ErrorKind::Internal);
}

}  // namespace mcd::vk
