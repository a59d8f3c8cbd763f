// Method `bayes`, the shrinkage: every detail coefficient y of a Mallat-layout image is
// replaced, in place, by its band's table at |y| (linear in u = asinh(|y| / b)), with y's
// sign; past the last entry the table continues with slope 1. NO_NOISE bands (s_n below
// BAYES_MIN_NOISE_S) keep y exactly; the coarsest low-low band is kept.
#ifndef MCD_SHADERS_BAYES_SHRINK_H
#define MCD_SHADERS_BAYES_SHRINK_H

#define BAYES_SHRINK_COEF 0
#define BAYES_SHRINK_PARAMS 1
#define BAYES_SHRINK_TABLE 2
#define BAYES_SHRINK_BINDINGS 3
#define BAYES_SHRINK_LOCAL_SIZE 64

#ifdef __cplusplus
namespace mcd::shader {
struct BayesShrinkPush {
#else
layout(push_constant) uniform BayesShrinkPush {
#endif
    int width;  // of the coefficient image
    int height;
    int levels;
#ifdef __cplusplus
};
static_assert(sizeof(BayesShrinkPush) == 12);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
