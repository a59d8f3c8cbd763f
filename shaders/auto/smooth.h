// Auto stage 2: the error maps' tent-weighted mean over a (2r+1)^2 window clipped to the
// frame, of the finite values only (NaN where the window has none): SURE is unbiased per
// pixel but noisy, the mean over a window is not. The weight of (u, v) around (x, y) is
// (r + 1 - |u - x|)(r + 1 - |v - y|): it falls to zero at the window's edge, so a large
// error does not draw the window's square into the weights as a box would. Two passes,
// one invocation per pixel and plane each: the rows' weighted sums and weights of finite
// values into a scratch of two planes per plane, then the columns' weighted sums of those
// and the quotient.
#ifndef MCD_SHADERS_AUTO_SMOOTH_H
#define MCD_SHADERS_AUTO_SMOOTH_H

#include "auto/auto.h"

#define AUTO_SMOOTH_INPUT 0
#define AUTO_SMOOTH_SCRATCH 1  // 2 planes per input plane: the row sums, the row weights
#define AUTO_SMOOTH_OUTPUT 2
#define AUTO_SMOOTH_BINDINGS 3

#define AUTO_SMOOTH_SPEC_PASS 0
#define AUTO_SMOOTH_PASS_ROWS 0
#define AUTO_SMOOTH_PASS_COLUMNS 1

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
