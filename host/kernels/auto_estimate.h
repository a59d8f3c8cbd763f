// Record the auto method's error estimate (shaders/auto/estimate.comp): per-pixel SURE of
// a candidate's relative squared error, with a Monte Carlo divergence from one perturbed
// run.
#pragma once

#include "host/vk/gpu_image.h"
#include "host/vk/recorder.h"

namespace mcd {

// `color` (the noisy input y), `variance` (of the mean), `probe` (b, +-1), `guide` (g, for
// relMSE's denominator), `output` (f on y), `perturbed` (f on y + epsilon sqrt(variance)
// b), `offset` (o, added to each value's term: 0 but for bayes's split output): same size,
// 1 to 4 channels; `error` one plane of that size. The denominator is max(guide^2 + 0.01,
// variance / noiseCap) (guide^2 + 0.01 when noiseCap is 0).
void RecordAutoEstimate(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &color,
                        const vk::GpuImage &variance, const vk::GpuImage &probe,
                        const vk::GpuImage &guide, const vk::GpuImage &output,
                        const vk::GpuImage &perturbed, const vk::GpuImage &offset,
                        float epsilon, float noiseCap, vk::GpuImage &error);

// Throw unless the images have the width and height of `a` and `channels` channels.
void CheckAutoShapes(const char *what, const vk::GpuImage &a, int channels,
                     std::initializer_list<const vk::GpuImage *> others);

}  // namespace mcd
