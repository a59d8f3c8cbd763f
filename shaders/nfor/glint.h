// nfor: a floor on the weights' noise where the albedo is noise near a glint (a frame without
// a variance layer). The frame's own estimate is a robust median of squared differences: on
// glossy metal a few samples hit a reflected light in some pixels and miss in the next, the
// median reads the misses, and the weights take each hit and gap for signal. Two passes:
// glint_rows.comp marks per pixel whether some albedo channel above `gate` lies within
// `reach` in its row (NaN: none); glint.comp then, where the row marks reach it within
// `reach` in its column (a Chebyshev square) and the trust (trust.comp) is 0, sets each
// channel's variance to max(v, scale x the clamped colour's variance over the 3x3 window
// inside the frame: its mean, then the mean squared deviation from it). A NaN on either side
// keeps v. It writes 1 where it raised some channel, else 0. One invocation per pixel.
#ifndef MCD_SHADERS_NFOR_GLINT_H
#define MCD_SHADERS_NFOR_GLINT_H

#include "nfor/nfor.h"

// glint_rows.comp's bindings, then glint.comp's.
#define NFOR_GLINT_ROWS_ALBEDO 0
#define NFOR_GLINT_ROWS_NEAR 1
#define NFOR_GLINT_ROWS_BINDINGS 2
#define NFOR_GLINT_NEAR 0
#define NFOR_GLINT_COLOR 1
#define NFOR_GLINT_TRUST 2
#define NFOR_GLINT_VARIANCE 3
#define NFOR_GLINT_FLOORED 4
#define NFOR_GLINT_BINDINGS 5
#define NFOR_GLINT_MAX_REACH 64

#ifdef __cplusplus
namespace mcd::shader {
struct NforGlintPush {
#else
layout(push_constant) uniform NforGlintPush {
#endif
    int width;
    int height;
    int albedoChannels;
    int reach;    // the gate's Chebyshev reach, 0 to NFOR_GLINT_MAX_REACH
    float gate;   // a glint: some albedo channel above this
    float scale;  // the floor: scale x the clamped colour's 3x3 variance
#ifdef __cplusplus
};
static_assert(sizeof(NforGlintPush) == 24);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
