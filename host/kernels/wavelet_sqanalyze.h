// Record one level of the squared-filter (variance) analysis of AWR eqs. 9-10
// (shaders/wavelet/sqanalyze.comp): a rows pass from `src` into `tmp`, then a columns
// pass from `tmp` into `dst`.
#pragma once

#include <string>

#include "host/vk/gpu_image.h"
#include "host/vk/recorder.h"
#include "host/wavelet.h"

namespace mcd {

// Same views as RecordWaveletAnalyze. The squared 1D low (high) taps are renormalised to
// sum to lowSum (highSum); values <= 0 keep the natural sums.
void RecordWaveletSqAnalyze(vk::Context &context, vk::Recorder &recorder, WaveletBasis basis,
                            int width, int height, int channels, const vk::ImageView &src,
                            const vk::MutableImageView &tmp, const vk::MutableImageView &dst,
                            float lowSum, float highSum,
                            const std::string &label = "wavelet.sqanalyze");

}  // namespace mcd
