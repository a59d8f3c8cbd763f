// Method `bayes`, stage 1: the log domain (eqs. 4-5). out = log(max(v, floor_c)), where
// NaN, Inf and values <= floor_c (zeros, negatives) take log(floor_c); floor_c per channel
// from the `floors` buffer (host: floorRel times the channel's median positive value). With
// fillMissed (--zeros restore), a dark pixel (no channel finite and above its floor) with no
// pair of opposite 3x3 neighbour pixels both dark (coordinates clamped to the frame) is a
// sample that missed the light: its values in [0, floor_c] take the mean of
// log(max(v, floor_c)) over its in-frame 3x3 neighbour pixels that are not dark (the floor's
// log when there are none).
#ifndef MCD_SHADERS_BAYES_LOG_H
#define MCD_SHADERS_BAYES_LOG_H

#define BAYES_LOG_COLOR 0
#define BAYES_LOG_FLOORS 1
#define BAYES_LOG_OUT 2
#define BAYES_LOG_BINDINGS 3
#define BAYES_LOG_LOCAL_SIZE 64

#ifdef __cplusplus
namespace mcd::shader {
struct BayesLogPush {
#else
layout(push_constant) uniform BayesLogPush {
#endif
    int width;
    int height;
    int fillMissed;
#ifdef __cplusplus
};
static_assert(sizeof(BayesLogPush) == 12);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
