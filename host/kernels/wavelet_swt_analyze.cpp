#include "host/kernels/wavelet_swt_analyze.h"

#include "host/error.h"
#include "host/vk/context.h"
#include "host/vk/kernel.h"
#include "wavelet/swt.h"
#include "wavelet/swt_analyze_spv.h"

namespace mcd {

void RecordWaveletSwtAnalyze(vk::Context &context, vk::Recorder &recorder, SwtAnalyzePass pass,
                             WaveletBasis basis, bool squared,
                             const shader::WaveletSwtAnalyzePush &push, int channels,
                             const vk::Buffer &src, vk::Buffer &dst, const std::string &label) {
    if (push.width < 1 || push.height < 1 || channels < 1 || push.step < 1)
        throw Error("wavelet swt analyze: empty pass", ErrorKind::Internal);
    bool fused = pass == SwtAnalyzePass::Fused;
    if (fused && basis != WaveletBasis::Haar)
        throw Error("wavelet swt analyze: the fused passes are Haar only", ErrorKind::Internal);
    int axis = fused                          ? WAVELET_SWT_FUSED
               : pass == SwtAnalyzePass::Rows ? WAVELET_SWT_ROWS
                                              : WAVELET_SWT_COLUMNS;
    const vk::Kernel &kernel =
        context.GetKernel({"wavelet_swt_analyze",
                           k_wavelet_swt_analyze_spv,
                           sizeof(k_wavelet_swt_analyze_spv),
                           WAVELET_SWT_ANALYZE_BINDINGS,
                           sizeof(shader::WaveletSwtAnalyzePush),
                           {{WAVELET_SWT_SPEC_BASIS, int32_t(basis)},
                            {WAVELET_SWT_SPEC_AXIS, axis},
                            {WAVELET_SWT_ANALYZE_SPEC_SQUARED, squared ? 1 : 0}},
                           1u << WAVELET_SWT_ANALYZE_SRC});
    recorder.Dispatch(kernel, label,
                      {{WAVELET_SWT_ANALYZE_SRC, &src, vk::Access::Read},
                       {WAVELET_SWT_ANALYZE_DST, &dst, vk::Access::Write}},
                      push,
                      uint32_t((push.width + 4 * WAVELET_SWT_ANALYZE_LOCAL_SIZE - 1) /
                               (4 * WAVELET_SWT_ANALYZE_LOCAL_SIZE)),
                      uint32_t(push.height), uint32_t(channels));
}

}  // namespace mcd
