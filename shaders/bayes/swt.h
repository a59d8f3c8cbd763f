// Method `bayes` over the stationary wavelet transform (--bayes-transform swt): the
// per-band moments (swt_moments.comp) and the shrinkage (swt_shrink.comp) of full-size
// bands in the layout of shaders/wavelet/swt.h (band b of channel c is plane b + c). A band
// whose axis is not transformed at its level (shaders/wavelet/swt.h) is empty: count 0,
// coefficients left as they are (zeros). Everything else as moments.h and shrink.h.
#ifndef MCD_SHADERS_BAYES_SWT_H
#define MCD_SHADERS_BAYES_SWT_H

#define BAYES_SWT_COEF 0     // moments: read as a float texel buffer; shrink: read-write
#define BAYES_SWT_MOMENTS 1  // moments only
#define BAYES_SWT_PARAMS 1   // shrink only
#define BAYES_SWT_TABLE 2    // shrink only; read as a float texel buffer
#define BAYES_SWT_MOMENTS_BINDINGS 2
#define BAYES_SWT_SHRINK_BINDINGS 3
#define BAYES_SWT_MOMENTS_LOCAL_SIZE 256
#define BAYES_SWT_SHRINK_LOCAL_SIZE 64

#ifdef __cplusplus
namespace mcd::shader {
struct BayesSwtPush {
#else
layout(push_constant) uniform BayesSwtPush {
#endif
    int width;
    int height;
    int levels;
#ifdef __cplusplus
};
static_assert(sizeof(BayesSwtPush) == 12);
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
