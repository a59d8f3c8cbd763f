// nfor's coarse correction (host/methods/nfor_coarse.h), the CPU reference: every window
// summed from scratch in two dimensions, in double.
#pragma once

#include "host/image.h"

namespace mcd::ref {

// Each 2x2 block's mean over its pixels inside the image; a variance (ofMean) divided by
// the block's pixel count once more.
Image NforHalf(const Image &image, bool ofMean = false);

// Per pixel d = the bilinear value of (coarse - NforHalf(output)) at coarse position
// ((x + 0.5) / 2 - 0.5, (y + 0.5) / 2 - 0.5), positions clamped to the coarse image; t =
// min(relative (m + 1e-3), noise sqrt(s)), m and s the means of sum_c |output| and sum_c
// (input - output)^2 weighted by exp(-|o|^2 / (2 sigma^2)) over the square of radius
// 3 sigma clipped to the image (sigma 1 and 2); output += max(0, 1 - |d|^2 / t^2) d where
// t > 0 and the pixel's largest albedo channel is at most emitterAlbedo.
void NforAddCoarse(const Image &input, const Image &coarse, const Image *albedo,
                   double emitterAlbedo, double relative, double noise, Image *output);

// The median over the pixels (the lower one: index (n - 1) / 2 of the sorted values, a
// non-finite value sorted last) of sum_c variance / (color^2 + 0.01) / channels.
double NforRelativeNoise(const Image &color, const Image &variance);

}  // namespace mcd::ref
