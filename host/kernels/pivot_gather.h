// Record the pivot filter's averaging stage (shaders/pivot/gather.comp): eqs. 11-13 as a
// gather, then the back-multiplication by the pivot.
#pragma once

#include <vector>

#include "host/image.h"
#include "host/kernels/pivot_fit.h"
#include "host/vk/kernel.h"

namespace mcd {

// Per channel and PIVOT_GATHER_TILE-square tile of centres, the tile's centres by radius,
// largest first (ties in raster order), from the radius planes (width x height x channels):
// an image PIVOT_GATHER_TILE^2 wide, one row per tile (raster order of the tiles) and
// 3 x channels planes. Plane c holds the centres' positions in the tile (y * TILE + x), plane
// channels + c their radii; slots past the tile's centres, centres without a fit, centres
// off their lattice (PivotLatticeStepOf) and those of step 1 (radius <= PIVOT_GATHER_NEAR,
// which the gather reads directly) have radius -1. A pixel at Chebyshev distance g
// from a tile needs only the prefix with radius >= g. Plane 2 x channels + c holds in slot
// 0 the tile's local reach: the largest listed radius of any tile whose Chebyshev gap to it
// is at most that radius (-1: none); the gather looks no further. `reach` receives the
// largest radius overall (0 if none).
Image PivotTileOrder(const Image &radii, int *reach);

// Eq. 13's lattice step of a centre of radius R0: the largest power of two <= R0 / 2, at
// most PIVOT_LATTICE_MAX_STEP (cpu_reference/pivot_filter.h). Only centres with x0 and y0
// multiples of it take part in the gather, with weight times step^2.
int PivotLatticeStepOf(float radius);

// The kernel RecordPivotGather records with these guides and zsn of 1 or 2 vec4s a pixel.
vk::KernelDesc PivotGatherKernel(bool normals, bool ids, int zsnTexels);

// `tiles` from PivotTileOrder of the fits' radii; `reach` its largest radius; `zsn` the
// ratio's packed (z, s, nu, level, noise) per channel, or (z, s, nu) where `edge` is 0;
// `edge` the sigmas of the shading-edge test (0: off). One dispatch per channel, reading that
// channel's fit and zsn buffers.
void RecordPivotGather(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &color,
                       const vk::GpuImage &pivot, const std::vector<vk::GpuImage> &zsn,
                       const PivotFitBuffers &fits, const PivotGpuGuides &guides,
                       const vk::GpuImage &tiles, int reach, float edge, vk::GpuImage &out,
                       int rowBase, int rows);

}  // namespace mcd
