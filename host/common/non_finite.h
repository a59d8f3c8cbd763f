// NaN/Inf values of an image: how many, and where the first lies in raster order (row by
// row, a pixel's channels together), as a user reads the image and messages name it.
#pragma once

#include <cstddef>

#include "host/image.h"

namespace mcd {

struct NonFiniteCount {
    size_t count = 0;
    int x = 0, y = 0, channel = 0;  // the first, where count > 0
};

NonFiniteCount CountNonFinite(const Image &image);

}  // namespace mcd
