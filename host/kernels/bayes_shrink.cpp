#include "host/kernels/bayes_shrink.h"

#include <fmt/format.h>

#include "bayes/bayes.h"
#include "bayes/shrink.h"
#include "bayes/shrink_spv.h"
#include "host/error.h"
#include "host/kernels/bayes_moments.h"
#include "host/vk/context.h"
#include "host/vk/kernel.h"

namespace mcd {

void RecordBayesShrink(vk::Context &context, vk::Recorder &recorder, vk::GpuImage &coef,
                       int levels, const vk::Buffer &params, const vk::Buffer &table) {
    int bands = BayesBandCount(coef.channels, levels);
    if (params.Bytes() < VkDeviceSize(bands) * BAYES_PARAM_STRIDE * sizeof(float) ||
        table.Bytes() < VkDeviceSize(bands) * BAYES_TABLE_SIZE * sizeof(float))
        throw Error(fmt::format("bayes shrink: buffers too small for {} bands", bands),
                    ErrorKind::Internal);
    const vk::Kernel &kernel = context.GetKernel({"bayes_shrink",
                                                  k_bayes_shrink_spv,
                                                  sizeof(k_bayes_shrink_spv),
                                                  BAYES_SHRINK_BINDINGS,
                                                  sizeof(shader::BayesShrinkPush),
                                                  {}});
    shader::BayesShrinkPush push{coef.width, coef.height, levels};
    recorder.Dispatch(
        kernel, "bayes.shrink",
        {{BAYES_SHRINK_COEF, &coef.buffer, vk::Access::ReadWrite},
         {BAYES_SHRINK_PARAMS, &params, vk::Access::Read},
         {BAYES_SHRINK_TABLE, &table, vk::Access::Read}},
        push, uint32_t((coef.width + BAYES_SHRINK_LOCAL_SIZE - 1) / BAYES_SHRINK_LOCAL_SIZE),
        uint32_t(coef.height), uint32_t(coef.channels));
}

}  // namespace mcd
