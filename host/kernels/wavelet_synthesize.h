// Record one level of the inverse 2D DWT (shaders/wavelet/synthesize.comp).
#pragma once

#include <string>

#include "host/vk/gpu_image.h"
#include "host/vk/recorder.h"
#include "host/wavelet.h"

namespace mcd {

// Rebuild the width x height region into `dst` from the compact low-low band in `low`
// and the detail bands in `coef` (Mallat layout; `low` may view the `coef` buffer).
void RecordWaveletSynthesize(vk::Context &context, vk::Recorder &recorder, WaveletBasis basis,
                             int width, int height, int channels, const vk::ImageView &low,
                             const vk::ImageView &coef, const vk::ImageView &dst,
                             const std::string &label = "wavelet.synthesize");

}  // namespace mcd
