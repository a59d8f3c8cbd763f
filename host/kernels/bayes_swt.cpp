#include "host/kernels/bayes_swt.h"

#include <fmt/format.h>

#include "bayes/bayes.h"
#include "bayes/swt.h"
#include "bayes/swt_moments_spv.h"
#include "bayes/swt_shrink_spv.h"
#include "host/error.h"
#include "host/kernels/bayes_moments.h"
#include "host/vk/context.h"
#include "host/vk/kernel.h"
#include "wavelet/swt.h"

namespace mcd {
namespace {

void CheckCoefficients(const vk::GpuImage &coef, int channels, int levels, const char *kernel) {
    if (levels < 1 || channels < 1 || coef.channels < channels * shader::SwtPlaneCount(levels))
        throw Error(fmt::format("{}: {} planes are not the SWT of {} channels at {} levels",
                                kernel, coef.channels, channels, levels));
}

}  // namespace

void RecordBayesSwtMoments(vk::Context &context, vk::Recorder &recorder,
                           const vk::GpuImage &coef, int channels, int levels,
                           vk::Buffer &moments) {
    CheckCoefficients(coef, channels, levels, "bayes swt moments");
    int bands = BayesBandCount(channels, levels);
    if (moments.Bytes() < VkDeviceSize(bands) * BAYES_MOMENT_STRIDE * sizeof(float))
        throw Error(fmt::format("bayes swt moments: buffer too small for {} bands", bands));
    const vk::Kernel &kernel = context.GetKernel({"bayes_swt_moments",
                                                  k_bayes_swt_moments_spv,
                                                  sizeof(k_bayes_swt_moments_spv),
                                                  BAYES_SWT_MOMENTS_BINDINGS,
                                                  sizeof(shader::BayesSwtPush),
                                                  {},
                                                  1u << BAYES_SWT_COEF});
    shader::BayesSwtPush push{coef.width, coef.height, levels};
    recorder.Dispatch(kernel, "bayes.swt.moments",
                      {{BAYES_SWT_COEF, &coef.buffer, vk::Access::Read},
                       {BAYES_SWT_MOMENTS, &moments, vk::Access::Write}},
                      push, uint32_t(bands));
}

void RecordBayesSwtShrink(vk::Context &context, vk::Recorder &recorder, vk::GpuImage &coef,
                          int channels, int levels, const vk::Buffer &params,
                          const vk::Buffer &table) {
    CheckCoefficients(coef, channels, levels, "bayes swt shrink");
    int bands = BayesBandCount(channels, levels);
    if (params.Bytes() < VkDeviceSize(bands) * BAYES_PARAM_STRIDE * sizeof(float) ||
        table.Bytes() < VkDeviceSize(bands) * BAYES_TABLE_SIZE * sizeof(float))
        throw Error(fmt::format("bayes swt shrink: buffers too small for {} bands", bands));
    const vk::Kernel &kernel = context.GetKernel({"bayes_swt_shrink",
                                                  k_bayes_swt_shrink_spv,
                                                  sizeof(k_bayes_swt_shrink_spv),
                                                  BAYES_SWT_SHRINK_BINDINGS,
                                                  sizeof(shader::BayesSwtPush),
                                                  {},
                                                  1u << BAYES_SWT_TABLE});
    shader::BayesSwtPush push{coef.width, coef.height, levels};
    recorder.Dispatch(kernel, "bayes.swt.shrink",
                      {{BAYES_SWT_COEF, &coef.buffer, vk::Access::ReadWrite},
                       {BAYES_SWT_PARAMS, &params, vk::Access::Read},
                       {BAYES_SWT_TABLE, &table, vk::Access::Read}},
                      push,
                      uint32_t((coef.width + 4 * BAYES_SWT_SHRINK_LOCAL_SIZE - 1) /
                               (4 * BAYES_SWT_SHRINK_LOCAL_SIZE)),
                      uint32_t(coef.height), uint32_t(bands));
}

}  // namespace mcd
