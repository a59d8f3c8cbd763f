// nfor stage 2: emitters and fireflies. A pixel whose largest albedo channel exceeds
// emitterAlbedo is an emitter (a reflectance is at most about 1; renderers write a light's
// emission as its albedo): mask 0, left out of every window, its colour kept as clamped here.
// Per channel, z = colour / divisor (as in nfor/noise.h) above the lower median (rank 0; rank k
// > 0: the k-th largest, so that a pixel with k - 1 bright neighbours, part of a highlight, is
// kept) of the z of the pixel's 8 neighbours divided alike (z compares only like albedos) +
// threshold sqrt(v) / divisor + relative |median| is clamped to that limit; a pixel with no
// neighbour divided alike (an albedo unlike all around it: a sample that hit a small bright
// object or a sub-pixel light) compares its colour with its neighbours' colours the same way;
// next to an emitter (a light's edge, partly covered) it is kept, or with lightEdge >= 0
// clamped with lightEdge in place of relative. Threshold 0: nothing clamped; no neighbour
// (1x1): kept. The relative term keeps the smooth peaks of noise-free regions (v = 0): only
// values well above their neighbours are fireflies. With sumChannels a pixel whose channels are
// clamped to r_c = clamped / value takes t = 1 - (the second smallest r_c) of the whole pixel
// scaled by the sum of its clamped values over the sum of its values (the hue stays: a
// highlight whose channels cross their limits unevenly does not turn into a coloured speck) and
// 1 - t of the channel clamped alone (one channel alone above its limit, a sample of one
// colour, is clamped alone; t goes to 0 with the second channel's excess, so nothing jumps).
// One invocation per pixel, every channel (the blend reads them all); it writes the mask. With
// line > 0 a pixel that has, along an axis or a diagonal, on both sides within 2 steps a pixel
// whose mean over the channels is above line x its own is on a line (a highlight's streak one
// or two pixels wide, hit by a few of its samples) and kept whole; pixels outside count as 0.
// With loneLight > 0 an emitter with no emitter among its 8 neighbours, its largest albedo
// channel at least loneLight and each colour channel within NFOR_LONE_LIGHT_RATIO of its
// albedo's (both ways) is kept whole: a light smaller than a pixel that its samples saw
// directly (their colour is the light's own emission), not a firefly. With lineFloor > 0 a
// pixel not kept whole keeps at least min(1, lineFloor x S / B) of each positive channel, B its
// brightness, S its line's (over the 4 directions, the largest of the dimmer side's brightest
// pixel within 2 steps): the peaks of a line hit by few samples, whose line rule fails at every
// peak, keep the line's level; a lone firefly's S is its ground's. The floor holds only within
// NFOR_LINE_FLOOR_REACH pixels of a pixel whose largest albedo channel is above
// NFOR_LINE_FLOOR_LIGHT (a highlight reflecting a light, whose hits the albedo marks as bright
// emitters; grass, edges and a dim light's rim hold none).
#ifndef MCD_SHADERS_NFOR_CLAMP_H
#define MCD_SHADERS_NFOR_CLAMP_H

#include "nfor/nfor.h"

#define NFOR_CLAMP_COLOR 0
#define NFOR_CLAMP_VARIANCE 1
#define NFOR_CLAMP_ALBEDO 2
#define NFOR_CLAMP_OUT 3
#define NFOR_CLAMP_MASK 4
#define NFOR_LONE_LIGHT_RATIO 1.25
#define NFOR_LINE_FLOOR_REACH 4
#define NFOR_LINE_FLOOR_LIGHT 8.0
#define NFOR_CLAMP_BINDINGS 5

#ifdef __cplusplus
#include <cstddef>
namespace mcd::shader {
struct NforClampPush {
#else
layout(push_constant) uniform NforClampPush {
#endif
    int width;
    int height;
    int albedoChannels;  // 0: no albedo (no divisor, no emitters)
    float threshold;
    float relative;
    float emitterAlbedo;
    int rank;         // 0: the neighbours' lower median; k > 0: their k-th largest
    float lightEdge;  // relative term at a light's edge; < 0: such a pixel is kept
    int channels;     // of the colour
    int sumChannels;  // 1: the channels clamped together by one factor; 0: each on its own
    float line;       // > 0: a pixel on a line this bright is kept; 0: off
    float loneLight;  // > 0: a lone emitter of this albedo or more seen directly is kept
    float lineFloor;  // > 0: a pixel keeps at least this x its line's brightness; 0: off
#ifdef __cplusplus
};
static_assert(sizeof(NforClampPush) == 52);
static_assert(offsetof(NforClampPush, emitterAlbedo) == 20);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
