// One level of the 2D forward DWT by lifting, as two dispatches of this kernel: the rows
// pass (specialization WAVELET_SPEC_AXIS = WAVELET_AXIS_ROWS) lifts the region's rows of
// `src` into `dst`, an interleaved temporary (position x keeps coefficient x); the columns
// pass lifts the temporary's columns and writes all four bands into `dst` in the Mallat
// layout of host/wavelet.h (low-low band at the top left). WAVELET_SPEC_BASIS selects the
// basis (MCD_WAVELET_*).
#ifndef MCD_SHADERS_WAVELET_ANALYZE_H
#define MCD_SHADERS_WAVELET_ANALYZE_H

#include "wavelet/tile.h"

#define WAVELET_ANALYZE_SRC 0
#define WAVELET_ANALYZE_DST 1
#define WAVELET_ANALYZE_BINDINGS 2

#ifdef __cplusplus
#include <cstddef>
namespace mcd::shader {
struct WaveletAnalyzePush {
#else
layout(push_constant) uniform WaveletAnalyzePush {
#endif
    int width;      // extent of this level's region, in positions
    int height;
    int srcStride;  // floats per row of src
    int srcPlane;   // floats per channel plane of src
    int dstStride;
    int dstPlane;
#ifdef __cplusplus
};
static_assert(sizeof(WaveletAnalyzePush) == 24);
static_assert(offsetof(WaveletAnalyzePush, srcStride) == 8);
static_assert(offsetof(WaveletAnalyzePush, dstStride) == 16);
static_assert(offsetof(WaveletAnalyzePush, dstPlane) == 20);
}  // namespace mcd::shader
#else
} push;
#endif

#endif
