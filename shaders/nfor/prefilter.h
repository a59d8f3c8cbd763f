// nfor stage 3: each feature plane filtered by NL-means on itself (NFOR 5.1): over the
// (2 radius + 1)^2 window, weight exp(-max(0, d) / bandwidth^2) (1 at the pixel itself,
// 0 where the exponent exceeds NFOR_EXP_CUT), d the mean over the patch positions inside
// at both ends of ((f_p - f_q)^2 - (v_p + v_q)) / (v_p + v_q + NFOR_REL_EPS (f_p^2 + f_q^2)
// + NFOR_TINY), each term at most NFOR_TERM_MAX; v the plane's estimated variance. Where
// a feature is sharp (v = 0) only equal patches mix. One invocation per pixel and plane.
#ifndef MCD_SHADERS_NFOR_PREFILTER_H
#define MCD_SHADERS_NFOR_PREFILTER_H

#include "nfor/nfor.h"

#define NFOR_PREFILTER_FEATURES 0
#define NFOR_PREFILTER_VARIANCE 1
#define NFOR_PREFILTER_OUT 2
#define NFOR_PREFILTER_BINDINGS 3

#ifdef __cplusplus
#include <cstddef>
namespace mcd::shader {
struct NforPrefilterPush {
#else
layout(push_constant) uniform NforPrefilterPush {
#endif
    int width;
    int height;
    int radius;       // 1..NFOR_PREFILTER_MAX_RADIUS
    int patchRadius;  // 0..NFOR_PREFILTER_MAX_PATCH
    float bandwidth;
#ifdef __cplusplus
};
static_assert(sizeof(NforPrefilterPush) == 20);
static_assert(offsetof(NforPrefilterPush, bandwidth) == 16);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
