// Method `bayes`, per-band moments: one workgroup per detail band (numbering in bayes.h)
// writes E[y^2], E[y^4], max |y| and the count. Lane l sums elements l, l + LOCAL, ... of
// the band (row-major) in float, then a fixed tree in shared memory: deterministic, no
// atomics.
#ifndef MCD_SHADERS_BAYES_MOMENTS_H
#define MCD_SHADERS_BAYES_MOMENTS_H

#define BAYES_MOMENTS_COEF 0
#define BAYES_MOMENTS_OUT 1
#define BAYES_MOMENTS_BINDINGS 2
#define BAYES_MOMENTS_LOCAL_SIZE 256

#ifdef __cplusplus
namespace mcd::shader {
struct BayesMomentsPush {
#else
layout(push_constant) uniform BayesMomentsPush {
#endif
    int width;  // of the coefficient image
    int height;
    int levels;
#ifdef __cplusplus
};
static_assert(sizeof(BayesMomentsPush) == 12);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
