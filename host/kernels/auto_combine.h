// Record the auto method's combination (shaders/auto/combine.comp): the candidates mixed
// per pixel by weights from their smoothed error estimates, or the best one selected.
#pragma once

#include "host/vk/gpu_image.h"
#include "host/vk/recorder.h"

namespace mcd {

// WeightsMedian: weights, and the candidates' median where every estimate is under the
// floor; Relative: the value of least expected relative squared error under the weights,
// equal where the estimates tell nothing or the noise outweighs them
// (shaders/auto/combine.h).
enum class AutoMode { Weights, Select, WeightsMedian, Relative };

// `candidates`: K x C planes (candidate k's channel c is plane k C + c), `errors`: K
// planes, `color` and `output`: C planes, `weights`: K planes; K in 1..AUTO_MAX_CANDIDATES.
// Weights modes take max(e, floorError)^-power (floorError > 0, power > 0). Relative mode
// reads `variance` (C planes, the variance of the pixel mean) against noiseLimit (> 0),
// and darkLimit (> 0); the other modes read none of them.
void RecordAutoCombine(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &color,
                       const vk::GpuImage &candidates, const vk::GpuImage &errors,
                       AutoMode mode, float power, float floorError, vk::GpuImage &output,
                       vk::GpuImage &weights, const vk::GpuImage *variance = nullptr,
                       float noiseLimit = 0, float darkLimit = 0);

}  // namespace mcd
