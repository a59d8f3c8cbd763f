#include "host/kernels/wavelet_analyze.h"

#include <cstdint>

#include "host/vk/context.h"
#include "host/vk/kernel.h"
#include "wavelet/analyze.h"
#include "wavelet/analyze_spv.h"

namespace mcd {

void RecordWaveletAnalyze(vk::Context &context, vk::Recorder &recorder, WaveletBasis basis,
                          int width, int height, int channels, const vk::ImageView &src,
                          const vk::ImageView &coef, const vk::ImageView &low,
                          const std::string &label) {
    int lowWidth = LevelExtent(width, width > 1 ? 1 : 0);
    int lowHeight = LevelExtent(height, height > 1 ? 1 : 0);
    vk::CheckView(src, width, height, channels, "wavelet analyze source");
    vk::CheckView(coef, width, height, channels, "wavelet analyze coefficients");
    vk::CheckView(low, lowWidth, lowHeight, channels, "wavelet analyze low band");

    const vk::Kernel &kernel = context.GetKernel(
        {"wavelet_analyze", k_wavelet_analyze_spv, sizeof(k_wavelet_analyze_spv),
         WAVELET_ANALYZE_BINDINGS, sizeof(shader::WaveletAnalyzePush),
         {{0, int32_t(basis)}}});
    shader::WaveletAnalyzePush push{width,       height,     src.stride, src.plane,
                                    coef.stride, coef.plane, low.stride, low.plane};
    recorder.Dispatch(kernel, label,
                      {{src.buffer, vk::Access::Read},
                       {coef.buffer, vk::Access::Write},
                       {low.buffer, vk::Access::Write}},
                      &push, uint32_t((width + WAVELET_TILE - 1) / WAVELET_TILE),
                      uint32_t((height + WAVELET_TILE - 1) / WAVELET_TILE), uint32_t(channels));
}

}  // namespace mcd
