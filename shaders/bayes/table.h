// Method `bayes`, the per-band lookup table of the posterior mean (eq. 11): entry i of a
// band is c^(y_i) at y_i = b sinh(i du) (b, du from the params; bayes.h), by the
// quadrature of model.glsl. NO_SIGNAL and EMPTY bands get 0, NO_NOISE bands y_i.
#ifndef MCD_SHADERS_BAYES_TABLE_H
#define MCD_SHADERS_BAYES_TABLE_H

#define BAYES_TABLE_PARAMS 0
#define BAYES_TABLE_OUT 1
#define BAYES_TABLE_BINDINGS 2
#define BAYES_TABLE_LOCAL_SIZE 64

#ifdef __cplusplus
namespace mcd::shader {
struct BayesTablePush {
#else
layout(push_constant) uniform BayesTablePush {
#endif
    int bands;
#ifdef __cplusplus
};
static_assert(sizeof(BayesTablePush) == 4);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
