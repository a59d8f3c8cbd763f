// Record method bayes' shrinkage of the coefficients through its lookup table
// (shaders/bayes/shrink.comp).
#pragma once

#include "host/vk/gpu_image.h"
#include "host/vk/recorder.h"

namespace mcd {

// In place on `coef`, a `levels`-level Mallat decomposition.
void RecordBayesShrink(vk::Context &context, vk::Recorder &recorder, vk::GpuImage &coef,
                       int levels, const vk::Buffer &params, const vk::Buffer &table);

}  // namespace mcd
