// A planar float image in a storage buffer, [channel][y][x], and views into one.
#pragma once

#include <string>

#include "host/image.h"
#include "host/vk/buffer.h"

namespace mcd::vk {

// Where a planar image lives in a buffer: element (c, y, x) is at c * plane + y * stride + x.
struct ImageView {
    const Buffer *buffer = nullptr;
    int stride = 0;
    int plane = 0;
};

// A view a kernel writes through: only a non-const buffer gives one, so a Record function
// that writes says so in its signature. Reads through it as an ImageView.
struct MutableImageView {
    Buffer *buffer = nullptr;
    int stride = 0;
    int plane = 0;

    operator ImageView() const { return {buffer, stride, plane}; }
};

struct GpuImage {
    Buffer buffer;
    int width = 0, height = 0, channels = 0;

    GpuImage() = default;
    GpuImage(Context &context, int width, int height, int channels, std::string name);

    ImageView View() const { return {&buffer, width, width * height}; }
    MutableImageView MutableView() { return {&buffer, width, width * height}; }
    void Upload(const Image &image);
    Image Download() const;
};

// Throw unless `view` holds a width x height x channels region inside its buffer.
void CheckView(const ImageView &view, int width, int height, int channels, const char *what);

}  // namespace mcd::vk
