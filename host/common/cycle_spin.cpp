#include "host/common/cycle_spin.h"

#include <fmt/format.h>

#include <algorithm>
#include <vector>

#include "host/common/parallel.h"
#include "host/error.h"

namespace mcd {

Image MirrorPad(const Image &image, int dx, int dy) {
    int w = image.width, h = image.height;
    auto mirror = [](int i, int n) { return i < 0 ? std::min(-i - 1, n - 1) : i; };
    Image padded(w + dx, h + dy, image.channels);
    const int rows = image.channels * (h + dy);
    ParallelFor(rows, padded.data.size(), [&](int begin, int end) {
        for (int row = begin; row < end; ++row) {
            const int c = row / (h + dy), y = row % (h + dy);
            for (int x = 0; x < w + dx; ++x)
                padded.At(c, y, x) = image.At(c, mirror(y - dy, h), mirror(x - dx, w));
        }
    });
    return padded;
}

Image CycleSpin(int width, int height, int channels, int spins,
                const std::function<Image(int dx, int dy)> &run) {
    std::vector<double> sum(size_t(width) * height * channels, 0.0);
    for (int dy = 0; dy < spins; ++dy)
        for (int dx = 0; dx < spins; ++dx) {
            Image one = run(dx, dy);
            if (one.width != width + dx || one.height != height + dy ||
                one.channels != channels)
                throw Error(
                    fmt::format("cycle spinning: shift ({}, {}) gave {}x{}x{}, not {}x{}x{}",
                                dx, dy, one.width, one.height, one.channels, width + dx,
                                height + dy, channels),
                    ErrorKind::Internal);
            ParallelFor(channels * height, sum.size(), [&](int begin, int end) {
                for (int row = begin; row < end; ++row) {
                    const int c = row / height, y = row % height;
                    for (int x = 0; x < width; ++x)
                        sum[(size_t(c) * height + y) * width + x] += one.At(c, y + dy, x + dx);
                }
            });
        }
    Image image(width, height, channels);
    double count = double(spins) * spins;
    ParallelValues(sum.size(), 2, [&](size_t begin, size_t end) {
        for (size_t i = begin; i < end; ++i) image.data[i] = float(sum[i] / count);
    });
    return image;
}

}  // namespace mcd
