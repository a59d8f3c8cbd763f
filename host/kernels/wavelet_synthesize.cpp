#include "host/kernels/wavelet_synthesize.h"

#include "host/kernels/wavelet_lines.h"
#include "wavelet/synthesize.h"
#include "wavelet/synthesize_spv.h"

namespace mcd {

void RecordWaveletSynthesize(vk::Context &context, vk::Recorder &recorder, WaveletBasis basis,
                             int width, int height, int channels, const vk::ImageView &src,
                             const vk::MutableImageView &tmp, const vk::MutableImageView &dst,
                             const std::string &label) {
    vk::CheckView(src, width, height, channels, "wavelet synthesize source");
    vk::CheckView(tmp, width, height, channels, "wavelet synthesize temporary");
    vk::CheckView(dst, width, height, channels, "wavelet synthesize destination");
    CheckWaveletTemporary(tmp, src, dst, width, "wavelet synthesize");
    // Inverse order: columns first.
    RecordWaveletSynthesizePass(context, recorder, basis, WAVELET_AXIS_COLUMNS, width, height,
                                channels, src, tmp, label);
    RecordWaveletSynthesizePass(context, recorder, basis, WAVELET_AXIS_ROWS, width, height,
                                channels, tmp, dst, label);
}

void RecordWaveletSynthesizePass(vk::Context &context, vk::Recorder &recorder,
                                 WaveletBasis basis, int axis, int width, int height,
                                 int channels, const vk::ImageView &src,
                                 const vk::MutableImageView &dst, const std::string &label) {
    RecordWaveletLinePass(context, recorder, "wavelet_synthesize", k_wavelet_synthesize_spv,
                          sizeof(k_wavelet_synthesize_spv), basis, axis, width, height,
                          channels, src, dst, label);
}

}  // namespace mcd
