// Method `auto`'s combination on the GPU (issue #17): given the outputs of the candidate
// methods on a frame, and of each one's second run (on a perturbed color for SURE, on
// half0 for the half-buffers), each candidate's per-pixel relative error is estimated
// without the reference (auto_estimate), averaged over a window (auto_smooth), and the
// candidates are combined per pixel by those estimates (auto_combine). And the variance
// of the pixel mean estimated from the frame itself, for frames without statistics
// (auto_noise). CPU reference: cpu_reference/auto_combine.cpp. Which candidates run, and
// how, is the front end's (host/api/method_auto.cpp).
#pragma once

#include <string>
#include <vector>

#include "host/image.h"
#include "host/methods/staged_run.h"
#include "host/vk/context.h"

namespace mcd {

struct AutoHalvesSums;  // host/methods/auto_halves.h

// Candidates one combination takes at most (AUTO_MAX_CANDIDATES), and the noise
// estimate's largest window radius (AUTO_NOISE_MAX_RADIUS).
constexpr int kAutoMaxCandidates = 11;
constexpr int kAutoNoiseMaxRadius = 8;

// The variance of the pixel mean of `color` (1 to 4 channels) from the frame itself: the
// local mean over (2 radius + 1)^2 windows of the smallest squared second difference over 4
// directions of the colour, divided by `albedo` when given (color's size, 1 channel or at
// least color's). The result's image is that variance (color's shape).
MethodResult AutoNoise(vk::Context &context, const Image &color, const Image *albedo,
                       int radius);
// Makes AutoNoise's kernel ahead (Context::PrepareKernel).
void PrepareAutoNoiseKernels(vk::Context &context);

// One candidate: a method's output on the frame and what its error estimate reads.
struct AutoCandidate {
    std::string label;   // names its stages ("auto.<label>")
    std::string method;  // the method it is a variant of (the mean's shares)
    Image output;        // F(y): what is combined
    // With an estimate: F on the perturbed color y + epsilon sqrt(v) b (SURE), or F(half0)
    // (the half-buffers: what is scored against half1).
    Image probe;
    float epsilon = 1;   // the perturbation's step (the half-buffers: unused)
    bool split = false;  // scored with AutoEstimateInputs::offset (bayes's split output)
    float colour[3] = {0, 0, 0};  // its colour in the map of the largest weights
};

// What the error estimates read. Empty `variance`: no estimate (AutoCombination::Mean).
struct AutoEstimateInputs {
    // SURE: the variance of the pixel mean and the probe b (+-1 per value). The
    // half-buffers: (h0 - h1)^2 / 2, the variance of half1, and a zero probe.
    Image variance, probe;
    Image half1;   // the half-buffers: what F(half0) is compared with; empty: SURE
    Image offset;  // bayes's split output: 2 (v - Cov(I, y)) per value; empty: none
    // The relative combination: the variance of the pixel mean.
    Image meanVariance;
    // The object guard's factors on the final estimates, one plane per candidate
    // (AutoObjectGuardFactors, host/methods/auto_object_floor.h); empty: none.
    Image objectFactors;
};

enum class AutoCombination {
    Relative,  // the value of least expected relative squared error under the weights
    Weights,   // the weighted mean; the candidates' median where no estimate tells
    Select,    // the candidate of the smallest estimate
    Mean,      // no estimate: each method the same weight, shared by its variants
};

struct AutoOptions {
    AutoCombination combination = AutoCombination::Relative;
    // relMSE's denominator in the estimates: the candidates' mean, or (false) a first
    // combination weighed by their plain squared error.
    bool meanGuide = false;
    int radius = 12;  // the estimates' window mean is (2 radius + 1)^2
    // The final estimates' windows weighed by the guide's colour too, exp(-distance /
    // bandwidth^2) (0: tents alone).
    float windowBandwidth = 0;
    float power = 2, floorError = 1e-5f;
    float noiseLimit = 30, darkLimit = 4;  // the relative combination's
    float noiseCap = 100;                  // the final estimates' (0: none)
    // Beside the half-buffers, the final estimates' adjustment (host/methods/auto_halves.h):
    // each raised to half1's variance, at most halvesFloor x the candidates' median, and a
    // candidate above halvesDrop x the median over the frame left out (0: off).
    float halvesFloor = 0, halvesDrop = 0;
    // The floor of each times (its estimate over the frame / the smallest) ^ this (0: off).
    float halvesRank = 0;
    // Beside the half-buffers, a method's variants share one candidate's weight (each
    // estimate times its method's candidates left in ^ (1 / power)); false: each weighs alone.
    bool halvesVariants = false;
    // Beside the half-buffers, the guard of the local means (host/methods/auto_halves.h):
    // a candidate whose mean over tents of meanGuardRadius departs from the colour's by
    // over meanGuard standard errors of it weighs less there (0: off). The standard errors
    // read the variance of the pixel mean times meanGuardVarianceScale (2 for a combination
    // of the half0 runs, whose colour holds half the samples).
    float meanGuard = 0;
    int meanGuardRadius = 2;
    float meanGuardVarianceScale = 1;
    // Set by AutoCombine for a combination in strips: the candidates left out over the whole
    // frame (empty: the window decides), its estimates and noise, and the sums its first pass
    // over the strips adds each strip's estimates to (null: none).
    std::vector<bool> halvesDropped;
    std::vector<double> halvesFrameEstimates;  // the whole frame's, for the rank
    double halvesFrameNoise = 0;
    AutoHalvesSums *halvesSums = nullptr;
    bool keepStages = false;
    bool map = false;          // return stage "auto.map" even without keepStages
    bool keepWeights = false;  // return the weights in AutoResult::weights
    // Rows per strip of the combination (0: the whole frame, or strips where it does not
    // fit the device; tests force strips).
    int stripRows = 0;
};

// Each candidate's share (its mean weight, in %) and where its weight is the largest (in %
// of the pixels), in the candidates' order. With keepStages, stages "auto.<label>.probe" (with
// an estimate), "auto.<label>", "auto.guide", "auto.estimates" and "auto.errors" (with an
// estimate: the guide, the second pass's raw estimates and their window means, one plane per
// candidate), "auto.weights"; with keepStages or `map`, "auto.map": each pixel the colour
// of the candidate of the largest weight (black where none weighs).
struct AutoResult : MethodResult {
    std::vector<double> sharePercent, wonPercent;
    Image weights;  // with keepWeights: each candidate's weight per pixel, one plane each
};

// Combine `candidates` (1 to kAutoMaxCandidates, each output of color's shape, 1 to 4
// channels) per pixel. Throws mcd::Error on bad shapes or options.
AutoResult AutoCombine(vk::Context &context, const Image &color,
                       const std::vector<AutoCandidate> &candidates,
                       const AutoEstimateInputs &estimate, const AutoOptions &options);

}  // namespace mcd
