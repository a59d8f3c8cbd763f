// RHF selection (Algorithm 2, lines 10-17): for every centre of a strip, the `nearest`
// nearest patches of its search window (k_NN + 1 with the patch itself; ties as the tool's
// selection sort over the window column by column) plus every patch closer than the
// threshold, as a bit mask over the window's offsets, planar
// [word][y][x] over the whole image. With poolBound > 0 a candidate is no candidate when the
// bright samples pooled over its patch box, Q, and over the centre's, P (RHF_SELECT_POOL, one
// float per pixel of the scale), differ by (P - Q)^2 > poolBound (P + Q).
#ifndef MCD_SHADERS_RHF_SELECT_H
#define MCD_SHADERS_RHF_SELECT_H

#define RHF_SELECT_DISTANCE 0
#define RHF_SELECT_MASK 1
#define RHF_SELECT_POOL 2  // bright samples pooled over each pixel's patch box, height x width
#define RHF_SELECT_BINDINGS 3
#define RHF_SELECT_LOCAL_SIZE 64
#define RHF_SELECT_SPEC_SEARCH_HALF 0  // b

#ifdef __cplusplus
#include <cstddef>
namespace mcd::shader {
struct RhfSelectPush {
#else
layout(push_constant) uniform RhfSelectPush {
#endif
    int width;
    int height;
    int searchHalf;   // b
    int rowBase;      // first centre row of the strip
    int rows;         // centre rows in the strip
    int nearest;      // nearest patches always taken
    float poolBound;  // 0: no pooled bright veto
    float threshold;
#ifdef __cplusplus
};
static_assert(sizeof(RhfSelectPush) == 32);
static_assert(offsetof(RhfSelectPush, threshold) == 28);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
