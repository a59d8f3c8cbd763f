// Method `bayes` over the stationary wavelet transform (--bayes-transform swt), per-band
// moments: one workgroup per detail band of the full-size bands in the layout of
// shaders/wavelet/swt.h (band b of channel c is plane b + c) writes E[y^2], E[y^4], max |y|
// and the count (bayes.h), as moments.h does for the DWT's bands. A band whose axis is not
// transformed at its level (shaders/wavelet/swt.h) is empty: count 0.
#ifndef MCD_SHADERS_BAYES_SWT_MOMENTS_H
#define MCD_SHADERS_BAYES_SWT_MOMENTS_H

#define BAYES_SWT_MOMENTS_COEF 0  // read as a float texel buffer
#define BAYES_SWT_MOMENTS_OUT 1
#define BAYES_SWT_MOMENTS_BINDINGS 2
#define BAYES_SWT_MOMENTS_LOCAL_SIZE 256

#ifdef __cplusplus
namespace mcd::shader {
struct BayesSwtMomentsPush {
#else
layout(push_constant) uniform BayesSwtMomentsPush {
#endif
    int width;
    int height;
    int levels;
#ifdef __cplusplus
};
static_assert(sizeof(BayesSwtMomentsPush) == 12);
}  // namespace mcd::shader
#else
}
push;

// Whether band `inChannel` (level * 3 + orientation) holds coefficients.
bool BayesSwtBandUsed(int inChannel) {
    int level = inChannel / 3, orientation = inChannel % 3;
    bool tx = level < 31 && push.width > (1 << level);
    bool ty = level < 31 && push.height > (1 << level);
    return orientation == 0 ? tx : (orientation == 1 ? ty : tx && ty);
}
#endif

#endif
