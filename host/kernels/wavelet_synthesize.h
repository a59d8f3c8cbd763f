// Record one level of the inverse 2D DWT (shaders/wavelet/synthesize.comp): a columns
// pass from `src` into `tmp`, then a rows pass from `tmp` into `dst`.
#pragma once

#include <string>

#include "host/vk/gpu_image.h"
#include "host/vk/recorder.h"
#include "host/wavelet.h"

namespace mcd {

// Rebuild the width x height region into `dst` from its four bands in `src` (Mallat
// layout). `tmp` must be a buffer of its own; `src` and `dst` may be the same view.
void RecordWaveletSynthesize(vk::Context &context, vk::Recorder &recorder, WaveletBasis basis,
                             int width, int height, int channels, const vk::ImageView &src,
                             const vk::MutableImageView &tmp, const vk::MutableImageView &dst,
                             const std::string &label = "wavelet.synthesize");

// One pass of it (WAVELET_AXIS_COLUMNS: bands -> temporary, WAVELET_AXIS_ROWS: temporary
// -> samples), for kernels that replace the other pass.
void RecordWaveletSynthesizePass(vk::Context &context, vk::Recorder &recorder,
                                 WaveletBasis basis, int axis, int width, int height,
                                 int channels, const vk::ImageView &src,
                                 const vk::MutableImageView &dst, const std::string &label);

}  // namespace mcd
