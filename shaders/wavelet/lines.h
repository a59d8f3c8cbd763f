// Bindings and push constants of one pass of the line-lifting wavelet kernels (analyze and
// synthesize share them), for GLSL and C++.
#ifndef MCD_SHADERS_WAVELET_LINES_H
#define MCD_SHADERS_WAVELET_LINES_H

#include "wavelet/tile.h"

// Bindings and push constants of one pass (analyze and synthesize share them).
#define WAVELET_LINES_SRC 0
#define WAVELET_LINES_DST 1
#define WAVELET_LINES_BINDINGS 2

#ifdef __cplusplus
#include <cstddef>
namespace mcd::shader {
struct WaveletLinesPush {
#else
layout(push_constant) uniform WaveletLinesPush {
#endif
    int width;      // extent of this level's region, in positions
    int height;
    int srcStride;  // floats per row of src
    int srcPlane;   // floats per channel plane of src
    int dstStride;
    int dstPlane;
#ifdef WAVELET_LINES_EXTRA_PUSH
    WAVELET_LINES_EXTRA_PUSH  // fields a kernel appends (GLSL; C++ wraps the struct)
#endif
#ifdef __cplusplus
};
static_assert(sizeof(WaveletLinesPush) == 24);
static_assert(offsetof(WaveletLinesPush, srcStride) == 8);
static_assert(offsetof(WaveletLinesPush, dstStride) == 16);
static_assert(offsetof(WaveletLinesPush, dstPlane) == 20);
}  // namespace mcd::shader
#else
} push;
#endif

#endif
