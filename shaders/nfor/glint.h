// nfor: a floor on the weights' noise where the albedo is noise near a glint (a frame without
// a variance layer). The frame's own estimate is a robust median of squared differences: on
// glossy metal a few samples hit a reflected light in some pixels and miss in the next, the
// median reads the misses, and the weights take each hit and gap for signal. Two passes:
// glint_rows.comp marks per pixel whether some albedo channel above `gate` lies within
// `reach` in its row (NaN: none); glint.comp then, where the row marks reach it within
// `reach` in its column (a Chebyshev square) and the trust (trust.comp) is 0, sets each
// channel's variance to max(v, scale x the clamped colour's variance over the 3x3 window
// inside the frame: its mean, then the mean squared deviation from it, each a sum times
// float(1 / n) from NFOR_GLINT_INVERSES). A NaN on either side keeps v. It writes 1 where it
// raised some channel, else 0. One invocation per pixel.
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
// float(1 / n) for the n pixels of a 3x3 window inside the frame (1, 2, 3, 4, 6 or 9; the
// others 0), each written out exactly: the kernel and its CPU twin multiply by the same value
// (a product is correctly rounded; a division may be off by some ULP on a device).
#define NFOR_GLINT_INVERSES                                      \
    0.0f, 1.0f, 0.5f, 0.3333333432674407958984375f, 0.25f, 0.0f, \
        0.16666667163372039794921875f, 0.0f, 0.0f, 0.111111111938953399658203125f
#define NFOR_GLINT_INVERSE_COUNT 10

#ifdef __cplusplus
namespace mcd::shader {
// The gate of the floor (NforOptions::glintNoise), for the host and the CPU twin alike: a
// glint is a pixel with an albedo channel above kNforGlintAlbedo (a light, as the line
// spread's), its reach kNforGlintReach pixels (Chebyshev). Within kNforGlintGuardReach of a
// pixel whose noise the floor raised, the output is kept at least the clamped colour's 3x3
// minimum.
inline constexpr float kNforGlintAlbedo = 8;
inline constexpr int kNforGlintReach = 16;
inline constexpr int kNforGlintGuardReach = 3;
inline constexpr float kNforGlintInverses[NFOR_GLINT_INVERSE_COUNT] = {NFOR_GLINT_INVERSES};
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
