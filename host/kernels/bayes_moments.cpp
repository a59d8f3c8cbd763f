#include "host/kernels/bayes_moments.h"

#include <fmt/format.h>

#include "bayes/bayes.h"
#include "bayes/moments.h"
#include "bayes/moments_spv.h"
#include "host/error.h"
#include "host/vk/context.h"
#include "host/vk/kernel.h"

namespace mcd {

void RecordBayesMoments(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &coef,
                        int levels, vk::Buffer &moments) {
    int bands = BayesBandCount(coef.channels, levels);
    if (levels < 1)
        throw Error("bayes moments: needs at least one level", ErrorKind::InvalidArgument);
    if (moments.Bytes() < VkDeviceSize(bands) * BAYES_MOMENT_STRIDE * sizeof(float))
        throw Error(fmt::format("bayes moments: buffer too small for {} bands", bands),
                    ErrorKind::Internal);
    const vk::Kernel &kernel = context.GetKernel({"bayes_moments",
                                                  k_bayes_moments_spv,
                                                  sizeof(k_bayes_moments_spv),
                                                  BAYES_MOMENTS_BINDINGS,
                                                  sizeof(shader::BayesMomentsPush),
                                                  {}});
    shader::BayesMomentsPush push{coef.width, coef.height, levels};
    recorder.Dispatch(kernel, "bayes.moments",
                      {{BAYES_MOMENTS_COEF, &coef.buffer, vk::Access::Read},
                       {BAYES_MOMENTS_OUT, &moments, vk::Access::Write}},
                      push, uint32_t(bands));
}

}  // namespace mcd
