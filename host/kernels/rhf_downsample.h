// Record RHF's Gaussian downsampling D_s (shaders/rhf/downsample.comp): an x pass into a
// scratch buffer, then a y pass.
#pragma once

#include <vector>

#include "host/vk/buffer.h"
#include "host/vk/kernel.h"
#include "host/vk/recorder.h"

namespace mcd {

// The tool's normalised Gaussian taps of standard deviation sigma for sampling by `step`:
// 2 h + 1 of them, h = ceil(sigma sqrt(4 ln 10)), centred on the sample point.
std::vector<float> RhfGaussianTaps(double sigma, int step);

// The kernel RecordRhfDownsample records.
vk::KernelDesc RhfDownsampleKernel();

// src holds `planes` planes of srcWidth x srcHeight; dst gets them at
// ceil(srcWidth / step) x ceil(srcHeight / step): tap i of `weights` (2 radius + 1 floats)
// reads step x + step / 2 - radius + i, mirrored at the edges. scratch holds the x pass,
// planes x srcHeight x ceil(srcWidth / step).
void RecordRhfDownsample(vk::Context &context, vk::Recorder &recorder, const vk::Buffer &src,
                         int srcWidth, int srcHeight, int planes, int step,
                         const vk::Buffer &weights, int radius, vk::Buffer &scratch,
                         vk::Buffer &dst);

}  // namespace mcd
