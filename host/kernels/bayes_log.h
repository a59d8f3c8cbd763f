// Record method bayes' log stage (shaders/bayes/log.comp).
#pragma once

#include "host/vk/gpu_image.h"
#include "host/vk/recorder.h"

namespace mcd {

// out = log(max(color, floor_c)) per shaders/bayes/log.h, missed samples filled from their
// neighbours when fillMissed; `floors` holds one float per channel.
void RecordBayesLog(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &color,
                    const vk::Buffer &floors, vk::GpuImage &out, bool fillMissed);

}  // namespace mcd
