// The temporal mode on the GPU (docs/sequences.md): a frame of a sequence gathered with its
// neighbours into one frame with more samples and with statistics, which any method then
// denoises. Each neighbour's pixels are found through the chain of motion vectors (or in
// place, without them), rejected where the features disagree (disocclusion) or the
// vectors are inconsistent, and the accepted samples folded into the current frame's
// statistics, as `accumulate` folds independent renders: the weighted mean, the variance
// of the mean (from the frames' own variances, or from their spread), the half-buffers
// (frames at even and at odd distances), spp, min, max, histograms, and the light split.
// Kernels: shaders/temporal/{match,fold,finish}.comp; CPU reference:
// cpu_reference/temporal.cpp.
#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "host/image.h"
#include "host/methods/run_setup.h"
#include "host/methods/staged_run.h"
#include "host/params/temporal.h"
#include "host/vk/context.h"

namespace mcd {

// One frame of the window as the gather reads it (null: the frame lacks the layer). All
// the frame's size.
struct TemporalFrameLayers {
    int offset = 0;                   // its number minus the current frame's
    const Image *color = nullptr;     // required, 1 to 4 channels
    const Image *variance = nullptr;  // of the pixel mean, as color
    const Image *spp = nullptr;       // 1 channel
    // 4 channels, Blender Cycles' Vector pass (shaders/temporal/temporal.h): the motion in
    // pixels towards the previous and the next frame.
    const Image *motion = nullptr;
    const Image *normal = nullptr, *depth = nullptr, *albedo = nullptr, *objectId = nullptr;
    // The other layers gathered (TemporalGathers names them), by name.
    std::map<std::string, const Image *> layers;
};

// Whether `layer` is gathered beside color (min, max: over the accepted samples; hist:
// summed; direct, indirect: weighted means, with their variances from direct.variance and
// indirect.variance as color's from variance), and not taken from the current frame.
bool TemporalGathers(const std::string &layer);

struct TemporalGathered : MethodResult {
    // The gathered frame: color (also `image`), variance, half0.color, half1.color, spp
    // (where every frame has one: the samples gathered), and each of the current frame's
    // layers that TemporalGathers names (direct and indirect with their variances).
    std::vector<std::pair<std::string, Image>> layers;
    Image frames;  // per pixel, the frames whose sample was accepted (the current one too)
    std::vector<int> offsets;             // the neighbours folded, in order
    std::vector<double> acceptedPercent;  // of each one's pixels, accepted
    bool pooled = false;  // the variances from the frames' own (else from the spread)
    bool motion = false;  // the positions followed motion vectors (else the camera is still)
};

// Gather frames[k] whose offset is 0 with those of offsets -radius..radius around it, each
// side's chain up to its first missing frame. Throws mcd::Error naming what is wrong.
TemporalGathered TemporalGather(vk::Context &context,
                                const std::vector<TemporalFrameLayers> &frames,
                                const TemporalParams &params, const RunSetup &setup = {});

}  // namespace mcd
