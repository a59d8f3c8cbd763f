// Auto stage 0, for frames without sample statistics (no variance layer, no half-buffers):
// the variance of the pixel mean estimated from the frame itself. Per channel, the colour
// is divided by the albedo (where the albedo exceeds AUTO_NOISE_ALBEDO_FLOOR; else taken
// as is), z = y / a, so that what is left is mostly smooth illumination. At each pixel the
// second differences along 4 directions (horizontal, vertical, both diagonals; those whose
// two neighbours are in the frame), r_d = z - (z_-d + z_+d) / 2, have variance 1.5 v_z for
// noise of locally constant variance v_z; the smallest r_d^2 / 1.5 is that of the
// direction along an edge, if any (an edge's step is not noise), and a firefly is large
// in every direction (it is noise). That smallest value over its mean for Gaussian noise
// (AUTO_NOISE_MIN_MEAN where all 4 directions fit, 1 on the border rows and columns where
// one does), its mean over the (2R+1)^2 window clipped to the frame (finite values only,
// and only the neighbours demodulated like the pixel: both divided by albedos within a
// factor AUTO_NOISE_DIVISOR_RATIO of each other, or both undivided), times a^2 at the
// pixel, is the estimate; 0 where the window has no finite value. The neighbours' values
// are in their own z's units: a black background pixel (undivided) next to a wall of
// albedo 0.3 took 11 times the wall's noise, which SURE then saw as error of every
// candidate that keeps the black. One invocation per pixel and channel.
#ifndef MCD_SHADERS_AUTO_NOISE_H
#define MCD_SHADERS_AUTO_NOISE_H

#include "auto/auto.h"

#define AUTO_NOISE_COLOR 0
#define AUTO_NOISE_ALBEDO 1
#define AUTO_NOISE_OUTPUT 2
#define AUTO_NOISE_BINDINGS 3

// The largest window radius.
#define AUTO_NOISE_MAX_RADIUS 8
// An albedo at or under this (or not finite) leaves the colour undivided there.
#define AUTO_NOISE_ALBEDO_FLOOR 0.02
// A neighbour's value enters the pixel's mean only if its divisor is within this factor of
// the pixel's (measured, README: 1.1-1.5 alike on the 256x256 Cycles cornell box, 2 worse).
#define AUTO_NOISE_DIVISOR_RATIO 1.25
// E[min_d r_d^2 / 1.5] = 0.27848 v for Gaussian noise (Monte Carlo, 2e6 draws of 3x3 iid
// normal values).
#define AUTO_NOISE_MIN_MEAN 0.27848

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
