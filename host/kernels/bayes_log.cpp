#include "host/kernels/bayes_log.h"

#include <fmt/format.h>

#include "bayes/log.h"
#include "bayes/log_spv.h"
#include "host/error.h"
#include "host/vk/context.h"
#include "host/vk/kernel.h"

namespace mcd {

void RecordBayesLog(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &color,
                    const vk::Buffer &floors, vk::GpuImage &out, bool fillMissed) {
    if (!color.buffer.Valid() || color.width != out.width || color.height != out.height ||
        color.channels != out.channels)
        throw Error(
            fmt::format("bayes log: input {}x{}x{} and output {}x{}x{} differ", color.width,
                        color.height, color.channels, out.width, out.height, out.channels),
            ErrorKind::Internal);
    if (floors.Bytes() < VkDeviceSize(color.channels) * sizeof(float))
        throw Error("bayes log: the floors buffer holds fewer floats than channels",
                    ErrorKind::Internal);
    const vk::Kernel &kernel = context.GetKernel({"bayes_log",
                                                  k_bayes_log_spv,
                                                  sizeof(k_bayes_log_spv),
                                                  BAYES_LOG_BINDINGS,
                                                  sizeof(shader::BayesLogPush),
                                                  {}});
    shader::BayesLogPush push{color.width, color.height, fillMissed ? 1 : 0};
    recorder.Dispatch(kernel, "bayes.log",
                      {{BAYES_LOG_COLOR, &color.buffer, vk::Access::Read},
                       {BAYES_LOG_FLOORS, &floors, vk::Access::Read},
                       {BAYES_LOG_OUT, &out.buffer, vk::Access::Write}},
                      push,
                      uint32_t((color.width + BAYES_LOG_LOCAL_SIZE - 1) / BAYES_LOG_LOCAL_SIZE),
                      uint32_t(color.height), uint32_t(color.channels));
}

}  // namespace mcd
