// One level of the 2D forward DWT, as two dispatches of this kernel: the rows pass
// (specialization WAVELET_SPEC_AXIS = WAVELET_AXIS_ROWS) filters the region's rows of `src`
// into `dst`, an interleaved temporary (position x keeps coefficient x); the columns pass
// filters the temporary's columns and writes all four bands into `dst` in the Mallat
// layout of host/wavelet.h (low-low band at the top left). Each line is filtered by direct
// convolutions with the filter bank of AWR appendix A (convolve.glsl, shared with
// sqanalyze.comp): measured on lavapipe about a quarter faster than the four in-place
// lifting steps, the same result up to round-off. WAVELET_SPEC_BASIS selects the basis
// (MCD_WAVELET_*). Bindings and push constants: WAVELET_LINES_* and WaveletLinesPush in
// lines.h.
#ifndef MCD_SHADERS_WAVELET_ANALYZE_H
#define MCD_SHADERS_WAVELET_ANALYZE_H

#include "wavelet/lines.h"

#endif
