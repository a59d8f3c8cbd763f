// The columns pass of one synthesis level with AWR's soft shrinkage (eq. 11) fused into
// its reads: laid out like synthesize (WaveletLinesPush, src = the bands, dst = the
// interleaved temporary), plus the per-coefficient variances in the layout of `src`
// (same strides) and cs after the line push. Each detail coefficient w becomes
// sign(w) max(0, |w| - cs sqrt(var)) before the column lifting, the arithmetic of
// shaders/awr/shrink.comp; the low-low band of the level passes through. Run from the
// coarsest level to the finest, every detail band of the transform is shrunk exactly once,
// the coarsest low-low band never: the result is that of shrink then synthesize. The rows
// pass is the plain synthesize kernel's.
#ifndef MCD_SHADERS_WAVELET_SYNTHESIZE_SHRINK_H
#define MCD_SHADERS_WAVELET_SYNTHESIZE_SHRINK_H

#include "wavelet/lines.h"

#define WAVELET_SYNTHESIZE_SHRINK_VARIANCE 2
#define WAVELET_SYNTHESIZE_SHRINK_BINDINGS 3

#ifdef __cplusplus
namespace mcd::shader {
struct WaveletSynthesizeShrinkPush {
    WaveletLinesPush lines;
    float cs;
};
static_assert(sizeof(WaveletSynthesizeShrinkPush) == 28);
static_assert(offsetof(WaveletSynthesizeShrinkPush, cs) == 24);
}  // namespace mcd::shader
#endif

#endif
