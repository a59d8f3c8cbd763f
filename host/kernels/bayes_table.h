// Record method bayes' lookup table (shaders/bayes/table.comp): the posterior mean at
// each band's nodes.
#pragma once

#include "host/vk/gpu_image.h"
#include "host/vk/recorder.h"

namespace mcd {

// table[band][i] = posterior mean at the band's node i (shaders/bayes/bayes.h).
void RecordBayesTable(vk::Context &context, vk::Recorder &recorder, const vk::Buffer &params,
                      int bands, vk::Buffer &table);

}  // namespace mcd
