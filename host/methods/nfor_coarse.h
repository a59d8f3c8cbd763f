// nfor's coarse correction (beyond the papers): the frame denoised again at half the
// resolution, where a window spans twice as far and each pixel holds a quarter of the noise,
// gives the fine output its low frequencies where the two agree to within the fine output's
// own residual. What the windows of the fine pass cannot reach (low-frequency blotches on
// dim, noisy walls) comes from the coarse pass; edges, lights and highlights, where the
// half-resolution fit differs by more, keep the fine output.
#pragma once

#include "host/image.h"

namespace mcd {

// Each 2x2 block's mean over its pixels inside the image ((w + 1) / 2 x (h + 1) / 2), each
// value divided by the block's pixel count once more when `ofMean` (a variance: that of the
// block's mean).
Image NforHalf(const Image &image, bool ofMean = false);

// Each plane convolved with a Gaussian of standard deviation sigma over a window of radius
// 3 sigma (rounded down) clipped to the image, normalised over the weights inside.
Image NforGaussian(const Image &image, double sigma);

// The fine output moved to the coarse one's low frequencies: per pixel d, the bilinear
// upsampling of (coarse - NforHalf(output)) at the pixel's centre (coarse position (x +
// 0.5) / 2 - 0.5, clamped to the coarse image), is added times max(0, 1 - |d|^2 / t^2),
// |d| over the channels, t = min(relative x m, noise x s); m = the Gaussian (sigma 1) of
// the output's channels' |values| summed, + 1e-3; s = the square root of the Gaussian
// (sigma 2) of (input - output)^2 summed over the channels (the fine output's residual).
// Pixels whose largest albedo channel exceeds emitterAlbedo (emitters) are left; albedo
// may be null.
void NforAddCoarse(const Image &input, const Image &coarse, const Image *albedo,
                   float emitterAlbedo, float relative, float noise, Image *output);

// The frame's noise as relMSE weighs it, which decides whether the coarse pass runs: per
// pixel the mean over the channels of variance / (color^2 + 0.01), and of those the lower
// median (the value at (n - 1) / 2 in order; non-finite values count as the largest).
// Noisy frames (an interior lit indirectly at 16 spp) hold blotches the fine windows cannot
// reach; on clean ones the half-resolution output is worse than the fine one at every scale
// the correction touches.
double NforRelativeNoise(const Image &color, const Image &variance);

}  // namespace mcd
