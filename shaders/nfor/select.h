// nfor stage 7: the bandwidth per pixel. SURE of candidate k at pixel u, the sum over the
// channels of (y_k - C)^2 - v + 2 v h_k (y_k its output, C the clamped colour, v the
// variance, h_k its fit's influence at u), averaged over the (2 r + 1)^2 window clipped to
// the frame; the candidate with the smallest average (ties: the first) gives the output,
// its index the choice. With agreement > 0 the choice is by agreement instead: candidate
// k > 0 (a wider window than candidate 0's) is taken where its disagreement with candidate
// 0, the channels' mean of (y_k - y_0)^2 over (the channels' mean of y_0)^2 +
// NFOR_AGREEMENT_FLOOR, averaged over the same window, is below agreement (the last such
// k); elsewhere candidate 0: the wide window's fit where the narrow one says it has no
// bias to add. One invocation per pixel; by SURE a workgroup (NFOR_LOCAL_SIZE pixels of a
// row) first makes each pixel's SURE its windows read once, in shared memory, a candidate
// at a time.
#ifndef MCD_SHADERS_NFOR_SELECT_H
#define MCD_SHADERS_NFOR_SELECT_H

#include "nfor/nfor.h"

#define NFOR_SELECT_COLOR 0
#define NFOR_SELECT_VARIANCE 1
#define NFOR_SELECT_CANDIDATES 2  // candidate k's output at planes k * channels..
#define NFOR_SELECT_HAT 3         // candidate k's influence at plane k
#define NFOR_SELECT_OUT 4
#define NFOR_SELECT_CHOICE 5
#define NFOR_SELECT_BINDINGS 6

// The magnitude floor of the disagreement: dark pixels compare absolutely.
#define NFOR_AGREEMENT_FLOOR 1e-3

#ifdef __cplusplus
#include <cstddef>
namespace mcd::shader {
struct NforSelectPush {
#else
layout(push_constant) uniform NforSelectPush {
#endif
    int width;
    int height;
    int candidates;  // 1..NFOR_MAX_CANDIDATES
    int radius;       // 0..NFOR_SURE_MAX_RADIUS
    float agreement;  // > 0: choose by agreement with candidate 0 below this; 0: SURE
#ifdef __cplusplus
};
static_assert(sizeof(NforSelectPush) == 20);
static_assert(offsetof(NforSelectPush, radius) == 12);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
