// The temporal mode (docs/sequences.md), the CPU reference: a frame of a sequence gathered
// with its neighbours. Plain loops in double, written from the definitions in
// shaders/temporal/*.h, sharing no code with the GPU path. Positions are float32 numbers by
// the layout's definition (a pixel centre plus motion vectors, rounded as the GPU does),
// so that the pixel they fall in is the GPU's; every other quantity is computed in double.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "host/image.h"
#include "host/params/temporal.h"

namespace mcd::ref {

// The features compared (bits: 1 normal, 2 depth, 4 albedo, 8 object id) and the
// tolerances, as shaders/temporal/match.h states them.
struct TemporalTest {
    int features = 0;
    double normalCos = 0.9, depthRel = 0.1, albedoRel = 0.1;
    double motionTol = 1;  // pixels; <= 0: no forward-backward check
};

// Stage 1 (shaders/temporal/match.h): per pixel of the current frame, the weight of the
// neighbour's sample (0: not accepted) and the position one frame further along the chain.
// Features are packed in 8 planes: normal (3), depth, albedo (3), object id.
struct TemporalMatched {
    Image weight;  // 1 plane
    Image next;    // 2 planes
};
TemporalMatched TemporalMatch(const Image &currentFeatures, const Image &features,
                              const Image &color, const Image *spp, const Image *motion,
                              const Image &previous, const Image &position, bool self,
                              bool first, int direction, const TemporalTest &test);

// Stage 2 (shaders/temporal/fold.h): fold one frame's layer into `state` (A planes, then
// B planes for Moments and Count), in place.
enum class TemporalFoldMode { Moments, Sum, Min, Max, Count };
void TemporalFold(const Image &value, const Image &position, const Image &weight,
                  const Image &total, TemporalFoldMode mode, int power, bool first,
                  bool centres, Image &state);

// Stage 3 (shaders/temporal/finish.h): mean, variance and, with the four half inputs, the
// half-buffers, as 2 or 4 groups of C planes.
Image TemporalFinish(const Image &moments, const Image &counts, const Image *pooled,
                     const Image &raw, const Image *sum0, const Image *counts0,
                     const Image *sum1, const Image *counts1, int fillRadius);

// One frame of the window for the whole gather (null: absent).
struct TemporalFrame {
    int offset = 0;
    const Image *color = nullptr, *variance = nullptr, *spp = nullptr, *motion = nullptr;
    Image features;  // 8 planes as above
    int mask = 0;    // the features present
    std::map<std::string, const Image *>
        layers;  // min, max, hist, direct, indirect (+ .variance)
};

struct TemporalGatheredRef {
    // color, variance, half0.color, half1.color, spp (with weights from spp), frames (the
    // accepted count), and min, max, hist, direct (+ .variance), indirect (+ .variance) as
    // the current frame has them.
    std::map<std::string, Image> layers;
};

// The whole gather, pixel by pixel: each side's chain walked frame by frame (the frames
// whose offsets are -1, -2, ... and 1, 2, ... up to the radius, nearest first, each side up
// to its first absent frame), each sample accepted as stage 1 says, and the accepted
// samples' statistics computed in two passes (the weighted mean, then the squared
// deviations from it). `withSpp`, `withMotion`, `pooled` (and `layerPooled` for direct and
// indirect) say which of the frames' layers are used, as the pipeline decides them.
TemporalGatheredRef TemporalGather(const std::vector<TemporalFrame> &frames,
                                   const TemporalParams &params, bool withSpp, bool withMotion,
                                   bool pooled, const std::map<std::string, bool> &layerPooled);

}  // namespace mcd::ref
