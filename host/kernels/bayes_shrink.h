// Record method bayes' lookup table (shaders/bayes/table.comp) and its application to
// the coefficients (shaders/bayes/shrink.comp).
#pragma once

#include "host/vk/gpu_image.h"
#include "host/vk/recorder.h"

namespace mcd {

// table[band][i] = posterior mean at the band's node i (shaders/bayes/bayes.h).
void RecordBayesTable(vk::Context &context, vk::Recorder &recorder, const vk::Buffer &params,
                      int bands, vk::Buffer &table);

// In place on `coef`, a `levels`-level Mallat decomposition.
void RecordBayesShrink(vk::Context &context, vk::Recorder &recorder, vk::GpuImage &coef,
                       int levels, const vk::Buffer &params, const vk::Buffer &table);

}  // namespace mcd
