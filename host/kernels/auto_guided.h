// Record the auto method's guided smoothing of its error maps (shaders/auto/guided.comp):
// the tent-weighted mean of the finite values over a (2r+1)^2 window, each weight also
// times exp(-d / bandwidth^2), d the guide's relative colour distance.
#pragma once

#include "host/vk/gpu_image.h"
#include "host/vk/recorder.h"

namespace mcd {

// `input` and `output`: same size and planes (1 to AUTO_GUIDED_MAX_PLANES); `guide`: the
// same size, 1 to 4 channels; radius 0..64, bandwidth > 0.
void RecordAutoSmoothGuided(vk::Context &context, vk::Recorder &recorder,
                            const vk::GpuImage &input, const vk::GpuImage &guide, int radius,
                            float bandwidth, vk::GpuImage &output);

}  // namespace mcd
