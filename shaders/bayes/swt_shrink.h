// Method `bayes` over the stationary wavelet transform (--bayes-transform swt), shrinkage:
// in place on the full-size bands in the layout of shaders/wavelet/swt.h (band b of channel
// c is plane b + c), every detail coefficient through its band's table, as shrink.h does
// for the DWT's bands. Empty bands (an axis not transformed at their level) are left as
// they are (zeros).
#ifndef MCD_SHADERS_BAYES_SWT_SHRINK_H
#define MCD_SHADERS_BAYES_SWT_SHRINK_H

#define BAYES_SWT_SHRINK_COEF 0  // read-write
#define BAYES_SWT_SHRINK_PARAMS 1
#define BAYES_SWT_SHRINK_TABLE 2  // read as a float texel buffer
#define BAYES_SWT_SHRINK_BINDINGS 3
#define BAYES_SWT_SHRINK_LOCAL_SIZE 64

#ifdef __cplusplus
namespace mcd::shader {
struct BayesSwtShrinkPush {
#else
layout(push_constant) uniform BayesSwtShrinkPush {
#endif
    int width;
    int height;
    int levels;
#ifdef __cplusplus
};
static_assert(sizeof(BayesSwtShrinkPush) == 12);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
