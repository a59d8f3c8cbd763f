#include "host/kernels/auto_smooth.h"

#include <fmt/format.h>

#include "auto/smooth.h"
#include "auto/smooth_spv.h"
#include "host/error.h"
#include "host/kernels/auto_estimate.h"
#include "host/vk/context.h"
#include "host/vk/kernel.h"

namespace mcd {

void RecordAutoSmooth(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &input,
                      int radius, vk::GpuImage &output) {
    CheckAutoShapes("auto smooth", input, input.channels, {&output});
    if (radius < 0 || radius > 64)
        throw Error(fmt::format("auto smooth: radius {} outside [0, 64]", radius),
                    ErrorKind::InvalidArgument);
    const vk::Kernel &kernel = context.GetKernel({"auto_smooth",
                                                  k_auto_smooth_spv,
                                                  sizeof(k_auto_smooth_spv),
                                                  AUTO_SMOOTH_BINDINGS,
                                                  sizeof(shader::AutoSmoothPush),
                                                  {},
                                                  0});
    shader::AutoSmoothPush push{input.width, input.height, radius};
    recorder.Dispatch(kernel, "auto.smooth",
                      {{AUTO_SMOOTH_INPUT, &input.buffer, vk::Access::Read},
                       {AUTO_SMOOTH_OUTPUT, &output.buffer, vk::Access::Write}},
                      push, uint32_t((input.width + AUTO_LOCAL_SIZE - 1) / AUTO_LOCAL_SIZE),
                      uint32_t(input.height), uint32_t(input.channels));
}

}  // namespace mcd
