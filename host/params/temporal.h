// The temporal mode's parameters (a frame of a sequence gathered with its neighbours:
// docs/sequences.md), as the GPU pipeline (host/methods/temporal.h), the API
// (host/api/temporal.cpp) and the CPU reference (cpu_reference/temporal.h) read them: a
// layout, like a kernel's push-constant header. The initializers are the defaults the
// command line shows.
#pragma once

namespace mcd {

// Where the gathered frame's variance comes from: the frames' own variance layers when
// every frame has one (Auto), else, or always (Spread), the spread of the frames' values.
enum class TemporalVariance { Auto, Spread };

struct TemporalParams {
    int radius = 3;  // frames gathered before and after the current one
    // Disocclusion: a neighbour's sample is rejected where its features disagree with the
    // current frame's (those both frames have).
    float normalAngle = 25.f;       // degrees between the normals
    float depthTolerance = 0.1f;    // relative difference of the depths
    float albedoTolerance = 0.15f;  // relative difference of the albedos, per channel
    // Forward-backward consistency of the motion vectors, in pixels (0: not checked).
    float motionTolerance = 1.f;
    TemporalVariance variance = TemporalVariance::Auto;
    // The spread's variance where only one frame was accepted: pooled over this radius.
    int fillRadius = 2;
};

}  // namespace mcd
