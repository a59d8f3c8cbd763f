#include "host/kernels/awr_shrink.h"

#include <fmt/format.h>

#include "awr/shrink.h"
#include "awr/shrink_spv.h"
#include "host/error.h"
#include "host/vk/context.h"
#include "host/vk/kernel.h"

namespace mcd {

void RecordAwrShrink(vk::Context &context, vk::Recorder &recorder, vk::GpuImage &coef,
                     const vk::GpuImage &variance, int lowWidth, int lowHeight, float cs) {
    if (coef.width != variance.width || coef.height != variance.height ||
        coef.channels != variance.channels)
        throw Error(
            fmt::format("awr shrink: coefficients {}x{}x{} and variances {}x{}x{} differ",
                        coef.width, coef.height, coef.channels, variance.width, variance.height,
                        variance.channels),
            ErrorKind::Internal);
    const vk::Kernel &kernel = context.GetKernel({"awr_shrink",
                                                  k_awr_shrink_spv,
                                                  sizeof(k_awr_shrink_spv),
                                                  AWR_SHRINK_BINDINGS,
                                                  sizeof(shader::AwrShrinkPush),
                                                  {}});
    shader::AwrShrinkPush push{coef.width, coef.height, lowWidth, lowHeight, cs};
    recorder.Dispatch(
        kernel, "awr.shrink",
        {{AWR_SHRINK_COEF, &coef.buffer, vk::Access::ReadWrite},
         {AWR_SHRINK_VARIANCE, &variance.buffer, vk::Access::Read}},
        push, uint32_t((coef.width + AWR_SHRINK_LOCAL_SIZE - 1) / AWR_SHRINK_LOCAL_SIZE),
        uint32_t(coef.height), uint32_t(coef.channels));
}

}  // namespace mcd
