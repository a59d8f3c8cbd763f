#include "host/kernels/auto_estimate.h"

#include <fmt/format.h>

#include <cmath>

#include "auto/estimate.h"
#include "auto/estimate_spv.h"
#include "host/error.h"
#include "host/vk/context.h"
#include "host/vk/kernel.h"

namespace mcd {

void CheckAutoShapes(const char *what, const vk::GpuImage &a, int channels,
                     std::initializer_list<const vk::GpuImage *> others) {
    for (const vk::GpuImage *b : others)
        if (b->width != a.width || b->height != a.height || b->channels != channels)
            throw Error(
                fmt::format("{}: {} is {}x{}x{}, {}x{}x{} expected", what, b->buffer.Name(),
                            b->width, b->height, b->channels, a.width, a.height, channels),
                ErrorKind::Internal);
}

void RecordAutoEstimate(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &color,
                        const vk::GpuImage &variance, const vk::GpuImage &probe,
                        const vk::GpuImage &guide, const vk::GpuImage &output,
                        const vk::GpuImage &perturbed, const vk::GpuImage &offset,
                        float epsilon, float noiseCap, vk::GpuImage &error) {
    if (color.channels < 1 || color.channels > 4)
        throw Error(
            fmt::format("auto estimate: {} channels; 1 to 4 are supported", color.channels),
            ErrorKind::InvalidArgument);
    CheckAutoShapes("auto estimate", color, color.channels,
                    {&variance, &probe, &guide, &output, &perturbed, &offset});
    CheckAutoShapes("auto estimate", color, 1, {&error});
    if (!(epsilon > 0) || !std::isfinite(epsilon))
        throw Error(fmt::format("auto estimate: epsilon {} is not a positive number", epsilon),
                    ErrorKind::InvalidArgument);
    if (!(noiseCap >= 0) || !std::isfinite(noiseCap))
        throw Error(fmt::format("auto estimate: noise cap {} is not a number >= 0", noiseCap),
                    ErrorKind::InvalidArgument);
    const vk::Kernel &kernel = context.GetKernel({"auto_estimate",
                                                  k_auto_estimate_spv,
                                                  sizeof(k_auto_estimate_spv),
                                                  AUTO_ESTIMATE_BINDINGS,
                                                  sizeof(shader::AutoEstimatePush),
                                                  {},
                                                  0});
    shader::AutoEstimatePush push{color.width, color.height, color.channels, epsilon, noiseCap};
    recorder.Dispatch(kernel, "auto.estimate",
                      {{AUTO_ESTIMATE_COLOR, &color.buffer, vk::Access::Read},
                       {AUTO_ESTIMATE_VARIANCE, &variance.buffer, vk::Access::Read},
                       {AUTO_ESTIMATE_PROBE, &probe.buffer, vk::Access::Read},
                       {AUTO_ESTIMATE_OUTPUT, &output.buffer, vk::Access::Read},
                       {AUTO_ESTIMATE_PERTURBED, &perturbed.buffer, vk::Access::Read},
                       {AUTO_ESTIMATE_ERROR, &error.buffer, vk::Access::Write},
                       {AUTO_ESTIMATE_GUIDE, &guide.buffer, vk::Access::Read},
                       {AUTO_ESTIMATE_OFFSET, &offset.buffer, vk::Access::Read}},
                      push, uint32_t((color.width + AUTO_LOCAL_SIZE - 1) / AUTO_LOCAL_SIZE),
                      uint32_t(color.height));
}

}  // namespace mcd
