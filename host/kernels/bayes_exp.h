// Record method bayes' exp stage (shaders/bayes/exp.comp).
#pragma once

#include "host/vk/gpu_image.h"
#include "host/vk/recorder.h"

namespace mcd {

// out = exp(logImage), exactly 0 where `original` is not finite and positive.
void RecordBayesExp(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &logImage,
                    const vk::GpuImage &original, const vk::GpuImage &out);

}  // namespace mcd
