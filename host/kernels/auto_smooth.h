// Record the auto method's smoothing of its error maps (shaders/auto/smooth.comp): the
// tent-weighted mean of the finite values over a (2r+1)^2 window, per plane, as a rows pass and
// a columns pass.
#pragma once

#include "host/vk/gpu_image.h"
#include "host/vk/recorder.h"

namespace mcd {

// `input` and `output`: same size and planes; `scratch`: the same size and twice the planes
// (the row pass's sums and counts); radius 0..64.
void RecordAutoSmooth(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &input,
                      int radius, vk::GpuImage &scratch, vk::GpuImage &output);

}  // namespace mcd
