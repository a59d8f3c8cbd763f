// Pivot filter, the bilateral baseline (section 4.1's "usual filter"): a cross-bilateral
// filter of z over the fitted pixels of a (2 radius + 1)^2 window, spatial Gaussian of
// sigma sigmaS, range Gaussian of sigmaRange on the relative difference of the pivot's
// channel mean, times the normal and id terms; then multiplied back by the pivot. Pixels
// without z or without weight keep their color. One invocation per pixel and channel.
#ifndef MCD_SHADERS_PIVOT_BILATERAL_H
#define MCD_SHADERS_PIVOT_BILATERAL_H

#include "pivot/pivot.h"

#define PIVOT_BILATERAL_COLOR 0
#define PIVOT_BILATERAL_PIVOT 1
#define PIVOT_BILATERAL_Z 2
#define PIVOT_BILATERAL_NU 3
#define PIVOT_BILATERAL_GUIDES 4
#define PIVOT_BILATERAL_OUT 5
#define PIVOT_BILATERAL_BINDINGS 6

#ifdef __cplusplus
#include <cstddef>
namespace mcd::shader {
struct PivotBilateralPush {
#else
layout(push_constant) uniform PivotBilateralPush {
#endif
    int width;
    int height;
    int channels;
    int radius;
    float sigmaS;
    float sigmaRange;
    float goodNu;
#ifdef __cplusplus
};
static_assert(sizeof(PivotBilateralPush) == 28);
static_assert(offsetof(PivotBilateralPush, goodNu) == 24);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
