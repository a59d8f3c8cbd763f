// Tiling of the 2D wavelet kernels, shared by GLSL and C++: a workgroup owns a
// WAVELET_TILE^2 block of positions and loads it with a WAVELET_HALO-wide apron (the
// reach of the four CDF 9/7 lifting steps), so row and column passes of one level run in
// shared memory with one read and one write of global memory.
#ifndef MCD_SHADERS_WAVELET_TILE_H
#define MCD_SHADERS_WAVELET_TILE_H

#define WAVELET_TILE 32
#define WAVELET_HALO 4
#define WAVELET_TILE_EXT (WAVELET_TILE + 2 * WAVELET_HALO)
#define WAVELET_LOCAL_SIZE 256

#endif
