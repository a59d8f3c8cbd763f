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

}  // namespace mcd
