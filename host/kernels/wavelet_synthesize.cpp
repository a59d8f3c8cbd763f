#include "host/kernels/wavelet_synthesize.h"

#include <cstdint>

#include "host/vk/context.h"
#include "host/vk/kernel.h"
#include "wavelet/synthesize.h"
#include "wavelet/synthesize_spv.h"

namespace mcd {

void RecordWaveletSynthesize(vk::Context &context, vk::Recorder &recorder, WaveletBasis basis,
                             int width, int height, int channels, const vk::ImageView &low,
                             const vk::ImageView &coef, const vk::ImageView &dst,
                             const std::string &label) {
    int lowWidth = LevelExtent(width, width > 1 ? 1 : 0);
    int lowHeight = LevelExtent(height, height > 1 ? 1 : 0);
    vk::CheckView(low, lowWidth, lowHeight, channels, "wavelet synthesize low band");
    vk::CheckView(coef, width, height, channels, "wavelet synthesize coefficients");
    vk::CheckView(dst, width, height, channels, "wavelet synthesize destination");

    const vk::Kernel &kernel = context.GetKernel(
        {"wavelet_synthesize", k_wavelet_synthesize_spv, sizeof(k_wavelet_synthesize_spv),
         WAVELET_SYNTHESIZE_BINDINGS, sizeof(shader::WaveletSynthesizePush),
         {{0, int32_t(basis)}}});
    shader::WaveletSynthesizePush push{width,       height,     low.stride, low.plane,
                                       coef.stride, coef.plane, dst.stride, dst.plane};
    recorder.Dispatch(kernel, label,
                      {{low.buffer, vk::Access::Read},
                       {coef.buffer, vk::Access::Read},
                       {dst.buffer, vk::Access::Write}},
                      &push, uint32_t((width + WAVELET_TILE - 1) / WAVELET_TILE),
                      uint32_t((height + WAVELET_TILE - 1) / WAVELET_TILE), uint32_t(channels));
}

}  // namespace mcd
