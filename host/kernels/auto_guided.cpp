#include "host/kernels/auto_guided.h"

#include <fmt/format.h>

#include <cmath>

#include "auto/guided.h"
#include "auto/guided_spv.h"
#include "host/error.h"
#include "host/kernels/auto_estimate.h"
#include "host/vk/context.h"
#include "host/vk/kernel.h"

namespace mcd {

void RecordAutoSmoothGuided(vk::Context &context, vk::Recorder &recorder,
                            const vk::GpuImage &input, const vk::GpuImage &guide, int radius,
                            float bandwidth, vk::GpuImage &output) {
    CheckAutoShapes("auto guided smooth", input, input.channels, {&output});
    CheckAutoShapes("auto guided smooth", input, guide.channels, {&guide});
    if (input.channels < 1 || input.channels > AUTO_GUIDED_MAX_PLANES || guide.channels < 1 ||
        guide.channels > AUTO_GUIDED_MAX_GUIDE_CHANNELS)
        throw Error(fmt::format("auto guided smooth: {} planes and a guide of {} channels; 1 "
                                "to {} and 1 to {}",
                                input.channels, guide.channels, AUTO_GUIDED_MAX_PLANES,
                                AUTO_GUIDED_MAX_GUIDE_CHANNELS),
                    ErrorKind::Internal);
    if (radius < 0 || radius > 64)
        throw Error(fmt::format("auto guided smooth: radius {} outside [0, 64]", radius),
                    ErrorKind::InvalidArgument);
    if (!(bandwidth > 0) || !std::isfinite(bandwidth))
        throw Error(
            fmt::format("auto guided smooth: bandwidth {} is not a positive number", bandwidth),
            ErrorKind::InvalidArgument);
    shader::AutoGuidedPush push{input.width,    input.height,   radius,
                                input.channels, guide.channels, 1.f / (bandwidth * bandwidth)};
    const vk::Kernel &kernel = context.GetKernel({"auto_guided",
                                                  k_auto_guided_spv,
                                                  sizeof(k_auto_guided_spv),
                                                  AUTO_GUIDED_BINDINGS,
                                                  sizeof(shader::AutoGuidedPush),
                                                  {},
                                                  0});
    recorder.Dispatch(kernel, "auto.smooth.guided",
                      {{AUTO_GUIDED_INPUT, &input.buffer, vk::Access::Read},
                       {AUTO_GUIDED_GUIDE, &guide.buffer, vk::Access::Read},
                       {AUTO_GUIDED_OUTPUT, &output.buffer, vk::Access::Write}},
                      push, uint32_t((input.width + AUTO_LOCAL_SIZE - 1) / AUTO_LOCAL_SIZE),
                      uint32_t(input.height), 1);
}

}  // namespace mcd
