// Record the pivot filter's averaging stage (shaders/pivot/gather.comp): eqs. 11-13 as a
// gather, then the back-multiplication by the pivot.
#pragma once

#include "host/image.h"
#include "host/kernels/pivot_fit.h"

namespace mcd {

// Per channel and PIVOT_GATHER_TILE-square tile of centres, the largest radius of their fits
// (-1: none), from the radius planes (width x height x channels); `reach` receives the
// largest overall (0 if none).
Image PivotTileRadii(const Image &radii, int *reach);

// `tiles` from PivotTileRadii of the fits' radii; `reach` its largest radius.
void RecordPivotGather(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &color,
                       const vk::GpuImage &pivot, const vk::GpuImage &nu,
                       const vk::GpuImage &fitLo, const vk::GpuImage &fitHi,
                       const PivotGpuGuides &guides, const vk::GpuImage &tiles, int reach,
                       vk::GpuImage &out, int rowBase, int rows);

}  // namespace mcd
