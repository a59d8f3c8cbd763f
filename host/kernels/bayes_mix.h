// Record method bayes' colour mix (shaders/bayes/mix.comp).
#pragma once

#include <array>

#include "host/vk/gpu_image.h"
#include "host/vk/recorder.h"

namespace mcd {

// In place on a 3-channel image: every pixel's channels times the row-major matrix `m`.
void RecordBayesMix(vk::Context &context, vk::Recorder &recorder, vk::GpuImage &image,
                    const std::array<float, 9> &m);

// The orthonormal opponent matrix of shaders/bayes/mix.h and its inverse (transpose).
std::array<float, 9> BayesOpponent();
std::array<float, 9> BayesOpponentInverse();

}  // namespace mcd
