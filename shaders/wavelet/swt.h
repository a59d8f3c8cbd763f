// The stationary (undecimated, "a trous") 2D wavelet transform: the coefficient layout and
// the constants its two kernels share (swt_analyze.h and swt_synthesize.h hold each one's
// bindings and push constants), read by GLSL, the host and the CPU reference (layout only,
// never arithmetic).
//
// Level j (0-based) filters with the DWT's analysis taps spread 2^j samples apart (holes)
// and does not decimate: along an axis of length n it maps a signal x to a low band L and
// a high band H of length n each, L(i) = sum_k h0[k] x(i + k 2^j), H(i) = sum_k h1[k]
// x(i + k 2^j) (both centred on i; Haar: taps at i and i + 2^j), with the DWT's
// symmetric extension (whole-sample for 5/3 and 9/7, half-sample for Haar). The taps keep
// the DWT's normalisation, so under white noise a band's coefficients have the variance
// of the decimated band's. The inverse is the mean of the two polyphase DWT
// reconstructions, x(m) = 1/2 sum_k (g0[k] L(m - k 2^j) + g1[k] H(m - k 2^j)) (Haar: the
// pair at m, and the pair at m - 2^j when m >= 2^j). An axis is transformed at level j
// only while n > 2^j (as the DWT stops at one coefficient): otherwise L = x and H = 0, its
// high bands are empty. Rows are transformed before columns.
//
// Coefficients: a C-channel w x h image becomes w x h x C (3 levels + 1) planes; channel c
// owns planes c (3 levels + 1) + SwtDetailPlane(level, orientation) (orientation 0 HL = x
// high, y low; 1 LH; 2 HH) and c (3 levels + 1) + SwtLowPlane(levels), the coarsest low
// band. Detail band b = (c levels + level) 3 + orientation (shaders/bayes/bayes.h) is
// plane b + c.
#ifndef MCD_SHADERS_WAVELET_SWT_H
#define MCD_SHADERS_WAVELET_SWT_H

// Specialization constants of both kernels (swt.glsl).
#define WAVELET_SWT_SPEC_BASIS 0  // MCD_WAVELET_*
#define WAVELET_SWT_SPEC_AXIS 1   // WAVELET_SWT_ROWS or WAVELET_SWT_COLUMNS
#define WAVELET_SWT_ROWS 0
#define WAVELET_SWT_COLUMNS 1
#define WAVELET_SWT_FUSED 2  // analysis, Haar only: a whole level (both axes) in one pass

// Push flags: which axes this level transforms.
#define WAVELET_SWT_TRANSFORM_X 1
#define WAVELET_SWT_TRANSFORM_Y 2

#ifdef __cplusplus
namespace mcd::shader {
inline int SwtPlaneCount(int levels) {
    return 3 * levels + 1;
}
inline int SwtDetailPlane(int level, int orientation) {
    return 3 * level + orientation;
}
inline int SwtLowPlane(int levels) {
    return 3 * levels;
}
// Whether an axis of length n is transformed at `level`.
inline bool SwtTransformsAxis(int n, int level) {
    return level < 31 && n > (1 << level);
}
}  // namespace mcd::shader
#endif

#endif
