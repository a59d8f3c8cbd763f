// AWR's adaptive sampler (Overbeck et al., section 4.1) driving the renderer's sample
// source. Start with 4 samples per pixel; then, in rounds, compute the priority of every
// scale coefficient of levels 0..5, P = var(S~) - mean over the three wavelets of W~^2
// (eq. 8), with var(S~) from the squared low-pass DWT (renormalised to lowSum) of the
// per-pixel variance of the mean under Mitchell's contrast (eqs. 5, 6, 9), and give the
// highest ones 64 x 2^k samples each, placed by importance sampling |phi_k| along each
// axis. The wavelet transforms run on the GPU; a round pops as many coefficients as fit
// an eighth of the remaining budget (the paper pops one at a time).
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "host/image.h"
#include "host/params/awr.h"
#include "host/vk/context.h"
#include "host/wavelet.h"
#include "tools/render/renderer.h"

namespace mcd::render {

// The transforms of a round (step 2): the luminance DWT (Mallat layout, for the details)
// and, for k = 1..levels, the squared low-pass analysis of the variance to level k (eq. 9;
// only the top-left LevelExtent(k) corner is read). The sampler runs them on the GPU;
// tests pass the scalar reference to run the same loop on the CPU.
using PriorityTransforms = std::function<void(
    const Image &luminance, const Image &variance, WaveletBasis basis, int levels, float lowSum,
    Image *details, std::vector<Image> *scaleVariances)>;

struct AdaptiveOptions {
    int width = 256, height = 256;
    int averageSpp = 16;       // the budget: averageSpp x width x height samples in all
    AwrSamplerParams sampler;  // the paper's parameters and their defaults
    uint64_t seed = 1;
    int threads = 0;  // tracing threads, 0: all cores; the frame is the same for any number
    PriorityTransforms transforms;                     // empty: on the GPU of the context
    std::function<void(uint64_t, uint64_t)> progress;  // (samples so far, budget)
};

struct AdaptiveResult {
    // color, variance (of the mean), spp (the sample density), min, max.
    std::vector<std::pair<std::string, Image>> layers;
    std::map<std::string, std::string> metadata;
    double seconds = 0;
    double traceSeconds = 0;     // tracing and accumulating samples
    double prioritySeconds = 0;  // the sampler's own work: transforms, priorities, sorting
    int rounds = 0;
    uint64_t samples = 0;
    // Where the adaptive samples came from: per pixel, the mean level k of the scale
    // coefficients whose 64 x 2^k samples landed there (-1 where none did), and the number
    // of samples placed from each level. The initial uniform samples count in neither.
    Image placementLevel;
    std::vector<uint64_t> samplesPerLevel;
};

AdaptiveResult RenderAdaptive(vk::Context &context, const Scene &scene,
                              const AdaptiveOptions &options);

// The sampler itself, on any integrand: `trace` returns the RGB value of the sample at
// image position (x, y) in pixels, with `key` naming the sample (for its random numbers).
// RenderAdaptive is this with the scene's sample source; tests drive it with functions
// whose edges and noise they know. Leaves `metadata` to the caller.
using TraceFunction = std::function<Vec3(double x, double y, uint64_t key)>;
AdaptiveResult SampleAdaptive(vk::Context &context, const TraceFunction &trace,
                              const AdaptiveOptions &options);

// |phi_k| of a level-k scale function of `basis` along one axis, from the synthesis low-pass
// cascade; profile[i] covers pixel offset origin + i from 2^k times the coefficient index.
struct ScaleProfile {
    int origin = 0;
    std::vector<double> cdf;  // normalised cumulative |phi_k|, cdf.back() == 1
};
ScaleProfile ScaleFunctionProfile(WaveletBasis basis, int level);

}  // namespace mcd::render
