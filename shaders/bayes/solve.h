// Method `bayes`, the moment solver (eqs. 12, 17-18): one invocation per band turns its
// moments into params (layout and fits in bayes.h): sigma_c^2 = m2 - sigma_n^2, the
// fourth moment of the signal m4 - m4_n - 6 sigma_c^2 sigma_n^2, p_c by bisection of the
// log kurtosis over [BAYES_P_LO, BAYES_P_HI], s_c from sigma_c^2; the fallbacks of
// cpu_reference/bayes_model.h. Also the band's table scale b = s_n and step
// du = asinh(y_max / b) / (BAYES_TABLE_SIZE - 1). The noise s of every band is read from
// the noise buffer (one float per band), so it may differ per channel and level.
#ifndef MCD_SHADERS_BAYES_SOLVE_H
#define MCD_SHADERS_BAYES_SOLVE_H

#define BAYES_SOLVE_MOMENTS 0
#define BAYES_SOLVE_PARAMS 1
#define BAYES_SOLVE_NOISE 2
#define BAYES_SOLVE_BINDINGS 3
#define BAYES_SOLVE_LOCAL_SIZE 64

#ifdef __cplusplus
namespace mcd::shader {
struct BayesSolvePush {
#else
layout(push_constant) uniform BayesSolvePush {
#endif
    int bands;
    int levels;
    float pn;  // noise shape
#ifdef __cplusplus
};
static_assert(sizeof(BayesSolvePush) == 12);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
