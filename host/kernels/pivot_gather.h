// Record the pivot filter's averaging stage (shaders/pivot/gather.comp): eqs. 11-13 as a
// gather, then the back-multiplication by the pivot.
#pragma once

#include "host/kernels/pivot_fit.h"

namespace mcd {

// `reach`: the largest radius among the fits (0 if none).
void RecordPivotGather(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &color,
                       const vk::GpuImage &pivot, const vk::GpuImage &nu,
                       const vk::GpuImage &fitLo, const vk::GpuImage &fitHi,
                       const PivotGpuGuides &guides, int reach, const vk::GpuImage &out);

}  // namespace mcd
