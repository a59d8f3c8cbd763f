// Record the pivot filter's bilateral baseline (shaders/pivot/bilateral.comp): a
// cross-bilateral filter of z guided by the pivot (and normals, ids), multiplied back.
#pragma once

#include "host/kernels/pivot_fit.h"
#include "host/vk/kernel.h"

namespace mcd {

struct PivotBilateralSettings {
    int radius = 8;
    float sigmaRange = 0.2f, goodNoise = 100.f;
};

// The kernel RecordPivotBilateral records with these guides.
vk::KernelDesc PivotBilateralKernel(bool normals, bool ids);

void RecordPivotBilateral(vk::Context &context, vk::Recorder &recorder,
                          const vk::GpuImage &color, const vk::GpuImage &pivot,
                          const vk::GpuImage &z, const vk::GpuImage &nu,
                          const PivotGpuGuides &guides, const PivotBilateralSettings &settings,
                          vk::GpuImage &out);

}  // namespace mcd
