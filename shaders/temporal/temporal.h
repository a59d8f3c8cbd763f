// Constants shared by the temporal kernels (a frame of a sequence gathered with its
// neighbours: docs/sequences.md) and their host code. The CPU reference
// (cpu_reference/temporal.cpp) keeps its own copies.
//
// Features: each frame's guides packed in one 8-plane image, so that one binding carries
// them: the normal (3 planes), the depth, the albedo (3) and the object id, each present
// or not by a bit of a mask.
//
// Positions: where a pixel of the current frame lies in another frame of the sequence, in
// that frame's pixels (x right, y down, the pixel (x, y) covering [x, x+1) x [y, y+1)), two
// planes (x, then y); NaN where it is lost (off the frame, or the chain of motion vectors
// that leads there broke).
//
// Motion: Blender Cycles' Vector pass, as measured on Cycles 3.4
// (scripts/blender/vector_pass.py): 4 planes in pixels, x right and y UP, (X, Y) the
// pixel's position in the previous frame minus its position in this one, (Z, W) its
// position in this frame minus its position in the next one. In our positions (y down):
// previous = (x + X, y - Y), next = (x - Z, y + W).
#ifndef MCD_SHADERS_TEMPORAL_TEMPORAL_H
#define MCD_SHADERS_TEMPORAL_TEMPORAL_H

#define TEMPORAL_LOCAL_SIZE 64

#define TEMPORAL_FEATURE_NORMAL 0  // planes 0-2
#define TEMPORAL_FEATURE_DEPTH 3
#define TEMPORAL_FEATURE_ALBEDO 4  // planes 4-6
#define TEMPORAL_FEATURE_ID 7
#define TEMPORAL_FEATURE_PLANES 8

#define TEMPORAL_HAS_NORMAL 1
#define TEMPORAL_HAS_DEPTH 2
#define TEMPORAL_HAS_ALBEDO 4
#define TEMPORAL_HAS_ID 8

// Albedos are compared relative to the larger of the two, or to this where both are darker.
#define TEMPORAL_ALBEDO_FLOOR 0.05

#endif
