#include "host/kernels/wavelet_sqanalyze.h"

#include <cstdint>

#include "host/vk/context.h"
#include "host/vk/kernel.h"
#include "wavelet/sqanalyze.h"
#include "wavelet/sqanalyze_spv.h"

namespace mcd {

void RecordWaveletSqAnalyze(vk::Context &context, vk::Recorder &recorder, WaveletBasis basis,
                            int width, int height, int channels, const vk::ImageView &src,
                            const vk::ImageView &coef, const vk::ImageView &low, float lowSum,
                            float highSum, const std::string &label) {
    int lowWidth = LevelExtent(width, width > 1 ? 1 : 0);
    int lowHeight = LevelExtent(height, height > 1 ? 1 : 0);
    vk::CheckView(src, width, height, channels, "wavelet sqanalyze source");
    vk::CheckView(coef, width, height, channels, "wavelet sqanalyze coefficients");
    vk::CheckView(low, lowWidth, lowHeight, channels, "wavelet sqanalyze low band");

    const vk::Kernel &kernel = context.GetKernel({"wavelet_sqanalyze",
                                                  k_wavelet_sqanalyze_spv,
                                                  sizeof(k_wavelet_sqanalyze_spv),
                                                  WAVELET_SQANALYZE_BINDINGS,
                                                  sizeof(shader::WaveletSqAnalyzePush),
                                                  {{0, int32_t(basis)}}});
    shader::WaveletSqAnalyzePush push{width,       height,     src.stride, src.plane,
                                      coef.stride, coef.plane, low.stride, low.plane,
                                      lowSum,      highSum};
    recorder.Dispatch(kernel, label,
                      {{src.buffer, vk::Access::Read},
                       {coef.buffer, vk::Access::Write},
                       {low.buffer, vk::Access::Write}},
                      &push, uint32_t((width + WAVELET_TILE - 1) / WAVELET_TILE),
                      uint32_t((height + WAVELET_TILE - 1) / WAVELET_TILE), uint32_t(channels));
}

}  // namespace mcd
