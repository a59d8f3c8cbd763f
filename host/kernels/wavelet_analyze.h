// Record one level of the forward 2D DWT (shaders/wavelet/analyze.comp, direct
// convolutions with the filter bank): a rows pass from `src` into `tmp`, then a columns
// pass from `tmp` into `dst`.
#pragma once

#include <string>

#include "host/vk/gpu_image.h"
#include "host/vk/recorder.h"
#include "host/wavelet.h"

namespace mcd {

// Transform the width x height region of `src` into the four bands of `dst` (Mallat
// layout, low-low band at the top left). `tmp` holds the row-transformed region and must
// be a buffer of its own; `src` and `dst` may be the same view (in-place levels).
void RecordWaveletAnalyze(vk::Context &context, vk::Recorder &recorder, WaveletBasis basis,
                          int width, int height, int channels, const vk::ImageView &src,
                          const vk::MutableImageView &tmp, const vk::MutableImageView &dst,
                          const std::string &label = "wavelet.analyze");

}  // namespace mcd
