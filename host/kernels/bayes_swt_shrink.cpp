#include "host/kernels/bayes_swt_shrink.h"

#include <fmt/format.h>

#include "bayes/bayes.h"
#include "bayes/swt_shrink.h"
#include "bayes/swt_shrink_spv.h"
#include "host/error.h"
#include "host/kernels/bayes_moments.h"
#include "host/vk/context.h"
#include "host/vk/kernel.h"
#include "wavelet/swt.h"

namespace mcd {

void RecordBayesSwtShrink(vk::Context &context, vk::Recorder &recorder, vk::GpuImage &coef,
                          int channels, int levels, const vk::Buffer &params,
                          const vk::Buffer &table) {
    if (levels < 1 || channels < 1 || coef.channels < channels * shader::SwtPlaneCount(levels))
        throw Error(
            fmt::format("bayes swt shrink: {} planes are not the SWT of {} channels at {} "
                        "levels",
                        coef.channels, channels, levels),
            ErrorKind::Internal);
    int bands = BayesBandCount(channels, levels);
    if (params.Bytes() < VkDeviceSize(bands) * BAYES_PARAM_STRIDE * sizeof(float) ||
        table.Bytes() < VkDeviceSize(bands) * BAYES_TABLE_SIZE * sizeof(float))
        throw Error(fmt::format("bayes swt shrink: buffers too small for {} bands", bands),
                    ErrorKind::Internal);
    const vk::Kernel &kernel = context.GetKernel({"bayes_swt_shrink",
                                                  k_bayes_swt_shrink_spv,
                                                  sizeof(k_bayes_swt_shrink_spv),
                                                  BAYES_SWT_SHRINK_BINDINGS,
                                                  sizeof(shader::BayesSwtShrinkPush),
                                                  {},
                                                  1u << BAYES_SWT_SHRINK_TABLE});
    shader::BayesSwtShrinkPush push{coef.width, coef.height, levels};
    recorder.Dispatch(kernel, "bayes.swt.shrink",
                      {{BAYES_SWT_SHRINK_COEF, &coef.buffer, vk::Access::ReadWrite},
                       {BAYES_SWT_SHRINK_PARAMS, &params, vk::Access::Read},
                       {BAYES_SWT_SHRINK_TABLE, &table, vk::Access::Read}},
                      push,
                      uint32_t((coef.width + 4 * BAYES_SWT_SHRINK_LOCAL_SIZE - 1) /
                               (4 * BAYES_SWT_SHRINK_LOCAL_SIZE)),
                      uint32_t(coef.height), uint32_t(bands));
}

}  // namespace mcd
