// Record the temporal mode's finish (shaders/temporal/finish.comp): a gathered layer's mean
// and the variance of its mean, and with halves the half-buffers, from the folded state.
#pragma once

#include "host/vk/gpu_image.h"
#include "host/vk/recorder.h"

namespace mcd {

// The folded state a layer is finished from. `moments` 2 C planes (mean, then the
// weighted squared deviations), `counts` 2 planes (weights, accepted frames), `raw` the
// current frame's own layer (C); `pooled` (C: the sum of w^2 v) or null: the spread's
// variance; halves (all four, or none): `sum0`/`sum1` C planes, `counts0`/`counts1` 2.
struct TemporalFinishInputs {
    const vk::GpuImage *moments = nullptr, *counts = nullptr, *raw = nullptr;
    const vk::GpuImage *pooled = nullptr;
    const vk::GpuImage *sum0 = nullptr, *counts0 = nullptr, *sum1 = nullptr, *counts1 = nullptr;
};

// `output`: C planes each of the mean, the variance, and with halves half0 and half1 (2 C
// or 4 C planes). fillRadius 0..TEMPORAL_FINISH_MAX_RADIUS.
void RecordTemporalFinish(vk::Context &context, vk::Recorder &recorder,
                          const TemporalFinishInputs &in, int fillRadius, vk::GpuImage &output);

}  // namespace mcd
