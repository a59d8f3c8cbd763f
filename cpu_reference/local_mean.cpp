#include "cpu_reference/local_mean.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace mcd::ref {
namespace {

// The mean of each plane over the box of radius r around each pixel, clipped to the image.
Image BoxMean(const Image &image, int r) {
    Image out(image.width, image.height, image.channels);
    for (int c = 0; c < image.channels; ++c)
        for (int y = 0; y < image.height; ++y)
            for (int x = 0; x < image.width; ++x) {
                double sum = 0;
                int n = 0;
                for (int v = std::max(0, y - r); v <= std::min(image.height - 1, y + r); ++v)
                    for (int u = std::max(0, x - r); u <= std::min(image.width - 1, x + r);
                         ++u) {
                        sum += image.At(c, v, u);
                        ++n;
                    }
                out.At(c, y, x) = float(sum / n);
            }
    return out;
}

}  // namespace

void RestoreLocalMeans(const Image &input, int r, Image *output) {
    Image clean(input.width, input.height, input.channels), moved = *output;
    std::vector<bool> kept(input.data.size());
    for (size_t i = 0; i < input.data.size(); ++i) {
        float v = input.data[i];
        kept[i] = output->data[i] == v;
        clean.data[i] = !kept[i] && std::isfinite(v) && v > 0 ? v : 0.f;
        if (kept[i]) moved.data[i] = 0;
    }
    Image mIn = BoxMean(BoxMean(clean, r), r);
    Image mOut = BoxMean(BoxMean(moved, r), r);
    for (size_t i = 0; i < output->data.size(); ++i) {
        if (kept[i]) continue;
        double a = mIn.data[i], b = mOut.data[i];
        if (a > 0 && b > 0 && std::isfinite(a) && std::isfinite(b))
            output->data[i] = float(output->data[i] * (a / b));
    }
}

}  // namespace mcd::ref
