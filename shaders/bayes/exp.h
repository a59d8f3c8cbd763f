// Method `bayes`, last stage: back from the log domain. out = exp(clamp(z, -87, 88)), or
// exactly 0 where the original value was NaN/Inf or negative; with restoreZeros also where it
// was an exact zero whose two neighbour pixels along a row, column or diagonal (clamped to
// the frame) are black in its channel, not finite positive (black stays black, and so do the
// zero channels of a primary colour; a lone zero among lit pixels is a sample that missed the
// light, filled by the log stage and denoised).
#ifndef MCD_SHADERS_BAYES_EXP_H
#define MCD_SHADERS_BAYES_EXP_H

#define BAYES_EXP_LOG 0
#define BAYES_EXP_ORIGINAL 1
#define BAYES_EXP_OUT 2
#define BAYES_EXP_BINDINGS 3
#define BAYES_EXP_LOCAL_SIZE 64

#ifdef __cplusplus
namespace mcd::shader {
struct BayesExpPush {
#else
layout(push_constant) uniform BayesExpPush {
#endif
    int width;
    int height;
    int restoreZeros;
#ifdef __cplusplus
};
static_assert(sizeof(BayesExpPush) == 12);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
