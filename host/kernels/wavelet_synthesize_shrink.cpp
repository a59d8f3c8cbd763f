#include "host/kernels/wavelet_synthesize_shrink.h"

#include <fmt/format.h>

#include "host/error.h"
#include "host/kernels/wavelet_lines.h"
#include "host/kernels/wavelet_synthesize.h"
#include "wavelet/synthesize_shrink.h"
#include "wavelet/synthesize_shrink_spv.h"

namespace mcd {

void RecordWaveletSynthesizeShrink(vk::Context &context, vk::Recorder &recorder,
                                   WaveletBasis basis, int width, int height, int channels,
                                   const vk::ImageView &src, const vk::ImageView &variance,
                                   float cs, const vk::MutableImageView &tmp,
                                   const vk::MutableImageView &dst, const std::string &label) {
    vk::CheckView(src, width, height, channels, "wavelet synthesize-shrink source");
    vk::CheckView(variance, width, height, channels, "wavelet synthesize-shrink variance");
    vk::CheckView(tmp, width, height, channels, "wavelet synthesize-shrink temporary");
    vk::CheckView(dst, width, height, channels, "wavelet synthesize-shrink destination");
    CheckWaveletTemporary(tmp, src, dst, width, "wavelet synthesize-shrink");
    // The kernel indexes the variances with the coefficients' strides.
    if (variance.stride != src.stride || variance.plane != src.plane)
        throw Error(fmt::format("wavelet synthesize-shrink: the variance view (stride {}, "
                                "plane {}) must be laid "
                                "out like the coefficients (stride {}, plane {})",
                                variance.stride, variance.plane, src.stride, src.plane),
                    ErrorKind::Internal);
    if (variance.buffer == tmp.buffer || variance.buffer == dst.buffer)
        throw Error("wavelet synthesize-shrink: the variances must not be overwritten",
                    ErrorKind::Internal);
    static_assert(sizeof(shader::WaveletSynthesizeShrinkPush) ==
                  sizeof(shader::WaveletLinesPush) + sizeof(float));
    RecordWaveletLinePass(
        context, recorder, "wavelet_synthesize_shrink", k_wavelet_synthesize_shrink_spv,
        sizeof(k_wavelet_synthesize_shrink_spv), basis, WAVELET_AXIS_COLUMNS, width, height,
        channels, src, tmp, label, shader::WaveletSynthesizeShrinkPush{{}, cs},
        {{WAVELET_SYNTHESIZE_SHRINK_VARIANCE, variance.buffer}});
    // The rows pass is the plain synthesis's.
    RecordWaveletSynthesizePass(context, recorder, basis, WAVELET_AXIS_ROWS, width, height,
                                channels, tmp, dst, label);
}

}  // namespace mcd
