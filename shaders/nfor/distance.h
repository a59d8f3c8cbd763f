// nfor stage 4: the colour's NL-means patch distance D(p, o) for every offset o of the
// regression window with oy > 0, or oy = 0 and ox > 0 (raster order; the other half is
// D(p, o) = D(p + o, -o)). Three kernels: `illumination` (below), then `term` writes, per pixel
// u and stored offset j, the mean over the channels of ((C_u - C_u+o)^2 - alpha (v_u + v_u+o))
// / (v_u + v_u+o + NFOR_REL_EPS (C_u^2 + C_u+o^2) + NFOR_TINY), each at most NFOR_TERM_MAX (0
// where u + o is outside; with minVariance both v_u + v_u+o are 2 min(v_u, v_u+o): a dark pixel
// does not borrow from a brighter, noisier one, and a term is at least -alpha); with an albedo,
// C is the colour divided by the albedo's channel where that is above NFOR_NOISE_ALBEDO_FLOOR
// and v the variance divided by its square (the illumination: texture and the coverage of edge
// pixels divide out), unless a trust plane (nfor/trust.h) marks either end's albedo as noise:
// then the pair compares the colours and variances themselves (the same units at both ends);
// `box` sums those over the patch positions, along rows (vertical 0) and
// then along columns (vertical 1), the second dividing by the number of patch positions with
// both ends inside (0 where none). `term`: one invocation per pixel and NFOR_TERM_OFFSETS
// stored offsets; `box` (rows) and `box_columns`: one per NFOR_BOX_BLOCK outputs of a group
// of NFOR_TERM_OFFSETS stored offsets.
// The terms and the row sums are stored in groups: stored offsets 4g..4g+3 of pixel p as the
// vec4 g * w * h + p (one store a group: lavapipe stores lane by lane, a vec4 as one); the
// column pass writes one plane per stored offset, as regress and gather read them.
#ifndef MCD_SHADERS_NFOR_DISTANCE_H
#define MCD_SHADERS_NFOR_DISTANCE_H

#include "nfor/nfor.h"

// `illumination` first writes, per pixel, three vec4s: C and v of each channel (zeros past
// the channels) and the divisor of each (1 where not divided, and past the channels), negated
// where the albedo is not trusted, so that `term` loads each end of a pair in three loads and
// divides nothing (a pair with an end not trusted multiplies back: the colours and variances
// of NforTerms up to rounding for albedos whose square is finite; past that, a variance 0).
#define NFOR_ILLUMINATION_COLOR 0
#define NFOR_ILLUMINATION_VARIANCE 1
#define NFOR_ILLUMINATION_ALBEDO 2
#define NFOR_ILLUMINATION_OUT 3
#define NFOR_ILLUMINATION_TRUST 4
#define NFOR_ILLUMINATION_BINDINGS 5
#define NFOR_ILLUMINATION_FLOATS 12

// `term` computes NFOR_TERM_OFFSETS consecutive stored offsets an invocation, a group (the
// count of stored offsets, 2R(R + 1), is a multiple of 4).
#define NFOR_TERM_OFFSETS 4
#define NFOR_TERM_ILLUMINATION 0
#define NFOR_TERM_OUT 1
#define NFOR_TERM_BINDINGS 2

// `box` sums NFOR_BOX_BLOCK outputs of a group an invocation, along its pass's axis, from
// the groups their patches read, fetched once.
#define NFOR_BOX_BLOCK 4
#define NFOR_BOX_IN 0
#define NFOR_BOX_OUT 1
#define NFOR_BOX_BINDINGS 2

#ifdef __cplusplus
#include <cstddef>
namespace mcd::shader {
struct NforDistancePush {
#else
layout(push_constant) uniform NforDistancePush {
#endif
    int width;
    int height;
    int radius;          // the regression window's half-size (the offsets)
    int patchRadius;     // box: the patch half-size
    int vertical;        // box: 0 rows, 1 columns (and the division)
    float alpha;         // term: the variance cancellation
    int albedoChannels;  // illumination: 0, or colour / albedo (where above the floor)
    int minVariance;     // term: normalise by 2 min(v_u, v_u+o) instead of v_u + v_u+o
    int trust;           // illumination: 1 where a trust plane marks the albedos to divide by
#ifdef __cplusplus
};
static_assert(sizeof(NforDistancePush) == 36);
static_assert(offsetof(NforDistancePush, albedoChannels) == 24);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
