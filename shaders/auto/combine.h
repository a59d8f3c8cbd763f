// Auto stage 3: the per-pixel combination of K candidates by their smoothed error
// estimates e_k. Weights mode: w_k = max(e_k, floor)^-power; select mode: weight 1 for the
// smallest e_k (the first on ties). A candidate whose estimate or output is not finite at
// the pixel has weight 0; a pixel where every weight is 0 keeps the input color. Weights
// with median (AUTO_MODE_WEIGHTS_MEDIAN): where every usable candidate's e_k is under the
// floor, so that all weigh the same, the output is the per-channel median of the usable
// candidates (the mean of the middle two for an even count) instead of their mean: at a
// firefly of a frame without statistics every SURE estimate goes negative, and the mean
// kept the firefly of the candidates that keep it. Writes the combined color and the
// normalised weights (K planes).
#ifndef MCD_SHADERS_AUTO_COMBINE_H
#define MCD_SHADERS_AUTO_COMBINE_H

#include "auto/auto.h"

#define AUTO_COMBINE_COLOR 0
#define AUTO_COMBINE_CANDIDATES 1
#define AUTO_COMBINE_ERRORS 2
#define AUTO_COMBINE_OUTPUT 3
#define AUTO_COMBINE_WEIGHTS 4
#define AUTO_COMBINE_BINDINGS 5

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
    int mode;   // AUTO_MODE_WEIGHTS, AUTO_MODE_SELECT or AUTO_MODE_WEIGHTS_MEDIAN
    float power;
    float floorError;  // > 0
#ifdef __cplusplus
};
static_assert(sizeof(AutoCombinePush) == 28);
static_assert(offsetof(AutoCombinePush, floorError) == 24);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
