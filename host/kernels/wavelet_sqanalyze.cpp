#include "host/kernels/wavelet_sqanalyze.h"

#include "host/kernels/wavelet_lines.h"
#include "wavelet/sqanalyze.h"
#include "wavelet/sqanalyze_spv.h"

namespace mcd {

void RecordWaveletSqAnalyze(vk::Context &context, vk::Recorder &recorder, WaveletBasis basis,
                            int width, int height, int channels, const vk::ImageView &src,
                            const vk::MutableImageView &tmp, const vk::MutableImageView &dst,
                            float lowSum, float highSum, const std::string &label) {
    static_assert(sizeof(shader::WaveletSqAnalyzePush) ==
                  sizeof(shader::WaveletLinesPush) + 2 * sizeof(float));
    vk::CheckView(src, width, height, channels, "wavelet sqanalyze source");
    vk::CheckView(tmp, width, height, channels, "wavelet sqanalyze temporary");
    vk::CheckView(dst, width, height, channels, "wavelet sqanalyze destination");
    CheckWaveletTemporary(tmp, src, dst, width, "wavelet sqanalyze");
    for (int axis : {WAVELET_AXIS_ROWS, WAVELET_AXIS_COLUMNS})
        RecordWaveletLinePass(context, recorder, "wavelet_sqanalyze", k_wavelet_sqanalyze_spv,
                              sizeof(k_wavelet_sqanalyze_spv), basis, axis, width, height,
                              channels, axis == WAVELET_AXIS_ROWS ? src : vk::ImageView(tmp),
                              axis == WAVELET_AXIS_ROWS ? tmp : dst, label,
                              shader::WaveletSqAnalyzePush{{}, lowSum, highSum});
}

}  // namespace mcd
