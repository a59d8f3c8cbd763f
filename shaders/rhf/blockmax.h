// RHF bin maxima per block of a row (issue #19): for every bin plane i < 3n, row y and block
// of RHF_BLOCKMAX_WIDTH pixels x = block * width .. min(that + width, image width) - 1, the
// largest of the bins as terms.comp reads them: h_i(x, y) histScale where the pixel's count
// (times histScale) is non-zero, -FLT_MAX where it is 0. terms.comp leaves out a bin where
// the largest bin of its pixels plus the largest of their candidates is <= 1 (no pair is
// counted there); these maxima bound them with a few reads. Planar [plane][y][block];
// one dispatch per histogram buffer, its planes written at their plane index.
#ifndef MCD_SHADERS_RHF_BLOCKMAX_H
#define MCD_SHADERS_RHF_BLOCKMAX_H

#define RHF_BLOCKMAX_HIST 0   // the buffer of this dispatch's planes
#define RHF_BLOCKMAX_COUNT 1  // the buffer holding the count plane
#define RHF_BLOCKMAX_OUT 2
#define RHF_BLOCKMAX_BINDINGS 3
#define RHF_BLOCKMAX_LOCAL_SIZE 64
#define RHF_BLOCKMAX_WIDTH 8  // pixels per block: terms.comp's pixels per lane

#ifdef __cplusplus
#include <cstddef>
namespace mcd::shader {
struct RhfBlockMaxPush {
#else
layout(push_constant) uniform RhfBlockMaxPush {
#endif
    int width;  // of the scale's image
    int height;
    int firstPlane;  // plane index of the buffer's first plane
    int planes;      // bin planes of the buffer to do (count plane excluded)
    int countAt;     // the count plane's index in its buffer
    float histScale;
    int unused0;
    int unused1;
#ifdef __cplusplus
};
static_assert(sizeof(RhfBlockMaxPush) == 32);
static_assert(offsetof(RhfBlockMaxPush, histScale) == 20);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
