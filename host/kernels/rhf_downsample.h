// Record RHF's Gaussian downsampling D_s (shaders/rhf/downsample.comp): an x pass into a
// scratch buffer, then a y pass.
#pragma once

#include <vector>

#include "host/vk/buffer.h"
#include "host/vk/recorder.h"

namespace mcd {

// The normalised Gaussian taps of standard deviation sigma, truncated at ceil(3 sigma).
std::vector<float> RhfGaussianTaps(double sigma);

// src holds `planes` planes of srcWidth x srcHeight; dst gets them at
// ceil(srcWidth / step) x ceil(srcHeight / step), sampled at step * x after the blur by
// the taps in `weights` (2 radius + 1 floats). scratch holds the x pass,
// planes x srcHeight x ceil(srcWidth / step).
void RecordRhfDownsample(vk::Context &context, vk::Recorder &recorder, const vk::Buffer &src,
                         int srcWidth, int srcHeight, int planes, int step,
                         const vk::Buffer &weights, int radius, vk::Buffer &scratch,
                         vk::Buffer &dst);

}  // namespace mcd
