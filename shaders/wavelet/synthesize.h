// One level of the 2D inverse DWT by lifting, as two dispatches of this kernel: the
// columns pass (WAVELET_SPEC_AXIS = WAVELET_AXIS_COLUMNS) reads the four bands of the
// region from `src` in the Mallat layout and undoes the column lifting into `dst`, an
// interleaved temporary; the rows pass undoes the row lifting of the temporary into `dst`,
// the region's samples. WAVELET_SPEC_BASIS selects the basis (MCD_WAVELET_*).
#ifndef MCD_SHADERS_WAVELET_SYNTHESIZE_H
#define MCD_SHADERS_WAVELET_SYNTHESIZE_H

#include "wavelet/tile.h"

#define WAVELET_SYNTHESIZE_SRC 0
#define WAVELET_SYNTHESIZE_DST 1
#define WAVELET_SYNTHESIZE_BINDINGS 2

#ifdef __cplusplus
#include <cstddef>
namespace mcd::shader {
struct WaveletSynthesizePush {
#else
layout(push_constant) uniform WaveletSynthesizePush {
#endif
    int width;      // extent of this level's region, in positions
    int height;
    int srcStride;  // floats per row of src
    int srcPlane;   // floats per channel plane of src
    int dstStride;
    int dstPlane;
#ifdef __cplusplus
};
static_assert(sizeof(WaveletSynthesizePush) == 24);
static_assert(offsetof(WaveletSynthesizePush, srcStride) == 8);
static_assert(offsetof(WaveletSynthesizePush, dstStride) == 16);
static_assert(offsetof(WaveletSynthesizePush, dstPlane) == 20);
}  // namespace mcd::shader
#else
} push;
#endif

#endif
