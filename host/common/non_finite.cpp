#include "host/common/non_finite.h"

#include <algorithm>
#include <cmath>
#include <mutex>

#include "host/common/parallel.h"

namespace mcd {

NonFiniteCount CountNonFinite(const Image &image) {
    NonFiniteCount result;
    // One pass over the planes split among the cores; the first in raster order has the
    // smallest pixel index, then the smallest channel: each part's first, then the least.
    const size_t pixels = std::max<size_t>(image.PixelCount(), 1);
    size_t firstPixel = pixels, firstChannel = 0;
    std::mutex lock;
    ParallelValues(image.data.size(), 1, [&](size_t begin, size_t end) {
        size_t count = 0, pixel = pixels, channel = 0;
        for (size_t i = begin; i < end; ++i) {
            if (std::isfinite(image.data[i])) continue;
            ++count;
            if (i % pixels < pixel) pixel = i % pixels, channel = i / pixels;
        }
        if (count == 0) return;
        std::lock_guard<std::mutex> guard(lock);
        result.count += count;
        if (pixel < firstPixel || (pixel == firstPixel && channel < firstChannel))
            firstPixel = pixel, firstChannel = channel;
    });
    if (result.count == 0) return result;
    const size_t width = size_t(std::max(image.width, 1));
    result.x = int(firstPixel % width);
    result.y = int(firstPixel / width);
    result.channel = int(firstChannel);
    return result;
}

}  // namespace mcd
