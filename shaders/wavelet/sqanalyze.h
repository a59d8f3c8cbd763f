// One level of the squared-filter analysis of AWR eqs. 9-10 (appendix B): the variance of
// each coefficient as the sum of squared filter taps times per-pixel variances, as a
// direct separable convolution (lifting has no squared form). Same bindings and layout as
// analyze. The squared 1D low (high) taps are renormalised to sum to lowSum (highSum);
// a value <= 0 keeps the natural sum.
#ifndef MCD_SHADERS_WAVELET_SQANALYZE_H
#define MCD_SHADERS_WAVELET_SQANALYZE_H

#include "wavelet/tile.h"

#define WAVELET_SQANALYZE_SRC 0
#define WAVELET_SQANALYZE_COEF 1
#define WAVELET_SQANALYZE_LOW 2
#define WAVELET_SQANALYZE_BINDINGS 3

#ifdef __cplusplus
#include <cstddef>
namespace mcd::shader {
struct WaveletSqAnalyzePush {
#else
layout(push_constant) uniform WaveletSqAnalyzePush {
#endif
    int width;
    int height;
    int srcStride;
    int srcPlane;
    int coefStride;
    int coefPlane;
    int lowStride;
    int lowPlane;
    float lowSum;
    float highSum;
#ifdef __cplusplus
};
static_assert(sizeof(WaveletSqAnalyzePush) == 40);
static_assert(offsetof(WaveletSqAnalyzePush, lowPlane) == 28);
static_assert(offsetof(WaveletSqAnalyzePush, lowSum) == 32);
static_assert(offsetof(WaveletSqAnalyzePush, highSum) == 36);
}  // namespace mcd::shader
#else
} push;
#endif

#endif
