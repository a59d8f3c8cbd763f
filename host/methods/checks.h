// Input checks the methods share.
#pragma once

#include <fmt/format.h>

#include <cmath>

#include "host/error.h"
#include "host/image.h"

namespace mcd {

// Refuse non-finite values (and negatives where they make no sense), naming the method,
// the layer, the first offending pixel and channel.
inline void CheckFinite(const char *method, const Image &image, const char *what,
                        bool nonNegative) {
    for (int c = 0; c < image.channels; ++c)
        for (int y = 0; y < image.height; ++y)
            for (int x = 0; x < image.width; ++x) {
                float v = image.At(c, y, x);
                if (std::isfinite(v) && !(nonNegative && v < 0)) continue;
                bool finite = std::isfinite(v);
                throw Error(
                    fmt::format("{}: {} has {} at pixel ({}, {}), channel {}; fix or "
                                "mask the input first",
                                method, what, finite ? "a negative value" : "NaN/Inf", x, y, c),
                    finite ? ErrorKind::InvalidArgument : ErrorKind::NonFiniteInput);
            }
}

// Refuse a layer not of the frame's size (and of `channels` channels where that is > 0),
// then its non-finite values as CheckFinite does.
inline void CheckLayer(const char *method, const Image &image, const char *what, int width,
                       int height, int channels, bool nonNegative) {
    if (image.width != width || image.height != height ||
        (channels > 0 && image.channels != channels))
        throw Error(fmt::format("{}: {} is {}x{}x{}, expected {}x{}x{}", method, what,
                                image.width, image.height, image.channels, width, height,
                                channels > 0 ? channels : image.channels),
                    ErrorKind::InvalidArgument);
    CheckFinite(method, image, what, nonNegative);
}

}  // namespace mcd
