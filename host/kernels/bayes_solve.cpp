#include "host/kernels/bayes_solve.h"

#include <fmt/format.h>

#include "bayes/bayes.h"
#include "bayes/solve.h"
#include "bayes/solve_spv.h"
#include "host/error.h"
#include "host/vk/context.h"
#include "host/vk/kernel.h"

namespace mcd {

void RecordBayesSolve(vk::Context &context, vk::Recorder &recorder, const vk::Buffer &moments,
                      int bands, int levels, const vk::Buffer &noise, float pn,
                      vk::Buffer &params) {
    if (params.Bytes() < VkDeviceSize(bands) * BAYES_PARAM_STRIDE * sizeof(float) ||
        noise.Bytes() < VkDeviceSize(bands) * sizeof(float) ||
        moments.Bytes() < VkDeviceSize(bands) * BAYES_MOMENT_STRIDE * sizeof(float))
        throw Error(fmt::format("bayes solve: buffers too small for {} bands", bands),
                    ErrorKind::Internal);
    const vk::Kernel &kernel = context.GetKernel({"bayes_solve",
                                                  k_bayes_solve_spv,
                                                  sizeof(k_bayes_solve_spv),
                                                  BAYES_SOLVE_BINDINGS,
                                                  sizeof(shader::BayesSolvePush),
                                                  {}});
    shader::BayesSolvePush push{bands, levels, pn};
    recorder.Dispatch(kernel, "bayes.solve",
                      {{BAYES_SOLVE_MOMENTS, &moments, vk::Access::Read},
                       {BAYES_SOLVE_PARAMS, &params, vk::Access::Write},
                       {BAYES_SOLVE_NOISE, &noise, vk::Access::Read}},
                      push,
                      uint32_t((bands + BAYES_SOLVE_LOCAL_SIZE - 1) / BAYES_SOLVE_LOCAL_SIZE));
}

}  // namespace mcd
