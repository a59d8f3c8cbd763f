// Record method bayes' exp stage (shaders/bayes/exp.comp).
#pragma once

#include "host/vk/gpu_image.h"
#include "host/vk/recorder.h"

namespace mcd {

// out = exp(logImage), exactly 0 where `original` is NaN/Inf/negative, and where it is 0
// when restoreZeros.
void RecordBayesExp(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &logImage,
                    const vk::GpuImage &original, vk::GpuImage &out, bool restoreZeros);

}  // namespace mcd
