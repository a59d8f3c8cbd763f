// One level of the squared-filter analysis of AWR eqs. 9-10 (appendix B): the variance of
// each coefficient as the sum of squared filter taps times per-pixel variances, as direct
// separable convolutions (lifting has no squared form; convolve.glsl, shared with
// analyze.comp). Two dispatches of this kernel, laid out like analyze: a rows pass from
// `src` into an interleaved temporary, a columns pass from it into the four bands of `dst`
// (Mallat layout). The squared 1D low (high) taps are renormalised to sum to lowSum
// (highSum); a value <= 0 keeps the natural sum. Bindings: WAVELET_LINES_* in lines.h.
#ifndef MCD_SHADERS_WAVELET_SQANALYZE_H
#define MCD_SHADERS_WAVELET_SQANALYZE_H

#include "wavelet/lines.h"

#ifdef __cplusplus
namespace mcd::shader {
struct WaveletSqAnalyzePush {
    WaveletLinesPush lines;
    float lowSum;
    float highSum;
};
static_assert(sizeof(WaveletSqAnalyzePush) == 32);
static_assert(offsetof(WaveletSqAnalyzePush, lowSum) == 24);
}  // namespace mcd::shader
#endif

#endif
