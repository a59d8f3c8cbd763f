// One level of the 2D inverse DWT, as two dispatches of this kernel: the columns pass
// (WAVELET_SPEC_AXIS = WAVELET_AXIS_COLUMNS) reads the four bands of the region from `src`
// in the Mallat layout and undoes the column transform into `dst`, an interleaved
// temporary; the rows pass undoes the row transform of the temporary into `dst`, the
// region's samples. Each line is filtered by direct convolutions with the impulse
// responses of the inverse lifting (synthesize.glsl). WAVELET_SPEC_BASIS selects the basis
// (MCD_WAVELET_*). Bindings and push constants: WaveletLinesPush in lines.h.
#ifndef MCD_SHADERS_WAVELET_SYNTHESIZE_H
#define MCD_SHADERS_WAVELET_SYNTHESIZE_H

#include "wavelet/lines.h"

#endif
