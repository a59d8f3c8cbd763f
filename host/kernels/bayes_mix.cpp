#include "host/kernels/bayes_mix.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "bayes/mix.h"
#include "bayes/mix_spv.h"
#include "host/error.h"
#include "host/vk/context.h"
#include "host/vk/kernel.h"

namespace mcd {

std::array<float, 9> BayesOpponent() {
    const float a = 1 / std::sqrt(3.f), b = 1 / std::sqrt(2.f), c = 1 / std::sqrt(6.f);
    return {a, a, a, b, -b, 0, c, c, -2 * c};
}

std::array<float, 9> BayesOpponentInverse() {
    std::array<float, 9> m = BayesOpponent(), t;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) t[3 * i + j] = m[3 * j + i];
    return t;
}

void RecordBayesMix(vk::Context &context, vk::Recorder &recorder, vk::GpuImage &image,
                    const std::array<float, 9> &m) {
    if (image.channels != 3)
        throw Error(fmt::format("bayes mix: needs 3 channels, '{}' has {}", image.buffer.Name(),
                                image.channels),
                    ErrorKind::InvalidArgument);
    const vk::Kernel &kernel = context.GetKernel({"bayes_mix",
                                                  k_bayes_mix_spv,
                                                  sizeof(k_bayes_mix_spv),
                                                  BAYES_MIX_BINDINGS,
                                                  sizeof(shader::BayesMixPush),
                                                  {}});
    shader::BayesMixPush push{image.width, image.height, {}};
    std::copy(m.begin(), m.end(), push.m);
    recorder.Dispatch(kernel, "bayes.mix",
                      {{BAYES_MIX_IMAGE, &image.buffer, vk::Access::ReadWrite}}, push,
                      uint32_t((image.width + BAYES_MIX_LOCAL_SIZE - 1) / BAYES_MIX_LOCAL_SIZE),
                      uint32_t(image.height));
}

}  // namespace mcd
