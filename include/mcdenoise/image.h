// A planar float image: the one container shared by I/O, the CPU reference, the GPU
// upload/download paths and the tests. Layout is [channel][y][x], as on the GPU.
#pragma once

#include <cstddef>
#include <vector>

namespace mcd {

struct Image {
    int width = 0, height = 0, channels = 0;
    std::vector<float> data;

    Image() = default;
    Image(int width, int height, int channels, float fill = 0.f)
        : width(width),
          height(height),
          channels(channels),
          data(size_t(width) * size_t(height) * size_t(channels), fill) {}

    size_t PixelCount() const { return size_t(width) * size_t(height); }
    size_t Size() const { return data.size(); }
    bool Empty() const { return data.empty(); }
    bool SameShape(const Image &o) const {
        return width == o.width && height == o.height && channels == o.channels;
    }

    float &At(int c, int y, int x) { return data[(size_t(c) * height + y) * width + x]; }
    float At(int c, int y, int x) const { return data[(size_t(c) * height + y) * width + x]; }
    float *Plane(int c) { return data.data() + size_t(c) * PixelCount(); }

    // The region [x0, x1) x [y0, y1), all channels (the caller keeps it inside).
    Image Crop(int x0, int y0, int x1, int y1) const {
        Image crop(x1 - x0, y1 - y0, channels);
        for (int c = 0; c < channels; ++c)
            for (int y = y0; y < y1; ++y)
                for (int x = x0; x < x1; ++x) crop.At(c, y - y0, x - x0) = At(c, y, x);
        return crop;
    }
    const float *Plane(int c) const { return data.data() + size_t(c) * PixelCount(); }
};

}  // namespace mcd
