// Temporal stage 2: fold one frame's layer into the running state of the gathered frame,
// one invocation per pixel p and channel c. The frame's value x is its layer at the pixel
// q its position P(p) falls in (q = floor(P)), or at p itself with TEMPORAL_FOLD_CENTRES
// (the current frame), with the sample's weight w (stage 1; 0: not accepted). Nothing
// changes where w <= 0, except as TEMPORAL_FOLD_FIRST says. Modes:
//   MOMENTS  running weighted mean A and sum of weighted squared deviations B (West's
//            update): W' = W + w, d = x - A, A += d (w / W'), B += w d (x - A); W is the
//            weights folded before this frame (plane 0 of binding TOTAL, COUNT's state).
//   SUM      A += x, w x or w^2 x (power 0, 1, 2): histograms, half sums, pooled variances.
//   MIN/MAX  A = x where x is finite and below (above) A, or A is not finite.
//   COUNT    A += w, B += 1 (x not read): the weights and the count of accepted frames.
// TEMPORAL_FOLD_FIRST: the state starts here (not read): as the fold of x into an empty
// state (A = x, B = 0 for MOMENTS; A = (w or w^2 or 1) x for SUM; A = w, B = 1 for COUNT;
// zeros where w <= 0), and for MIN/MAX A = x whatever w. Values that are not finite are
// folded as they are (the result says so), except by MIN/MAX, which leave them out.
// The state is one buffer: A in planes [0, channels), B (MOMENTS, COUNT) in the next
// `channels`; COUNT takes one channel.
#ifndef MCD_SHADERS_TEMPORAL_FOLD_H
#define MCD_SHADERS_TEMPORAL_FOLD_H

#include "temporal/temporal.h"

#define TEMPORAL_FOLD_VALUE 0     // channels planes: the frame's layer
#define TEMPORAL_FOLD_POSITION 1  // 2 planes: positions in the frame
#define TEMPORAL_FOLD_WEIGHT 2    // 1 plane
#define TEMPORAL_FOLD_TOTAL 3     // COUNT's state: plane 0 the weights folded before (MOMENTS)
#define TEMPORAL_FOLD_STATE 4     // A, then B: read and written
#define TEMPORAL_FOLD_BINDINGS 5

#define TEMPORAL_FOLD_MOMENTS 0
#define TEMPORAL_FOLD_SUM 1
#define TEMPORAL_FOLD_MIN 2
#define TEMPORAL_FOLD_MAX 3
#define TEMPORAL_FOLD_COUNT 4

#define TEMPORAL_FOLD_FIRST 1
#define TEMPORAL_FOLD_CENTRES 2

#ifdef __cplusplus
#include <cstddef>
namespace mcd::shader {
struct TemporalFoldPush {
#else
layout(push_constant) uniform TemporalFoldPush {
#endif
    int width;
    int height;
    int channels;
    int mode;   // TEMPORAL_FOLD_MOMENTS ...
    int power;  // SUM: 0, 1 or 2
    int flags;  // TEMPORAL_FOLD_FIRST, TEMPORAL_FOLD_CENTRES
#ifdef __cplusplus
};
static_assert(sizeof(TemporalFoldPush) == 24);
static_assert(offsetof(TemporalFoldPush, flags) == 20);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
