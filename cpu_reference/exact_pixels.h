// Pixels a frame knows exactly (host/common/exact_pixels.h), the CPU reference.
#pragma once

#include "host/image.h"

namespace mcd::ref {

// Each value of `output` whose input is finite and > 0 and whose variance (the value at the
// same pixel, in the same channel or in the only one) is exactly 0 becomes the input's. A
// variance of another size changes nothing.
void KeepExactPixels(const Image &input, const Image &variance, Image *output);

}  // namespace mcd::ref
