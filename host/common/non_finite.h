// NaN/Inf values of an image: how many, and where the first lies in raster order (row by
// row, a pixel's channels together), as a user reads the image and messages name it.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "host/image.h"

namespace mcd {

struct NonFiniteCount {
    size_t count = 0;
    int x = 0, y = 0, channel = 0;  // the first, where count > 0
};

inline NonFiniteCount CountNonFinite(const Image &image) {
    NonFiniteCount result;
    // One pass over the planes; the first in raster order has the smallest pixel index.
    const size_t pixels = std::max<size_t>(image.PixelCount(), 1);
    size_t firstPixel = pixels, firstChannel = 0;
    for (size_t i = 0; i < image.data.size(); ++i) {
        if (std::isfinite(image.data[i])) continue;
        ++result.count;
        if (i % pixels < firstPixel) firstPixel = i % pixels, firstChannel = i / pixels;
    }
    if (result.count == 0) return result;
    const size_t width = size_t(std::max(image.width, 1));
    result.x = int(firstPixel % width);
    result.y = int(firstPixel / width);
    result.channel = int(firstChannel);
    return result;
}

}  // namespace mcd
