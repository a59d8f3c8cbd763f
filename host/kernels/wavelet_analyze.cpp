#include "host/kernels/wavelet_analyze.h"

#include "host/kernels/wavelet_lines.h"
#include "host/vk/context.h"
#include "host/vk/kernel.h"
#include "wavelet/analyze.h"
#include "wavelet/analyze_spv.h"

namespace mcd {
namespace {

const vk::Kernel &AnalyzeKernel(vk::Context &context, WaveletBasis basis, int axis, bool vec4) {
    return context.GetKernel({"wavelet_analyze",
                              k_wavelet_analyze_spv,
                              sizeof(k_wavelet_analyze_spv),
                              WAVELET_ANALYZE_BINDINGS,
                              sizeof(shader::WaveletAnalyzePush),
                              {{WAVELET_SPEC_BASIS, int32_t(basis)},
                               {WAVELET_SPEC_AXIS, axis},
                               {WAVELET_SPEC_VEC4, vec4 ? 1 : 0}}});
}

}  // namespace

void RecordWaveletAnalyze(vk::Context &context, vk::Recorder &recorder, WaveletBasis basis,
                          int width, int height, int channels, const vk::ImageView &src,
                          const vk::ImageView &tmp, const vk::ImageView &dst,
                          const std::string &label) {
    vk::CheckView(src, width, height, channels, "wavelet analyze source");
    vk::CheckView(tmp, width, height, channels, "wavelet analyze temporary");
    vk::CheckView(dst, width, height, channels, "wavelet analyze destination");
    CheckWaveletTemporary(tmp, src, dst, width, "wavelet analyze");

    bool vec4 = WaveletVec4Rows(src, tmp);
    shader::WaveletAnalyzePush rows{width,     height,     src.stride,
                                    src.plane, tmp.stride, tmp.plane};
    WaveletGrid g = WaveletPassGrid(WAVELET_AXIS_ROWS, width, height, channels);
    recorder.Dispatch(AnalyzeKernel(context, basis, WAVELET_AXIS_ROWS, vec4), label + ".rows",
                      {{src.buffer, vk::Access::Read}, {tmp.buffer, vk::Access::Write}}, &rows,
                      g.x, g.y, g.z);

    shader::WaveletAnalyzePush columns{width,     height,     tmp.stride,
                                       tmp.plane, dst.stride, dst.plane};
    g = WaveletPassGrid(WAVELET_AXIS_COLUMNS, width, height, channels);
    recorder.Dispatch(AnalyzeKernel(context, basis, WAVELET_AXIS_COLUMNS, false),
                      label + ".columns",
                      {{tmp.buffer, vk::Access::Read}, {dst.buffer, vk::Access::Write}},
                      &columns, g.x, g.y, g.z);
}

}  // namespace mcd
