// nfor stage 1, for frames without a variance layer: the variance of each pixel's mean
// estimated from the image itself. Per channel z = value / divisor where the divisor (the
// albedo's channel) is above NFOR_NOISE_ALBEDO_FLOOR, else z = value (not divided). For
// each of 4 directions d (horizontal, vertical, both diagonals) the half squared
// differences (z_u - z_u+d)^2 / 2 over the (2r+1)^2 window, both pixels inside and divided
// alike to the pixel (both not, or both by divisors within NFOR_NOISE_DIVISOR_RATIO of
// its); their lower median over the median of chi^2_1; the smallest over the directions
// (the direction along an edge), a direction counting with at least NFOR_NOISE_MIN_PAIRS
// pairs; where none has them and `relaxed` is set, the same over the pairs of its
// neighbours (the pixel in
// neither) both divided where the pixel is (both not where it is not), whatever their
// divisors, with at least NFOR_NOISE_MIN_RELAXED_PAIRS; times the calibration and
// the pixel's divisor squared. 0 where no pair fits. A median: a firefly does not raise its
// neighbours' estimate. With `sparse`, a direction whose median is 0 (at least half its
// pairs equal: a frame of few samples, most of them exactly 0, whose noise a median cannot
// see) takes the mean of its half squared differences instead, the variance's unbiased
// estimate for independent pixels. One invocation per pixel and channel.
#ifndef MCD_SHADERS_NFOR_NOISE_H
#define MCD_SHADERS_NFOR_NOISE_H

#include "nfor/nfor.h"

#define NFOR_NOISE_IMAGE 0
#define NFOR_NOISE_DIVISOR 1
#define NFOR_NOISE_OUTPUT 2
#define NFOR_NOISE_BINDINGS 3

#ifdef __cplusplus
#include <cstddef>
namespace mcd::shader {
struct NforNoisePush {
#else
layout(push_constant) uniform NforNoisePush {
#endif
    int width;
    int height;
    int divisorChannels;  // 0: no divisor
    int radius;           // 1..NFOR_NOISE_MAX_RADIUS
    float calibration;
    int relaxed;  // 1: the fallback for pixels with too few pairs divided alike
    int sparse;   // 1: a direction whose median is 0 takes the mean of its half squares
#ifdef __cplusplus
};
static_assert(sizeof(NforNoisePush) == 28);
static_assert(offsetof(NforNoisePush, calibration) == 16);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
