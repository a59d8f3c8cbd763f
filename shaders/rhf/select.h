// RHF selection (Algorithm 2, lines 10-17): for every centre of a strip, the `nearest`
// nearest patches of its search window (k_NN + 1 with the patch itself; ties as the tool's
// selection sort over the window column by column) plus every patch closer than the
// threshold, as a bit mask over the window's offsets, planar
// [word][y][x] over the whole image. With poolBound > 0 a candidate is no candidate when the
// bright samples pooled over its patch box, Q, and over the centre's, P (RHF_SELECT_POOL, one
// float per pixel of the scale), differ as rates over their boxes' pixel counts aQ, aP (the
// boxes cut at the image's edges): (P/aP - Q/aQ)^2 > poolBound (P/aP^2 + Q/aQ^2).
#ifndef MCD_SHADERS_RHF_SELECT_H
#define MCD_SHADERS_RHF_SELECT_H

#define RHF_SELECT_DISTANCE 0
#define RHF_SELECT_MASK 1
#define RHF_SELECT_POOL 2  // bright samples pooled over each pixel's patch box, height x width
#define RHF_SELECT_BINDINGS 3
#define RHF_SELECT_LOCAL_SIZE 64
#define RHF_SELECT_SPEC_SEARCH_HALF 0  // b
#define RHF_SELECT_SPEC_POOL 1         // 1: the pooled bright veto is on (compiled out at 0)

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
    int patchHalf;  // w: the pool's box is (2w + 1)^2 pixels, cut at the image's edges
#ifdef __cplusplus
};
static_assert(sizeof(RhfSelectPush) == 36);
static_assert(offsetof(RhfSelectPush, threshold) == 28);
static_assert(offsetof(RhfSelectPush, patchHalf) == 32);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
