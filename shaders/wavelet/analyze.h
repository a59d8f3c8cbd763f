// One level of the 2D forward DWT by lifting, as two dispatches of this kernel: the rows
// pass (specialization WAVELET_SPEC_AXIS = WAVELET_AXIS_ROWS) lifts the region's rows of
// `src` into `dst`, an interleaved temporary (position x keeps coefficient x); the columns
// pass lifts the temporary's columns and writes all four bands into `dst` in the Mallat
// layout of host/wavelet.h (low-low band at the top left). WAVELET_SPEC_BASIS selects the
// basis (MCD_WAVELET_*). Bindings and push constants: WaveletLinesPush in lines.h.
#ifndef MCD_SHADERS_WAVELET_ANALYZE_H
#define MCD_SHADERS_WAVELET_ANALYZE_H

#include "wavelet/lines.h"

#endif
