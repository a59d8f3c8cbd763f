#include "host/kernels/wavelet_sqanalyze.h"

#include <fmt/format.h>

#include "host/kernels/wavelet_lines.h"
#include "wavelet/sqanalyze.h"
#include "wavelet/sqanalyze_spv.h"

namespace mcd {

namespace {

// Both passes of the convolution kernel: plain taps (squared 0) or squared taps
// renormalised to lowSum / highSum (squared 1).
void RecordLinePasses(vk::Context &context, vk::Recorder &recorder, WaveletBasis basis,
                      int width, int height, int channels, const vk::ImageView &src,
                      const vk::MutableImageView &tmp, const vk::MutableImageView &dst,
                      bool squared, float lowSum, float highSum, const char *what,
                      const std::string &label) {
    vk::CheckView(src, width, height, channels, fmt::format("{} source", what).c_str());
    vk::CheckView(tmp, width, height, channels, fmt::format("{} temporary", what).c_str());
    vk::CheckView(dst, width, height, channels, fmt::format("{} destination", what).c_str());
    CheckWaveletTemporary(tmp, src, dst, width, what);
    for (int axis : {WAVELET_AXIS_ROWS, WAVELET_AXIS_COLUMNS})
        RecordWaveletLinePass(context, recorder, "wavelet_sqanalyze", k_wavelet_sqanalyze_spv,
                              sizeof(k_wavelet_sqanalyze_spv), basis, axis, width, height,
                              channels, axis == WAVELET_AXIS_ROWS ? src : tmp,
                              axis == WAVELET_AXIS_ROWS ? tmp : dst, label,
                              shader::WaveletSqAnalyzePush{{}, lowSum, highSum}, {},
                              {{WAVELET_SPEC_SQUARED, squared ? 1 : 0}});
}

}  // namespace

void RecordWaveletSqAnalyze(vk::Context &context, vk::Recorder &recorder, WaveletBasis basis,
                            int width, int height, int channels, const vk::ImageView &src,
                            const vk::MutableImageView &tmp, const vk::MutableImageView &dst,
                            float lowSum, float highSum, const std::string &label) {
    static_assert(sizeof(shader::WaveletSqAnalyzePush) ==
                  sizeof(shader::WaveletLinesPush) + 2 * sizeof(float));
    RecordLinePasses(context, recorder, basis, width, height, channels, src, tmp, dst, true,
                     lowSum, highSum, "wavelet sqanalyze", label);
}

void RecordWaveletConvAnalyze(vk::Context &context, vk::Recorder &recorder, WaveletBasis basis,
                              int width, int height, int channels, const vk::ImageView &src,
                              const vk::MutableImageView &tmp, const vk::MutableImageView &dst,
                              const std::string &label) {
    RecordLinePasses(context, recorder, basis, width, height, channels, src, tmp, dst, false,
                     0.f, 0.f, "wavelet analyze", label);
}

}  // namespace mcd
