#include "host/kernels/wavelet_analyze.h"

#include "host/kernels/wavelet_lines.h"
#include "wavelet/analyze.h"
#include "wavelet/analyze_spv.h"

namespace mcd {

void RecordWaveletAnalyze(vk::Context &context, vk::Recorder &recorder, WaveletBasis basis,
                          int width, int height, int channels, const vk::ImageView &src,
                          const vk::MutableImageView &tmp, const vk::MutableImageView &dst,
                          const std::string &label) {
    vk::CheckView(src, width, height, channels, "wavelet analyze source");
    vk::CheckView(tmp, width, height, channels, "wavelet analyze temporary");
    vk::CheckView(dst, width, height, channels, "wavelet analyze destination");
    CheckWaveletTemporary(tmp, src, dst, width, "wavelet analyze");
    for (int axis : {WAVELET_AXIS_ROWS, WAVELET_AXIS_COLUMNS})
        RecordWaveletLinePass(context, recorder, "wavelet_analyze", k_wavelet_analyze_spv,
                              sizeof(k_wavelet_analyze_spv), basis, axis, width, height,
                              channels, axis == WAVELET_AXIS_ROWS ? src : vk::ImageView(tmp),
                              axis == WAVELET_AXIS_ROWS ? tmp : dst, label);
}

}  // namespace mcd
