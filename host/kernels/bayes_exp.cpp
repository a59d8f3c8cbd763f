#include "host/kernels/bayes_exp.h"

#include <fmt/format.h>

#include <utility>

#include "bayes/exp.h"
#include "bayes/exp_spv.h"
#include "host/error.h"
#include "host/vk/context.h"
#include "host/vk/kernel.h"

namespace mcd {

void RecordBayesExp(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &logImage,
                    const vk::GpuImage &original, vk::GpuImage &out, bool restoreZeros) {
    for (const vk::GpuImage *image : {&original, &std::as_const(out)})
        if (image->width != logImage.width || image->height != logImage.height ||
            image->channels != logImage.channels)
            throw Error(
                fmt::format("bayes exp: '{}' is {}x{}x{}, the log image {}x{}x{}",
                            image->buffer.Name(), image->width, image->height, image->channels,
                            logImage.width, logImage.height, logImage.channels),
                ErrorKind::Internal);
    const vk::Kernel &kernel = context.GetKernel({"bayes_exp",
                                                  k_bayes_exp_spv,
                                                  sizeof(k_bayes_exp_spv),
                                                  BAYES_EXP_BINDINGS,
                                                  sizeof(shader::BayesExpPush),
                                                  {}});
    shader::BayesExpPush push{logImage.width, logImage.height, restoreZeros ? 1 : 0};
    recorder.Dispatch(
        kernel, "bayes.exp",
        {{BAYES_EXP_LOG, &logImage.buffer, vk::Access::Read},
         {BAYES_EXP_ORIGINAL, &original.buffer, vk::Access::Read},
         {BAYES_EXP_OUT, &out.buffer, vk::Access::Write}},
        push, uint32_t((logImage.width + BAYES_EXP_LOCAL_SIZE - 1) / BAYES_EXP_LOCAL_SIZE),
        uint32_t(logImage.height), uint32_t(logImage.channels));
}

}  // namespace mcd
