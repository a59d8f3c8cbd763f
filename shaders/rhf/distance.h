// RHF patch distances (issue #4): for every centre of a strip and every offset o in the
// search window, the pixel terms (terms.comp; those of offsets with dy < 0 read as the
// terms of -o at the candidate's pixels) box-summed over the centre's patch, shrunk
// near the border to w0 = min(w, distance to the edge), divided by the number of counted
// terms + 1e-4. Offsets whose patch would leave the image (the window is clamped so every
// compared patch fits) get -1, as do vetoed pairs (a term count of -1 in the patch). Distances
// are planar [offset][strip row][x].
#ifndef MCD_SHADERS_RHF_DISTANCE_H
#define MCD_SHADERS_RHF_DISTANCE_H

#define RHF_DISTANCE_SUM 0
#define RHF_DISTANCE_COUNT 1
#define RHF_DISTANCE_OUT 2
#define RHF_DISTANCE_BINDINGS 3
#define RHF_DISTANCE_LOCAL_SIZE 64
#define RHF_DISTANCE_PIXELS_PER_LANE 8  // consecutive centres of a row per lane
#define RHF_DISTANCE_SPEC_SEARCH_HALF 0  // b
#define RHF_DISTANCE_SPEC_PATCH_HALF 1   // w

#ifdef __cplusplus
#include <cstddef>
namespace mcd::shader {
struct RhfDistancePush {
#else
layout(push_constant) uniform RhfDistancePush {
#endif
    int width;
    int height;
    int patchHalf;  // w
    int unused;
    int termBase;  // first image row held by the term buffers
    int termRows;  // rows they hold
    int rowBase;   // first centre row of the strip
    int rows;      // centre rows in the strip
#ifdef __cplusplus
};
static_assert(sizeof(RhfDistancePush) == 32);
static_assert(offsetof(RhfDistancePush, rows) == 28);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
