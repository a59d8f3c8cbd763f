// Auto stage 0, for frames without sample statistics (no variance layer, no half-buffers):
// the variance of the pixel mean estimated from the frame itself. Per channel, the colour
// is divided by the albedo (where the albedo exceeds AUTO_NOISE_ALBEDO_FLOOR; else taken
// as is), z = y / a, so that what is left is mostly smooth illumination; each pixel's
// residual against the mean of its n in-frame 8-neighbours, r = z - mean, has variance
// v_z (1 + 1/n) where v_z is locally constant; the estimate is the median of r^2 / (1 +
// 1/n) over the (2R+1)^2 window clipped to the frame (finite values only), divided by
// AUTO_NOISE_MEDIAN_CHI2 (the median of a chi-square with one degree of freedom: unbiased
// for Gaussian noise; the median ignores the edges' and texels' large residuals), times
// a^2 at the pixel. 0 where the window has no finite residual. One invocation per pixel
// and channel.
#ifndef MCD_SHADERS_AUTO_NOISE_H
#define MCD_SHADERS_AUTO_NOISE_H

#include "auto/auto.h"

#define AUTO_NOISE_COLOR 0
#define AUTO_NOISE_ALBEDO 1
#define AUTO_NOISE_OUTPUT 2
#define AUTO_NOISE_BINDINGS 3

// The largest window radius (the window's values are sorted in a local array).
#define AUTO_NOISE_MAX_RADIUS 3
#define AUTO_NOISE_MAX_WINDOW 49
// An albedo at or under this (or not finite) leaves the colour undivided there.
#define AUTO_NOISE_ALBEDO_FLOOR 0.02
#define AUTO_NOISE_MEDIAN_CHI2 0.45493642

#ifdef __cplusplus
#include <cstddef>
namespace mcd::shader {
struct AutoNoisePush {
#else
layout(push_constant) uniform AutoNoisePush {
#endif
    int width;
    int height;
    int channels;
    int albedoChannels;  // 0: no albedo (z = y); else 1 or >= channels
    int radius;          // 1..AUTO_NOISE_MAX_RADIUS
#ifdef __cplusplus
};
static_assert(sizeof(AutoNoisePush) == 20);
static_assert(offsetof(AutoNoisePush, radius) == 16);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
