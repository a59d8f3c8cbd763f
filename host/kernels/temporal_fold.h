// Record the temporal mode's fold (shaders/temporal/fold.comp): one frame's layer folded
// into the running state of the gathered frame, at the positions its samples were matched
// at, with their weights.
#pragma once

#include "host/vk/gpu_image.h"
#include "host/vk/recorder.h"

namespace mcd {

enum class TemporalFoldMode { Moments, Sum, Min, Max, Count };

struct TemporalFoldStep {
    TemporalFoldMode mode = TemporalFoldMode::Moments;
    int power = 1;         // Sum: the weight's power, 0, 1 or 2
    bool first = false;    // the state starts here
    bool centres = false;  // the value is read at the pixel itself (the current frame)
};

// `value` C channels (not read by Count: pass any image of the frame's size), `position` 2
// planes, `weight` 1 plane, `total` Count's state (2 planes, its plane 0 read by Moments;
// any image of that shape otherwise), `state` C planes (Sum, Min, Max), 2 C (Moments) or 2
// with C = 1 (Count).
void RecordTemporalFold(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &value,
                        const vk::GpuImage &position, const vk::GpuImage &weight,
                        const vk::GpuImage &total, const TemporalFoldStep &step,
                        vk::GpuImage &state);

}  // namespace mcd
