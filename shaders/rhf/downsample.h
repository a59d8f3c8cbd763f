// RHF Gaussian downsampling D_s (paper eq. 8) as the tool samples, one axis at a time:
// dst(x) = sum_i g(i) src(mirror(step * x + step / 2 - radius + i)), i in [0, 2 radius],
// for every plane of a planar image (step / 2 = floor((x + 0.5) step) - step x).
// The normalised weights g come in a buffer. The x pass makes dstWidth x srcHeight, the y
// pass srcWidth x dstHeight.
#ifndef MCD_SHADERS_RHF_DOWNSAMPLE_H
#define MCD_SHADERS_RHF_DOWNSAMPLE_H

#define RHF_DOWNSAMPLE_SRC 0
#define RHF_DOWNSAMPLE_DST 1
#define RHF_DOWNSAMPLE_WEIGHTS 2
#define RHF_DOWNSAMPLE_BINDINGS 3
#define RHF_DOWNSAMPLE_LOCAL_SIZE 64

#ifdef __cplusplus
#include <cstddef>
namespace mcd::shader {
struct RhfDownsamplePush {
#else
layout(push_constant) uniform RhfDownsamplePush {
#endif
    int srcWidth;
    int srcHeight;
    int dstWidth;  // of the result
    int dstHeight;
    int step;    // 2^s
    int radius;  // weights hold 2 radius + 1 taps
    int axis;    // 0: along x, 1: along y
#ifdef __cplusplus
};
static_assert(sizeof(RhfDownsamplePush) == 28);
static_assert(offsetof(RhfDownsamplePush, axis) == 24);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
