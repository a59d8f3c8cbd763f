// Line geometry of the wavelet kernels, shared by GLSL and C++. Measured on lavapipe,
// shared memory and barriers cost more than a second pass over global memory, so a 2D
// level runs as two dispatches that each filter whole lines in registers: a rows pass (one
// invocation per row segment, contiguous and vec4-wide when aligned) into an interleaved
// temporary, then a columns pass (one invocation per column segment, neighbouring
// invocations on neighbouring columns). A segment is WAVELET_TILE positions read with a
// WAVELET_HALO-wide apron on each side, the reach of the four CDF 9/7 lifting steps and of
// the 9-tap filters. Measured too: one lane owning four columns as vec4s makes the columns
// passes slower (lifting and convolution alike), and so do two as vec2s. The segment is
// short because the code is unrolled over it and lavapipe runs faster on less code: the
// 2048x2048 5-level bench's CPU time per forward + inverse fell about a fifth from 56 to
// 16 positions (8 and 12 were slower again, 24 and 40 in between, 120 slower still).
#ifndef MCD_SHADERS_WAVELET_TILE_H
#define MCD_SHADERS_WAVELET_TILE_H

#define WAVELET_TILE 16
#define WAVELET_HALO 4
#define WAVELET_TILE_EXT (WAVELET_TILE + 2 * WAVELET_HALO)
#define WAVELET_LOCAL_SIZE 64  // lines per workgroup

// Specialization constants of the analyze and synthesize kernels.
#define WAVELET_SPEC_BASIS 0  // MCD_WAVELET_*
#define WAVELET_SPEC_AXIS 1   // WAVELET_AXIS_*
#define WAVELET_SPEC_VEC4 2   // 1: rows pass may use vec4 access (strides are multiples of 4)
#define WAVELET_SPEC_PART 3   // WAVELET_PART_*: which segments along the filtered axis
#define WAVELET_AXIS_ROWS 0
#define WAVELET_AXIS_COLUMNS 1

// Segments a pass's dispatch covers along its filtered axis of length n. A segment is
// interior when its apron lies inside the axis (segment s >= 1 with s * TILE + TILE +
// HALO <= n, the first InteriorSegments(n) after segment 0); the others fold their loads.
// Lavapipe runs both sides of a branch under a mask, so a dispatch whose segments take
// both paths pays both everywhere: large passes run as one dispatch of the interior
// segments (no folding code at all) and one of the edge segments (folding only), where
// the axis has at least WAVELET_SPLIT_LENGTH positions (below it, one dispatch costs less
// than two).
#define WAVELET_SPLIT_LENGTH 256
#define WAVELET_PART_ALL 0       // every segment, either path (short axes)
#define WAVELET_PART_INTERIOR 1  // group g: segment g + 1, all interior
#define WAVELET_PART_EDGES 2     // group 0: segment 0; group g > 0: InteriorSegments(n) + g


#endif
