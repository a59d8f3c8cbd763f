// Auto stage 2: the error maps' box mean over a (2r+1)^2 window clipped to the frame, of
// the finite values only (NaN where the window has none): SURE is unbiased per pixel but
// noisy, the mean over a window is not. One invocation per pixel and plane.
#ifndef MCD_SHADERS_AUTO_SMOOTH_H
#define MCD_SHADERS_AUTO_SMOOTH_H

#include "auto/auto.h"

#define AUTO_SMOOTH_INPUT 0
#define AUTO_SMOOTH_OUTPUT 1
#define AUTO_SMOOTH_BINDINGS 2

#ifdef __cplusplus
#include <cstddef>
namespace mcd::shader {
struct AutoSmoothPush {
#else
layout(push_constant) uniform AutoSmoothPush {
#endif
    int width;
    int height;
    int radius;
#ifdef __cplusplus
};
static_assert(sizeof(AutoSmoothPush) == 12);
static_assert(offsetof(AutoSmoothPush, radius) == 8);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
