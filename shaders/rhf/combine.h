// RHF multi-scale recombination (Algorithm 3, line 10): u_s - U(D(u_s)) + U(u_{s+1}),
// U the bicubic (Keys, a = -0.5) interpolator as the tool's: fine pixel x at coarse
// position (x + 0.5) coarseWidth / width - 0.5, edges mirrored. D(u_s) and u_{s+1} are both
// coarseWidth x coarseHeight.
// A tile's window maps through its whole frame's sizes (frameWidth ... at this scale) and
// its origin in it (originX, originY: even), so that it interpolates at the positions the
// untiled run does; an untiled run passes origin 0 and its own sizes.
#ifndef MCD_SHADERS_RHF_COMBINE_H
#define MCD_SHADERS_RHF_COMBINE_H

#define RHF_COMBINE_FILTERED 0
#define RHF_COMBINE_LOW 1
#define RHF_COMBINE_COARSE 2
#define RHF_COMBINE_OUT 3
#define RHF_COMBINE_BINDINGS 4
#define RHF_COMBINE_LOCAL_SIZE 64

#ifdef __cplusplus
#include <cstddef>
namespace mcd::shader {
struct RhfCombinePush {
#else
layout(push_constant) uniform RhfCombinePush {
#endif
    int width;
    int height;
    int coarseWidth;
    int coarseHeight;
    int originX;
    int originY;
    int frameWidth;
    int frameHeight;
    int frameCoarseWidth;
    int frameCoarseHeight;
#ifdef __cplusplus
};
static_assert(sizeof(RhfCombinePush) == 40);
static_assert(offsetof(RhfCombinePush, frameCoarseHeight) == 36);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
