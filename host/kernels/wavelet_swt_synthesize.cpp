#include "host/kernels/wavelet_swt_synthesize.h"

#include "host/error.h"
#include "host/vk/context.h"
#include "host/vk/kernel.h"
#include "wavelet/swt.h"
#include "wavelet/swt_synthesize_spv.h"

namespace mcd {

void RecordWaveletSwtSynthesize(vk::Context &context, vk::Recorder &recorder,
                                SwtSynthesizePass pass, WaveletBasis basis,
                                const shader::WaveletSwtSynthesizePush &push, int channels,
                                const vk::Buffer &src, vk::Buffer &dst,
                                const std::string &label) {
    if (push.width < 1 || push.height < 1 || channels < 1 || push.step < 1)
        throw Error("wavelet swt synthesize: empty pass", ErrorKind::Internal);
    int axis = pass == SwtSynthesizePass::Rows ? WAVELET_SWT_ROWS : WAVELET_SWT_COLUMNS;
    const vk::Kernel &kernel = context.GetKernel(
        {"wavelet_swt_synthesize",
         k_wavelet_swt_synthesize_spv,
         sizeof(k_wavelet_swt_synthesize_spv),
         WAVELET_SWT_SYNTHESIZE_BINDINGS,
         sizeof(shader::WaveletSwtSynthesizePush),
         {{WAVELET_SWT_SPEC_BASIS, int32_t(basis)}, {WAVELET_SWT_SPEC_AXIS, axis}},
         1u << WAVELET_SWT_SYNTHESIZE_SRC});
    recorder.Dispatch(kernel, label,
                      {{WAVELET_SWT_SYNTHESIZE_SRC, &src, vk::Access::Read},
                       {WAVELET_SWT_SYNTHESIZE_DST, &dst, vk::Access::Write}},
                      push,
                      uint32_t((push.width + 4 * WAVELET_SWT_SYNTHESIZE_LOCAL_SIZE - 1) /
                               (4 * WAVELET_SWT_SYNTHESIZE_LOCAL_SIZE)),
                      uint32_t(push.height), uint32_t(channels));
}

}  // namespace mcd
