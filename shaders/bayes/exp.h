// Method `bayes`, last stage: back from the log domain. out = exp(clamp(z, -87, 88)), or
// exactly 0 where the original value was not a finite positive number (black stays black).
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
#ifdef __cplusplus
};
static_assert(sizeof(BayesExpPush) == 8);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
