// A reconstruction held above the lowest input value around each pixel
// (host/common/input_minimum.h), the CPU reference.
#pragma once

#include <cstddef>

#include "host/image.h"

namespace mcd::ref {

// Each value of `output` whose output and input window (radius r, clipped to the image) are
// all finite becomes max(output, the minimum over that window of `input`'s channel). Returns
// how many values changed.
size_t RaiseToInputMinimum(const Image &input, int r, Image *output);

}  // namespace mcd::ref
