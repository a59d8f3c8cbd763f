// Pivot filter stage 2: for every centre and channel, the square window grown from 5x5
// (section 4.3) and the weighted least-squares planes Z = a dx + b dy + c of the square and
// its four quadrants (section 4.2, weight eq. 10) at the chosen radius. Growth adds one ring
// of pixels per step to running sums; a centre whose radius leaves eq. 13's lattice stops
// there and keeps its growth fits; see cpu_reference/pivot_filter.h for the rules. One
// invocation per centre; one dispatch per channel, each channel's packed input and fits in
// buffers of their own (a binding holds one channel's planes, so a frame of 4 channels binds
// like one of 1).
#ifndef MCD_SHADERS_PIVOT_FIT_H
#define MCD_SHADERS_PIVOT_FIT_H

#include "pivot/pivot.h"

// (z, s, nu, level) and (noise, 0, 0, 0) of the dispatch's channel, two vec4 texels a pixel
#define PIVOT_FIT_ZSN 0
#define PIVOT_FIT_GUIDES 1
#define PIVOT_FIT_LO 2  // planes 0..7 of one channel
#define PIVOT_FIT_HI 3  // planes 8..15 of one channel
#define PIVOT_FIT_BINDINGS 4

#ifdef __cplusplus
#include <cstddef>
namespace mcd::shader {
struct PivotFitPush {
#else
layout(push_constant) uniform PivotFitPush {
#endif
    int width;
    int height;
    int maxRadius;
    float targetNoise;   // relative std of the centre value that stops growth
    float goodNu;        // pixels with nu above this are not fitted (goodNoise^2)
    float disagreement;  // relative square-vs-quadrant limit at the centre
    float k;             // eq. 10's robustness constant
    float sigmaWeight;   // multiplies sigma (nu) in eq. 10's exponent (1: the paper)
    int rowBase;         // first centre row of this dispatch (row strips)
    float edge;          // sigmas of the shading-edge test (pivot/edge.glsl; 0: off)
#ifdef __cplusplus
};
static_assert(sizeof(PivotFitPush) == 40);
static_assert(offsetof(PivotFitPush, rowBase) == 32);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
