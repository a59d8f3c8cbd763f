// Auto stage 3: the per-pixel combination of K candidates by their smoothed error
// estimates e_k. Weights mode: w_k = max(e_k, floor)^-power; select mode: weight 1 for the
// smallest e_k (the first on ties). A candidate whose estimate or output is not finite at
// the pixel has weight 0; a pixel where every weight is 0 keeps the input color. Weights
// with median (AUTO_MODE_WEIGHTS_MEDIAN): where every usable candidate's e_k is under the
// floor, so that all weigh the same, the output is the per-channel median of the usable
// candidates (the mean of the middle two for an even count) instead of their mean: at a
// firefly of a frame without statistics every SURE estimate goes negative, and the mean
// kept the firefly of the candidates that keep it. Relative (AUTO_MODE_RELATIVE): each
// candidate c_k stands for the unknown reference r with probability w_k, and the output
// is the value f that minimises sum_k w_k (f - c_k)^2 / (c_k^2 + 0.01), the expected
// relative squared error (relMSE's per-value term):
//   f = sum_k w_k c_k / (c_k^2 + 0.01) / sum_k w_k / (c_k^2 + 0.01),
// per channel; where the candidates agree it is their weighted mean, where they disagree
// it leans to the dark ones, which relMSE charges at most 1 for being too dark and without
// bound for being too bright. A candidate darker than the weighted mean m counts as if its
// square were m^2 / darkLimit, so that a small weight on one dark candidate cannot pull a
// bright edge down (the weights are the estimates' trust, not probabilities), except at
// a noisy pixel (below). The weights are equal where every usable estimate is under
// the floor, and where the pixel's noise outweighs what the estimates resolve: the mean
// over channels of v / (u^2 + 0.01) above noiseLimit, v the variance of the pixel mean and
// u the equal-weight f (a firefly: the window's estimates say how candidates do around
// it, not which of them removes it). A sum of weights over 1/(c^2 + 0.01) that is 0 or
// beyond a float falls back to the weighted mean. Writes the combined color and the
// normalised weights (K planes; the equal ones where they were taken).
#ifndef MCD_SHADERS_AUTO_COMBINE_H
#define MCD_SHADERS_AUTO_COMBINE_H

#include "auto/auto.h"

#define AUTO_COMBINE_COLOR 0
#define AUTO_COMBINE_CANDIDATES 1
#define AUTO_COMBINE_ERRORS 2
#define AUTO_COMBINE_OUTPUT 3
#define AUTO_COMBINE_WEIGHTS 4
#define AUTO_COMBINE_VARIANCE 5
#define AUTO_COMBINE_BINDINGS 6

#ifdef __cplusplus
#include <cstddef>
namespace mcd::shader {
struct AutoCombinePush {
#else
layout(push_constant) uniform AutoCombinePush {
#endif
    int width;
    int height;
    int channels;
    int count;  // K, 1..AUTO_MAX_CANDIDATES
    int mode;   // AUTO_MODE_WEIGHTS, _SELECT, _WEIGHTS_MEDIAN or _RELATIVE
    float power;
    float floorError;  // > 0
    // Relative mode: the mean of v / (u^2 + 0.01) above which the weights are equal (> 0),
    // and the darkLimit (> 0) of candidates darker than the weighted mean.
    float noiseLimit;
    float darkLimit;
#ifdef __cplusplus
};
static_assert(sizeof(AutoCombinePush) == 36);
static_assert(offsetof(AutoCombinePush, floorError) == 24);
static_assert(offsetof(AutoCombinePush, noiseLimit) == 28);
static_assert(offsetof(AutoCombinePush, darkLimit) == 32);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
