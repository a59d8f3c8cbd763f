// Record method bayes' shrinkage over stationary wavelet bands
// (shaders/bayes/swt_shrink.comp; layout in swt_shrink.h).
#pragma once

#include "host/vk/gpu_image.h"
#include "host/vk/recorder.h"

namespace mcd {

// In place on `coef`, the SWT of a `channels`-channel image at `levels` levels in its first
// channels (3 levels + 1) planes: every detail coefficient through its band's table.
void RecordBayesSwtShrink(vk::Context &context, vk::Recorder &recorder, vk::GpuImage &coef,
                          int channels, int levels, const vk::Buffer &params,
                          const vk::Buffer &table);

}  // namespace mcd
