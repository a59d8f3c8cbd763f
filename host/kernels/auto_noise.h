// Record the auto method's noise estimate for frames without sample statistics
// (shaders/auto/noise.comp): the variance of the pixel mean from the local median of the
// albedo-demodulated colour's squared residuals.
#pragma once

#include "host/vk/gpu_image.h"
#include "host/vk/kernel.h"
#include "host/vk/recorder.h"

namespace mcd {

// The kernel RecordAutoNoise records.
vk::KernelDesc AutoNoiseKernel();

// `color` 1 to 4 channels; `albedo` null (no demodulation) or of color's size with 1
// channel or at least color's; `output` color's shape; radius 1..AUTO_NOISE_MAX_RADIUS.
void RecordAutoNoise(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &color,
                     const vk::GpuImage *albedo, int radius, vk::GpuImage &output);

}  // namespace mcd
