// Record one level of the forward 2D DWT (shaders/wavelet/analyze.comp).
#pragma once

#include <string>

#include "host/vk/gpu_image.h"
#include "host/vk/recorder.h"
#include "host/wavelet.h"

namespace mcd {

// Transform the width x height region of `src`; detail bands go to `coef` (Mallat
// layout), the low-low band, compact, to `low` (may view the same buffer as `coef`).
void RecordWaveletAnalyze(vk::Context &context, vk::Recorder &recorder, WaveletBasis basis,
                          int width, int height, int channels, const vk::ImageView &src,
                          const vk::ImageView &coef, const vk::ImageView &low,
                          const std::string &label = "wavelet.analyze");

}  // namespace mcd
