// Auto stage 2, the guided windows (--auto-window colour): the error maps' mean over the
// (2r+1)^2 window clipped to the frame, of the finite values only (NaN where the window
// has none), each weighted by the tent (r + 1 - |u - x|)(r + 1 - |v - y|) times
// exp(-min(d / bandwidth^2, 40)), d the guide's relative colour distance between the two
// pixels: the mean over its channels of (a - b)^2 / (a^2 + b^2 + 0.01) (a channel's term 0
// where it is not finite). The windows keep to pixels of the guide's colour, so that the
// estimates are not mixed across the edges where the candidates' errors change. Not
// separable: one invocation per pixel, every plane at once (the weight is shared).
#ifndef MCD_SHADERS_AUTO_GUIDED_H
#define MCD_SHADERS_AUTO_GUIDED_H

#include "auto/auto.h"

#define AUTO_GUIDED_INPUT 0
#define AUTO_GUIDED_GUIDE 1
#define AUTO_GUIDED_OUTPUT 2
#define AUTO_GUIDED_BINDINGS 3
// Planes one dispatch smooths at most (the candidates' estimates).
#define AUTO_GUIDED_MAX_PLANES AUTO_MAX_CANDIDATES
// Guide channels at most.
#define AUTO_GUIDED_MAX_GUIDE_CHANNELS 4
// The colour distance's largest exponent: a weight of exp(-40) (about 4e-18) times an
// estimate down to about 1e-20 is still a normal float, so neither flushes to 0 on a GPU
// while the CPU twin's double keeps it.
#define AUTO_GUIDED_MAX_EXPONENT 40

#ifdef __cplusplus
#include <cstddef>
namespace mcd::shader {
struct AutoGuidedPush {
#else
layout(push_constant) uniform AutoGuidedPush {
#endif
    int width;
    int height;
    int radius;
    int planes;
    int guideChannels;
    float inverseBandwidth2;  // 1 / bandwidth^2
#ifdef __cplusplus
};
static_assert(sizeof(AutoGuidedPush) == 24);
static_assert(offsetof(AutoGuidedPush, inverseBandwidth2) == 20);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
