// Method `bayes`, colour: a 3x3 matrix applied across the three channels of every pixel,
// in place: out_i = sum_j m[i][j] in_j. With the orthonormal opponent matrix (rows
// (1,1,1)/sqrt3, (1,-1,0)/sqrt2, (1,1,-2)/sqrt6) on the log channels it gives log
// luminance and two log chroma channels; its transpose goes back.
#ifndef MCD_SHADERS_BAYES_MIX_H
#define MCD_SHADERS_BAYES_MIX_H

#define BAYES_MIX_IMAGE 0
#define BAYES_MIX_BINDINGS 1
#define BAYES_MIX_LOCAL_SIZE 64

#ifdef __cplusplus
namespace mcd::shader {
struct BayesMixPush {
#else
layout(push_constant) uniform BayesMixPush {
#endif
    int width;
    int height;
    float m[9];  // row-major
#ifdef __cplusplus
};
static_assert(sizeof(BayesMixPush) == 44);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
