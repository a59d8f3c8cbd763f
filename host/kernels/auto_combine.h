// Record the auto method's combination (shaders/auto/combine.comp): the candidates mixed
// per pixel by weights from their smoothed error estimates, or the best one selected.
#pragma once

#include "host/vk/gpu_image.h"
#include "host/vk/recorder.h"

namespace mcd {

// WeightsMedian: weights, and the candidates' median where every estimate is under the
// floor (shaders/auto/combine.h).
enum class AutoMode { Weights, Select, WeightsMedian };

// `candidates`: K x C planes (candidate k's channel c is plane k C + c), `errors`: K
// planes, `color` and `output`: C planes, `weights`: K planes; K in 1..8. Weights mode
// takes max(e, floorError)^-power (floorError > 0, power > 0).
void RecordAutoCombine(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &color,
                       const vk::GpuImage &candidates, const vk::GpuImage &errors,
                       AutoMode mode, float power, float floorError, vk::GpuImage &output,
                       vk::GpuImage &weights);

}  // namespace mcd
