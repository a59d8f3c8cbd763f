// Record RHF's multi-scale recombination (shaders/rhf/combine.comp).
#pragma once

#include "host/vk/gpu_image.h"
#include "host/vk/recorder.h"

namespace mcd {

// out = filtered - U(low) + U(coarse); low and coarse are one size, half of filtered's
// (rounded up), all 3 channels.
void RecordRhfCombine(vk::Context &context, vk::Recorder &recorder,
                      const vk::GpuImage &filtered, const vk::GpuImage &low,
                      const vk::GpuImage &coarse, vk::GpuImage &out);

}  // namespace mcd
