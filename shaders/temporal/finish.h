// Temporal stage 3: the gathered frame's layer from the folded state, one invocation per
// pixel and channel. With W the weights and n the count of accepted frames (fold's COUNT),
// A the weighted mean and B the weighted squared deviations (fold's MOMENTS):
//   mean      A where n > 0; else the current frame's own value (RAW: nothing was
//             accepted, not even the current frame's sample, whose colour was not finite).
//   variance  of the mean: with TEMPORAL_FINISH_POOLED, from the frames' own variances,
//             V / W^2 where V = sum w^2 v (fold's SUM, power 2); else from the spread of the
//             frames, B / ((n - 1) W) where n >= 2, and where n < 2 the spread per unit
//             weight pooled over the (2r+1)^2 window of pixels with n >= 2 (clipped to
//             the frame), sum B / sum (n - 1), over W; 0 where W <= 0, or where that window
//             has no such pixel.
//   halves    with TEMPORAL_FINISH_HALVES: S_k / W_k, the weighted means of the frames at
//             even (k = 0) and odd (k = 1) distances from the current frame; the mean
//             where a half has no weight.
#ifndef MCD_SHADERS_TEMPORAL_FINISH_H
#define MCD_SHADERS_TEMPORAL_FINISH_H

#include "temporal/temporal.h"

#define TEMPORAL_FINISH_MOMENTS 0  // 2 x channels planes: A, then B
#define TEMPORAL_FINISH_COUNTS 1   // 2 planes: W, n
#define TEMPORAL_FINISH_POOLED 2   // channels planes: V
#define TEMPORAL_FINISH_RAW 3      // channels planes: the current frame's own layer
#define TEMPORAL_FINISH_SUM0 4     // channels planes: S_0
#define TEMPORAL_FINISH_COUNTS0 5  // 2 planes: W_0 (and its count, not read)
#define TEMPORAL_FINISH_SUM1 6     // channels planes: S_1
#define TEMPORAL_FINISH_COUNTS1 7  // 2 planes: W_1 (and its count, not read)
// Written: channels planes each of the mean, the variance, and with HALVES half0, half1.
#define TEMPORAL_FINISH_OUTPUT 8
#define TEMPORAL_FINISH_BINDINGS 9

#define TEMPORAL_FINISH_WITH_POOLED 1
#define TEMPORAL_FINISH_WITH_HALVES 2

// The largest window radius of the spread's fill.
#define TEMPORAL_FINISH_MAX_RADIUS 8

#ifdef __cplusplus
#include <cstddef>
namespace mcd::shader {
struct TemporalFinishPush {
#else
layout(push_constant) uniform TemporalFinishPush {
#endif
    int width;
    int height;
    int channels;
    int flags;       // TEMPORAL_FINISH_WITH_*
    int fillRadius;  // 0..TEMPORAL_FINISH_MAX_RADIUS
#ifdef __cplusplus
};
static_assert(sizeof(TemporalFinishPush) == 20);
static_assert(offsetof(TemporalFinishPush, fillRadius) == 16);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
