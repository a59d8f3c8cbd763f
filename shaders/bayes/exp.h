// Method `bayes`, last stage: back from the log domain. out = exp(clamp(z, -87, 88)), or,
// with restoreZeros, exactly 0 where the original value was not a finite positive number
// (black stays black); without it only NaN/Inf/negative originals give 0.
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
