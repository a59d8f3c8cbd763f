// Sequences without flicker (docs/sequences.md): a frame of a sequence gathered with its
// neighbours before a method denoises it. Each neighbour's pixels are found through the
// renderer's motion vectors (the `motion` layer: Blender Cycles' Vector pass), or in place
// for a still camera, rejected where the features (normal, depth, albedo, object id)
// disagree or the vectors are inconsistent, and the accepted samples folded into the frame's
// statistics, as `accumulate` folds independent renders: the result is a frame with more
// samples, a variance layer and half-buffers, which any method (auto included) denoises.
//
//     mcd::Temporal temporal;                          // radius 3: frames t-3 .. t+3
//     std::map<int, const mcd::Frame *> window = {{-1, &previous}, {0, &frame}, {1, &next}};
//     mcd::TemporalResult gathered = temporal.Gather(device, window);
//     mcd::Result result = method.Run(device, gathered.frame);
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "mcdenoise/mcdenoise.h"

namespace mcd {

struct TemporalResult {
    // The gathered frame: the current frame's layers, with color, variance, spp,
    // half0.color, half1.color (and min, max, hist, direct, indirect and their variances
    // where it has them) gathered; the sample statistics it cannot gather (partial images,
    // zhist, remainder, color.unfiltered) left out. Its layers are its own (no view).
    Frame frame;
    Image frames;                         // per pixel, the frames whose sample was accepted
    std::vector<int> offsets;             // the neighbours gathered, in order
    std::vector<double> acceptedPercent;  // of each one's pixels, accepted
    std::vector<std::string> plan, warnings;
    std::vector<Timing> timings;
    double wallMs = 0;
};

// The temporal mode's parameters (typed, checked, as Method's) and the gather.
class Temporal {
  public:
    Temporal();
    ~Temporal();
    Temporal(const Temporal &other);
    Temporal &operator=(const Temporal &other);
    Temporal(Temporal &&) noexcept;
    Temporal &operator=(Temporal &&) noexcept;

    // "temporal-radius", "temporal-normal", "temporal-depth", "temporal-albedo",
    // "temporal-motion", "temporal-variance", "temporal-fill".
    const std::vector<ParamInfo> &Params() const;
    void Set(const std::string &name, ParamValue value);
    void SetText(const std::string &name, const std::string &text);
    ParamValue Get(const std::string &name) const;
    bool HasParam(const std::string &name) const;

    // Frames gathered before and after the current one.
    int Radius() const;
    // The layers the gather reads of each frame (for ReadOptions::layers, beside the
    // method's): color, variance, spp, motion, the features, and those it gathers.
    std::vector<std::string> Uses() const;

    // Gather window[0] (required) with the frames at the other offsets (frame number
    // minus the current one's; those beyond the radius are not read; each side up to its
    // first missing offset). Every frame of one size. Throws mcd::Error.
    TemporalResult Gather(Device &device, const std::map<int, const Frame *> &window) const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl;
};

}  // namespace mcd
