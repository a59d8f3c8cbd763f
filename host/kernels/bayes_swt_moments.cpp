#include "host/kernels/bayes_swt_moments.h"

#include <fmt/format.h>

#include "bayes/bayes.h"
#include "bayes/swt_moments.h"
#include "bayes/swt_moments_spv.h"
#include "host/error.h"
#include "host/kernels/bayes_moments.h"
#include "host/vk/context.h"
#include "host/vk/kernel.h"
#include "wavelet/swt.h"

namespace mcd {

void RecordBayesSwtMoments(vk::Context &context, vk::Recorder &recorder,
                           const vk::GpuImage &coef, int channels, int levels,
                           vk::Buffer &moments) {
    if (levels < 1 || channels < 1 || coef.channels < channels * shader::SwtPlaneCount(levels))
        throw Error(
            fmt::format("bayes swt moments: {} planes are not the SWT of {} channels at {} "
                        "levels",
                        coef.channels, channels, levels),
            ErrorKind::Internal);
    int bands = BayesBandCount(channels, levels);
    if (moments.Bytes() < VkDeviceSize(bands) * BAYES_MOMENT_STRIDE * sizeof(float))
        throw Error(fmt::format("bayes swt moments: buffer too small for {} bands", bands),
                    ErrorKind::Internal);
    const vk::Kernel &kernel = context.GetKernel({"bayes_swt_moments",
                                                  k_bayes_swt_moments_spv,
                                                  sizeof(k_bayes_swt_moments_spv),
                                                  BAYES_SWT_MOMENTS_BINDINGS,
                                                  sizeof(shader::BayesSwtMomentsPush),
                                                  {},
                                                  1u << BAYES_SWT_MOMENTS_COEF});
    shader::BayesSwtMomentsPush push{coef.width, coef.height, levels};
    recorder.Dispatch(kernel, "bayes.swt.moments",
                      {{BAYES_SWT_MOMENTS_COEF, &coef.buffer, vk::Access::Read},
                       {BAYES_SWT_MOMENTS_OUT, &moments, vk::Access::Write}},
                      push, uint32_t(bands));
}

}  // namespace mcd
