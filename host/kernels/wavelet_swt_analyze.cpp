#include "host/kernels/wavelet_swt.h"

#include "host/error.h"
#include "host/vk/context.h"
#include "host/vk/kernel.h"
#include "wavelet/swt_analyze_spv.h"
#include "wavelet/swt_synthesize_spv.h"

namespace mcd {

void RecordWaveletSwtPass(vk::Context &context, vk::Recorder &recorder, SwtPass pass,
                          WaveletBasis basis, bool squared, const shader::WaveletSwtPush &push,
                          int channels, const vk::Buffer &src, vk::Buffer &dst,
                          const std::string &label) {
    if (push.width < 1 || push.height < 1 || channels < 1 || push.step < 1)
        throw Error("wavelet swt: empty pass");
    bool analyze = pass == SwtPass::AnalyzeRows || pass == SwtPass::AnalyzeColumns ||
                   pass == SwtPass::AnalyzeFused;
    bool rows = pass == SwtPass::AnalyzeRows || pass == SwtPass::SynthesizeRows;
    if (squared && !analyze) throw Error("wavelet swt: the squared taps are analysis only");
    bool fused = pass == SwtPass::AnalyzeFused;
    if (fused && basis != WaveletBasis::Haar)
        throw Error("wavelet swt: the fused passes are Haar only");
    int axis = fused ? WAVELET_SWT_FUSED : rows ? WAVELET_SWT_ROWS : WAVELET_SWT_COLUMNS;
    const vk::Kernel &kernel =
        analyze ? context.GetKernel({"wavelet_swt_analyze",
                                     k_wavelet_swt_analyze_spv,
                                     sizeof(k_wavelet_swt_analyze_spv),
                                     WAVELET_SWT_BINDINGS,
                                     sizeof(shader::WaveletSwtPush),
                                     {{WAVELET_SWT_SPEC_BASIS, int32_t(basis)},
                                      {WAVELET_SWT_SPEC_AXIS, axis},
                                      {WAVELET_SWT_SPEC_SQUARED, squared ? 1 : 0}},
                                     1u << WAVELET_SWT_SRC})
                : context.GetKernel({"wavelet_swt_synthesize",
                                     k_wavelet_swt_synthesize_spv,
                                     sizeof(k_wavelet_swt_synthesize_spv),
                                     WAVELET_SWT_BINDINGS,
                                     sizeof(shader::WaveletSwtPush),
                                     {{WAVELET_SWT_SPEC_BASIS, int32_t(basis)},
                                      {WAVELET_SWT_SPEC_AXIS, axis}},
                                     1u << WAVELET_SWT_SRC});
    recorder.Dispatch(
        kernel, label,
        {{WAVELET_SWT_SRC, &src, vk::Access::Read}, {WAVELET_SWT_DST, &dst, vk::Access::Write}},
        push,
        uint32_t((push.width + 4 * WAVELET_SWT_LOCAL_SIZE - 1) / (4 * WAVELET_SWT_LOCAL_SIZE)),
        uint32_t(push.height), uint32_t(channels));
}

}  // namespace mcd
