// One level of the 2D inverse DWT (columns, then rows) by lifting. Reads the low-low band
// (compact) from `low` and the detail bands from `coef` in the Mallat layout, writes the
// level's region, compact, into `dst`. Specialization constant 0 selects the basis.
#ifndef MCD_SHADERS_WAVELET_SYNTHESIZE_H
#define MCD_SHADERS_WAVELET_SYNTHESIZE_H

#include "wavelet/tile.h"

#define WAVELET_SYNTHESIZE_LOW 0
#define WAVELET_SYNTHESIZE_COEF 1
#define WAVELET_SYNTHESIZE_DST 2
#define WAVELET_SYNTHESIZE_BINDINGS 3

#ifdef __cplusplus
#include <cstddef>
namespace mcd::shader {
struct WaveletSynthesizePush {
#else
layout(push_constant) uniform WaveletSynthesizePush {
#endif
    int width;       // extent of the level's region (the output), in positions
    int height;
    int lowStride;
    int lowPlane;
    int coefStride;
    int coefPlane;
    int dstStride;
    int dstPlane;
#ifdef __cplusplus
};
static_assert(sizeof(WaveletSynthesizePush) == 32);
static_assert(offsetof(WaveletSynthesizePush, lowStride) == 8);
static_assert(offsetof(WaveletSynthesizePush, coefStride) == 16);
static_assert(offsetof(WaveletSynthesizePush, dstPlane) == 28);
}  // namespace mcd::shader
#else
} push;
#endif

#endif
