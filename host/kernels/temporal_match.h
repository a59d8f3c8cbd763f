// Record the temporal mode's match (shaders/temporal/match.comp): where each pixel of the
// current frame lands in a neighbour, whether the neighbour's sample there is accepted
// (features, motion consistency, a finite colour) and with what weight, and the positions
// one frame further along the chain of motion vectors.
#pragma once

#include "host/vk/gpu_image.h"
#include "host/vk/recorder.h"

namespace mcd {

struct TemporalMatchTest {
    int features = 0;  // TEMPORAL_HAS_* of the features both frames have
    float normalCos = 0.9f, depthRel = 0.1f, albedoRel = 0.1f;
    float motionTol = 1.f;  // pixels; <= 0: no forward-backward check
};

// One frame's images as the match reads them.
struct TemporalMatchFrame {
    const vk::GpuImage *features = nullptr;  // TEMPORAL_FEATURE_PLANES planes
    const vk::GpuImage *color = nullptr;     // 1 to 4 channels
    const vk::GpuImage *spp = nullptr;       // 1 channel, or null: weight 1
    const vk::GpuImage *motion = nullptr;    // 4 channels, or null: positions stay
};

// self: `neighbour` is the current frame itself (positions are its pixel centres; only its
// colour is tested). first: the neighbour is the current frame's, so `previous` is not read
// (the chain starts at the current frame's centres). `previous` and `position` 2 planes
// (ignored where self says), `weight` 1 plane and `next` 2 planes are written. direction:
// -1 earlier frames, +1 later ones.
void RecordTemporalMatch(vk::Context &context, vk::Recorder &recorder,
                         const vk::GpuImage &currentFeatures,
                         const TemporalMatchFrame &neighbour, const vk::GpuImage &previous,
                         const vk::GpuImage &position, bool self, bool first, int direction,
                         const TemporalMatchTest &test, vk::GpuImage &weight,
                         vk::GpuImage &next);

}  // namespace mcd
