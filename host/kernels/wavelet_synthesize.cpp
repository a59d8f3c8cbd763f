#include "host/kernels/wavelet_synthesize.h"

#include "host/kernels/wavelet_lines.h"
#include "wavelet/synthesize_spv.h"

namespace mcd {

void RecordWaveletSynthesize(vk::Context &context, vk::Recorder &recorder, WaveletBasis basis,
                             int width, int height, int channels, const vk::ImageView &src,
                             const vk::ImageView &tmp, const vk::ImageView &dst,
                             const std::string &label) {
    vk::CheckView(src, width, height, channels, "wavelet synthesize source");
    vk::CheckView(tmp, width, height, channels, "wavelet synthesize temporary");
    vk::CheckView(dst, width, height, channels, "wavelet synthesize destination");
    CheckWaveletTemporary(tmp, src, dst, width, "wavelet synthesize");
    // Inverse order: columns first.
    for (int axis : {WAVELET_AXIS_COLUMNS, WAVELET_AXIS_ROWS})
        RecordWaveletLinePass(context, recorder, "wavelet_synthesize", k_wavelet_synthesize_spv,
                              sizeof(k_wavelet_synthesize_spv), basis, axis, width, height,
                              channels, axis == WAVELET_AXIS_COLUMNS ? src : tmp,
                              axis == WAVELET_AXIS_COLUMNS ? tmp : dst, label);
}

}  // namespace mcd
