// Pivot filter stage 1: pseudo-brightness z = L / L_a (section 4.1), the variance s of z
// (the variance layer / L_a^2, or the sample variance of z over the valid 3x3 neighbours)
// and nu = s / zl^2 with zl the mean z of the valid 3x3 neighbours; nu = -1 marks pixels
// whose pivot is at or below the channel's threshold or that lie on an object/part boundary
// (the boundary term, when ids are given): no z. One invocation per pixel and channel.
#ifndef MCD_SHADERS_PIVOT_RATIO_H
#define MCD_SHADERS_PIVOT_RATIO_H

#include "pivot/pivot.h"

#define PIVOT_RATIO_COLOR 0
#define PIVOT_RATIO_PIVOT 1
#define PIVOT_RATIO_VARIANCE 2
#define PIVOT_RATIO_Z 3
#define PIVOT_RATIO_S 4
#define PIVOT_RATIO_NU 5
#define PIVOT_RATIO_GUIDES 6
// (z, s, nu, level) and (noise, 0, 0, 0) per pixel adjacent, two texels: channel c's in its own
// buffer at slot PIVOT_RATIO_ZSN + c, so that a binding holds one channel's (the slots of
// channels the frame lacks are bound but not written).
#define PIVOT_RATIO_ZSN 7
#define PIVOT_RATIO_BINDINGS (PIVOT_RATIO_ZSN + PIVOT_MAX_CHANNELS)

#ifdef __cplusplus
#include <cstddef>
namespace mcd::shader {
struct PivotRatioPush {
#else
layout(push_constant) uniform PivotRatioPush {
#endif
    int width;
    int height;
    // Pivot validity threshold per channel (floor x the channel's mean of max(L_a, 0)).
    float threshold0;
    float threshold1;
    float threshold2;
    float threshold3;
#ifdef __cplusplus
};
static_assert(sizeof(PivotRatioPush) == 24);
static_assert(offsetof(PivotRatioPush, threshold3) == 20);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
