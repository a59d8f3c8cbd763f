// Record AWR's soft shrinkage (eq. 11, shaders/awr/shrink.comp), in place on `coef`.
#pragma once

#include "host/vk/gpu_image.h"
#include "host/vk/recorder.h"

namespace mcd {

// `coef` and `variance` are same-sized Mallat-layout images; the top-left lowWidth x
// lowHeight (the coarsest low-low band) is kept.
void RecordAwrShrink(vk::Context &context, vk::Recorder &recorder, vk::GpuImage &coef,
                     const vk::GpuImage &variance, int lowWidth, int lowHeight, float cs);

}  // namespace mcd
