// AWR eq. 11: soft shrinkage of the detail coefficients of a Mallat-layout DWT,
// W = sign(W~) max(0, |W~| - cs * sqrt(var)), where var is the coefficient's variance from
// the squared-filter analysis (eq. 10). The coarsest low-low band (lowWidth x lowHeight at
// the top left) is kept. In place: `coef` is read and written.
#ifndef MCD_SHADERS_AWR_SHRINK_H
#define MCD_SHADERS_AWR_SHRINK_H

#define AWR_SHRINK_COEF 0
#define AWR_SHRINK_VARIANCE 1
#define AWR_SHRINK_BINDINGS 2
#define AWR_SHRINK_LOCAL_SIZE 64

#ifdef __cplusplus
#include <cstddef>
namespace mcd::shader {
struct AwrShrinkPush {
#else
layout(push_constant) uniform AwrShrinkPush {
#endif
    int width;      // of the coefficient image
    int height;
    int lowWidth;   // coarsest low-low band, kept as is
    int lowHeight;
    float cs;       // smoothing constant
#ifdef __cplusplus
};
static_assert(sizeof(AwrShrinkPush) == 20);
static_assert(offsetof(AwrShrinkPush, cs) == 16);
}  // namespace mcd::shader
#else
} push;
#endif

#endif
