// Temporal stage 1, one neighbour j of the current frame t at a time, one invocation per
// pixel p of t. The pixel lands at position P(p) in j (temporal.h), in pixel
// q = floor(P); the neighbour's sample there is accepted when
//   - P is finite and inside the frame,
//   - the features present in both frames agree (disocclusion): the same object id, normals
//     within an angle (n_t . n_j >= normalCos |n_t| |n_j|, or both zero: the background),
//     depths equal or within a relative tolerance (d_t - d_j finite and |d_t - d_j| <=
//     depthRel max(|d_t|, |d_j|)), albedos per channel equal or within albedoRel
//     max(|a_t|, |a_j|, TEMPORAL_ALBEDO_FLOOR) (the difference finite);
//   - with motion and motionTol > 0: j's vector at q back towards the chain's previous
//     frame lands within motionTol pixels (each axis) of where the chain came from
//     (forward-backward consistency: an occluder that moves otherwise fails it),
//   - and every channel of j's colour at q is finite.
// Its weight is then j's spp at q (finite and > 0; else 1) or 1 without an spp layer, and 0
// where it is not accepted. The position one frame further along the chain, in direction
// `direction` (-1 earlier, +1 later), is P + j's vector at q (temporal.h); NaN where P was
// lost or the features or the motion check failed (j's vector there belongs to another
// surface), not where only the colour was non-finite. Without motion it is P itself
// whatever the tests said (a still camera: a sample rejected here says nothing of the
// frames beyond).
//
// MATCH_SELF: j is t itself: P(p) is p's centre, every test but the colour's is skipped and
// the next positions start the chain from t. MATCH_FIRST: j is t's neighbour, the chain's
// previous frame t, so the previous positions are t's pixel centres (not read).
#ifndef MCD_SHADERS_TEMPORAL_MATCH_H
#define MCD_SHADERS_TEMPORAL_MATCH_H

#include "temporal/temporal.h"

#define TEMPORAL_MATCH_PREVIOUS 0  // 2 planes: positions in the chain's previous frame
#define TEMPORAL_MATCH_POSITION 1  // 2 planes: positions in j
#define TEMPORAL_MATCH_CURRENT 2   // TEMPORAL_FEATURE_PLANES: t's features
#define TEMPORAL_MATCH_FEATURES 3  // TEMPORAL_FEATURE_PLANES: j's features
#define TEMPORAL_MATCH_COLOR 4     // colorChannels planes: j's colour
#define TEMPORAL_MATCH_SPP 5       // 1 plane: j's samples per pixel
#define TEMPORAL_MATCH_MOTION 6    // 4 planes: j's motion vectors
#define TEMPORAL_MATCH_WEIGHT 7    // 1 plane, written: the sample's weight
#define TEMPORAL_MATCH_NEXT 8      // 2 planes, written: positions one frame further
#define TEMPORAL_MATCH_BINDINGS 9

#define TEMPORAL_MATCH_SELF 1
#define TEMPORAL_MATCH_FIRST 2
#define TEMPORAL_MATCH_WITH_SPP 4
#define TEMPORAL_MATCH_WITH_MOTION 8

#ifdef __cplusplus
#include <cstddef>
namespace mcd::shader {
struct TemporalMatchPush {
#else
layout(push_constant) uniform TemporalMatchPush {
#endif
    int width;
    int height;
    int colorChannels;  // 1..4
    int features;       // TEMPORAL_HAS_* of the features both frames have
    int flags;          // TEMPORAL_MATCH_*
    int direction;      // -1 or +1
    float normalCos;
    float depthRel;
    float albedoRel;
    float motionTol;  // pixels; <= 0: no forward-backward check
#ifdef __cplusplus
};
static_assert(sizeof(TemporalMatchPush) == 40);
static_assert(offsetof(TemporalMatchPush, motionTol) == 36);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
