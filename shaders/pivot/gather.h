// Pivot filter stage 3: the two-stage averaging (eq. 13) written as a gather. Every pixel
// with z sums, over the centres whose squares hold it, the centre's combined approximation
// (eqs. 11-12) at the pixel with weight exp(-d^2 / R0^2) x normal term x id terms x step^2,
// over the centres on their lattice (pivot/lattice.glsl), normalises, and multiplies
// back by the pivot; a pixel no such centre reaches takes its own fit at its place; other
// pixels keep their color. One invocation per pixel; one dispatch per channel, with that
// channel's fit buffers.
#ifndef MCD_SHADERS_PIVOT_GATHER_H
#define MCD_SHADERS_PIVOT_GATHER_H

#include "pivot/pivot.h"

#define PIVOT_GATHER_COLOR 0
#define PIVOT_GATHER_PIVOT 1
#define PIVOT_GATHER_ZSN 2  // (z, s, nu, level) of the dispatch's channel (pivot/fit.h)
#define PIVOT_GATHER_FIT_LO 3
#define PIVOT_GATHER_FIT_HI 4
#define PIVOT_GATHER_GUIDES 5
#define PIVOT_GATHER_OUT 6
#define PIVOT_GATHER_TILES 7  // per channel and tile, its centres by radius (PivotTileOrder)
#define PIVOT_GATHER_BINDINGS 8
// Centres are visited tile by tile, each tile's by radius, largest first: the walk stops at
// the first radius below the pixel's distance to the tile.
#define PIVOT_GATHER_TILE 8
// Centres of lattice step 1 (radius <= this, pivot/lattice.glsl) are dense and reach only
// this far: the gather reads them from the pixel's neighbourhood, and the tiles list only
// centres of step 2 and above.
#define PIVOT_GATHER_NEAR 3

#ifdef __cplusplus
#include <cstddef>
namespace mcd::shader {
struct PivotGatherPush {
#else
layout(push_constant) uniform PivotGatherPush {
#endif
    int width;
    int height;
    int channels;
    int reach;   // the largest radius of any fit: no centre further away holds the pixel
    int tilesX;  // ceil(width / PIVOT_GATHER_TILE)
    int tilesY;
    int rowBase;  // first row of this dispatch (row strips)
    int channel;  // the channel of this dispatch, whose fit and zsn buffers are bound
    float edge;   // sigmas of the shading-edge test (pivot/edge.glsl; 0: off)
#ifdef __cplusplus
};
static_assert(sizeof(PivotGatherPush) == 36);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
