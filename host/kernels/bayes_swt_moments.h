// Record method bayes' per-band moments over stationary wavelet bands
// (shaders/bayes/swt_moments.comp; layout in swt_moments.h).
#pragma once

#include "host/vk/gpu_image.h"
#include "host/vk/recorder.h"

namespace mcd {

// `coef` holds the SWT of a `channels`-channel image at `levels` levels in its first
// channels (3 levels + 1) planes (it may have more, unused). moments[band] = E[y^2], E[y^4],
// max |y|, count (shaders/bayes/bayes.h).
void RecordBayesSwtMoments(vk::Context &context, vk::Recorder &recorder,
                           const vk::GpuImage &coef, int channels, int levels,
                           vk::Buffer &moments);

}  // namespace mcd
