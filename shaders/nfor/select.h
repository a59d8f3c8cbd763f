// nfor stage 7: the bandwidth per pixel. SURE of candidate k at pixel u, the sum over the
// channels of (y_k - C)^2 - v + 2 v h_k (y_k its output, C the clamped colour, v the
// variance, h_k its fit's influence at u), averaged over the (2 r + 1)^2 window clipped to
// the frame; the candidate with the smallest average (ties: the first) gives the output,
// its index the choice. One invocation per pixel.
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
    int radius;      // 0..NFOR_SURE_MAX_RADIUS
#ifdef __cplusplus
};
static_assert(sizeof(NforSelectPush) == 16);
static_assert(offsetof(NforSelectPush, radius) == 12);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
