// nfor stages 5 and 6, one candidate bandwidth k each. `regress`: per pixel p the weighted
// least-squares fit of every colour channel on the columns (1, dx / R, dy / R, F_q - F_p)
// over the (2R + 1)^2 window, weight of q exp(-max(0, D(p, q - p)) / k^2 - sum_j (s_j
// (F_q,j - F_p,j))^2) (1 at q = p; 0 for emitters, outside the frame and where the
// exponent exceeds NFOR_EXP_CUT), ridge lambda sum(w) on every column but the constant,
// Cholesky; writes the coefficients (per pixel, below) and the fit's influence on its
// centre, (A^-1)_00, at plane `outPlane` of the hat buffer. With NFOR_SPEC_CANDIDATES 2 it
// fits a second bandwidth (1 / k^2 secondInvBandwidth2) over the same window in the same
// pass, into the second coefficients and plane outPlane + 1: the window's fetches, columns
// and feature distances are shared, each candidate's sums are its own, in the same order.
// An emitter (mask 0) writes its colour as the constant, no slope, influence 1. `gather`:
// per pixel q the average of the fits of the windows p holding q whose centres are at most
// gatherRadius away (all of them at the window's radius: NFOR's collaborative filtering),
// evaluated at q and weighted by q's weight in p's window, into planes outPlane.. of the
// output; an emitter keeps its input. One invocation per pixel.
#ifndef MCD_SHADERS_NFOR_FIT_H
#define MCD_SHADERS_NFOR_FIT_H

#include "nfor/nfor.h"

// The fits read each pixel's inputs packed (`pack`, one invocation per pixel): per pixel
// NFOR_PACKED_VEC4S(F) vec4s, the mask at float 0, feature j at float 1 + j, zeros to the
// next vec4, then the colour's channels (zeros past them): one load brings four values. The
// coefficients are packed per pixel too: NFOR_BETA_STRIDE(F, channels) floats, column i and
// channel c at i * channels + c.
#define NFOR_FEATURE_VEC4S(F) (((F) + 4) / 4)
#define NFOR_PACKED_VEC4S(F) (NFOR_FEATURE_VEC4S(F) + 1)
#define NFOR_BETA_STRIDE(F, C) ((((F) + 3) * (C) + 3) / 4 * 4)

#define NFOR_PACK_COLOR 0
#define NFOR_PACK_FEATURES 1
#define NFOR_PACK_MASK 2
#define NFOR_PACK_OUT 3
#define NFOR_PACK_BINDINGS 4

#define NFOR_FIT_PACKED 0
#define NFOR_FIT_DISTANCE 1
#define NFOR_FIT_BETA 2         // regress writes, gather reads
#define NFOR_FIT_OUT 3          // regress: the influence; gather: the output
#define NFOR_FIT_COLOR 4        // gather: the input colour, kept by emitters
#define NFOR_FIT_SECOND_BETA 4  // regress: the second candidate's coefficients
#define NFOR_REGRESS_BINDINGS 5
#define NFOR_GATHER_BINDINGS 5

#ifdef __cplusplus
#include <cstddef>
namespace mcd::shader {
struct NforFitPush {
#else
layout(push_constant) uniform NforFitPush {
#endif
    int width;
    int height;
    int radius;
    int gatherRadius;     // gather: the windows averaged are those centred this close
    int outPlane;         // regress: the influence's plane; gather: the output's first
    float invBandwidth2;  // 1 / k^2
    float ridge;
    float featureWeight[NFOR_MAX_FEATURES];  // s_j
    float secondInvBandwidth2;               // regress: the second candidate's 1 / k^2
#ifdef __cplusplus
};
static_assert(sizeof(NforFitPush) == 72);
static_assert(offsetof(NforFitPush, featureWeight) == 28);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
