// One level of the 2D forward DWT (rows, then columns) by lifting. Reads the level's
// region from `src`, writes the three detail bands into `coef` in the Mallat layout of
// host/wavelet.h and the low-low band, compact, into `low` (which may be `coef` itself on
// the last level). Specialization constant 0 selects the basis (MCD_WAVELET_*).
#ifndef MCD_SHADERS_WAVELET_ANALYZE_H
#define MCD_SHADERS_WAVELET_ANALYZE_H

#include "wavelet/tile.h"

#define WAVELET_ANALYZE_SRC 0
#define WAVELET_ANALYZE_COEF 1
#define WAVELET_ANALYZE_LOW 2
#define WAVELET_ANALYZE_BINDINGS 3

#ifdef __cplusplus
#include <cstddef>
namespace mcd::shader {
struct WaveletAnalyzePush {
#else
layout(push_constant) uniform WaveletAnalyzePush {
#endif
    int width;       // extent of this level's region, in positions
    int height;
    int srcStride;   // floats per row of src
    int srcPlane;    // floats per channel plane of src
    int coefStride;
    int coefPlane;
    int lowStride;
    int lowPlane;
#ifdef __cplusplus
};
static_assert(sizeof(WaveletAnalyzePush) == 32);
static_assert(offsetof(WaveletAnalyzePush, srcStride) == 8);
static_assert(offsetof(WaveletAnalyzePush, coefStride) == 16);
static_assert(offsetof(WaveletAnalyzePush, lowPlane) == 28);
}  // namespace mcd::shader
#else
} push;
#endif

#endif
