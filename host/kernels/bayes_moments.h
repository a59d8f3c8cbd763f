// Record method bayes' per-band moments (shaders/bayes/moments.comp).
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

}  // namespace mcd
