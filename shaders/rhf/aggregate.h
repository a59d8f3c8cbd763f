// RHF aggregation (eqs. 6-7): every pixel gathers, from each patch that covers it (shrunk
// patches near the border cover less), the mean of that patch's selected candidates at its
// position, and averages those estimates; a pixel no selected patch covers keeps its value.
// A gather, so the result does not depend on any scheduling order.
#ifndef MCD_SHADERS_RHF_AGGREGATE_H
#define MCD_SHADERS_RHF_AGGREGATE_H

#define RHF_AGGREGATE_COLOR 0
#define RHF_AGGREGATE_MASK 1
#define RHF_AGGREGATE_OUT 2
#define RHF_AGGREGATE_BINDINGS 3
#define RHF_AGGREGATE_LOCAL_SIZE 64
#define RHF_AGGREGATE_SPEC_SEARCH_HALF 0  // b
#define RHF_AGGREGATE_SPEC_PATCH_HALF 1   // w

#ifdef __cplusplus
#include <cstddef>
namespace mcd::shader {
struct RhfAggregatePush {
#else
layout(push_constant) uniform RhfAggregatePush {
#endif
    int width;
    int height;
    int patchHalf;   // w
    int searchHalf;  // b
    int words;       // mask words per centre
#ifdef __cplusplus
};
static_assert(sizeof(RhfAggregatePush) == 20);
static_assert(offsetof(RhfAggregatePush, words) == 16);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
