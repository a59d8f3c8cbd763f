// Restoring an input's local means (host/common/local_mean.h), the CPU reference: every
// window summed from scratch, in double.
#pragma once

#include "host/image.h"

namespace mcd::ref {

// Each output value times m_in / m_out where both are positive and finite: the means of
// max(input, 0) (NaN/Inf as 0) and of the output over the box of radius r around each pixel
// clipped to the image, taken twice (a tent of radius 2r). Values equal to the input's (the
// method left them) count as 0 in both means and stay as they are.
void RestoreLocalMeans(const Image &input, int r, Image *output);

}  // namespace mcd::ref
