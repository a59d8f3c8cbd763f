#include "host/kernels/wavelet_synthesize.h"

#include "host/kernels/wavelet_lines.h"
#include "host/vk/context.h"
#include "host/vk/kernel.h"
#include "wavelet/synthesize.h"
#include "wavelet/synthesize_spv.h"

namespace mcd {
namespace {

const vk::Kernel &SynthesizeKernel(vk::Context &context, WaveletBasis basis, int axis,
                                   bool vec4) {
    return context.GetKernel({"wavelet_synthesize",
                              k_wavelet_synthesize_spv,
                              sizeof(k_wavelet_synthesize_spv),
                              WAVELET_SYNTHESIZE_BINDINGS,
                              sizeof(shader::WaveletSynthesizePush),
                              {{WAVELET_SPEC_BASIS, int32_t(basis)},
                               {WAVELET_SPEC_AXIS, axis},
                               {WAVELET_SPEC_VEC4, vec4 ? 1 : 0}}});
}

}  // namespace

void RecordWaveletSynthesize(vk::Context &context, vk::Recorder &recorder, WaveletBasis basis,
                             int width, int height, int channels, const vk::ImageView &src,
                             const vk::ImageView &tmp, const vk::ImageView &dst,
                             const std::string &label) {
    vk::CheckView(src, width, height, channels, "wavelet synthesize source");
    vk::CheckView(tmp, width, height, channels, "wavelet synthesize temporary");
    vk::CheckView(dst, width, height, channels, "wavelet synthesize destination");
    CheckWaveletTemporary(tmp, src, dst, width, "wavelet synthesize");

    shader::WaveletSynthesizePush columns{width,     height,     src.stride,
                                          src.plane, tmp.stride, tmp.plane};
    WaveletGrid g = WaveletPassGrid(WAVELET_AXIS_COLUMNS, width, height, channels);
    recorder.Dispatch(SynthesizeKernel(context, basis, WAVELET_AXIS_COLUMNS, false),
                      label + ".columns",
                      {{src.buffer, vk::Access::Read}, {tmp.buffer, vk::Access::Write}},
                      &columns, g.x, g.y, g.z);

    bool vec4 = WaveletVec4Rows(tmp, dst);
    shader::WaveletSynthesizePush rows{width,     height,     tmp.stride,
                                       tmp.plane, dst.stride, dst.plane};
    g = WaveletPassGrid(WAVELET_AXIS_ROWS, width, height, channels);
    recorder.Dispatch(SynthesizeKernel(context, basis, WAVELET_AXIS_ROWS, vec4),
                      label + ".rows",
                      {{tmp.buffer, vk::Access::Read}, {dst.buffer, vk::Access::Write}}, &rows,
                      g.x, g.y, g.z);
}

}  // namespace mcd
