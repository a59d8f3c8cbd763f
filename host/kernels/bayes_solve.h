// Record method bayes' moment solver (shaders/bayes/solve.comp): each band's signal
// model from its moments and noise.
#pragma once

#include "host/vk/gpu_image.h"
#include "host/vk/recorder.h"

namespace mcd {

// params[band] from moments[band]: noise s noise[band] (one float per band), shape `pn`.
void RecordBayesSolve(vk::Context &context, vk::Recorder &recorder, const vk::Buffer &moments,
                      int bands, int levels, const vk::Buffer &noise, float pn,
                      vk::Buffer &params);

}  // namespace mcd
