// Record one level of the inverse 2D DWT with AWR's soft shrinkage fused into its columns
// pass (shaders/wavelet/synthesize_shrink.comp); the rows pass is the plain synthesis's.
#pragma once

#include <string>

#include "host/vk/gpu_image.h"
#include "host/vk/recorder.h"
#include "host/wavelet.h"

namespace mcd {

// One level of RecordWaveletSynthesize with AWR's soft shrinkage fused into the columns pass
// (shaders/wavelet/synthesize_shrink.h): every detail coefficient w of the level's bands
// is read as sign(w) max(0, |w| - cs sqrt(var)), var from `variance` (the layout of
// `src`: same stride and plane); the level's low-low band is read as it is. `src` is
// left unchanged unless it is `dst`.
void RecordWaveletSynthesizeShrink(vk::Context &context, vk::Recorder &recorder,
                                   WaveletBasis basis, int width, int height, int channels,
                                   const vk::ImageView &src, const vk::ImageView &variance,
                                   float cs, const vk::MutableImageView &tmp,
                                   const vk::MutableImageView &dst,
                                   const std::string &label = "wavelet.synthesize_shrink");

}  // namespace mcd
