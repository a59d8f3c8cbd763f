// Record method bayes' per-band moments (shaders/bayes/moments.comp) and the moment
// solver (shaders/bayes/solve.comp).
#pragma once

#include "host/vk/gpu_image.h"
#include "host/vk/recorder.h"

namespace mcd {

// Detail bands of a `levels`-level decomposition of a C-channel image: 3 levels C.
inline int BayesBandCount(int channels, int levels) {
    return 3 * levels * channels;
}

// moments[band] = E[y^2], E[y^4], max |y|, count (layout in shaders/bayes/bayes.h).
void RecordBayesMoments(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &coef,
                        int levels, vk::Buffer &moments);

// params[band] from moments[band]: noise s noise[band] (one float per band), shape `pn`.
void RecordBayesSolve(vk::Context &context, vk::Recorder &recorder, const vk::Buffer &moments,
                      int bands, int levels, const vk::Buffer &noise, float pn,
                      vk::Buffer &params);

}  // namespace mcd
