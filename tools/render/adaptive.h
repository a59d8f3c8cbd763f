// AWR's adaptive sampler (Overbeck et al., section 4.1) driving the renderer's sample
// source. Start with 4 samples per pixel; then, in rounds, compute the priority of every
// scale coefficient of levels 0..5, P = var(S~) - mean over the three wavelets of W~^2
// (eq. 8), with var(S~) from the squared low-pass DWT (renormalised to 1.05) of the
// per-pixel variance of the mean under Mitchell's contrast (eqs. 5, 6, 9), and give the
// highest ones 64 x 2^k samples each, placed by importance sampling |phi_k| along each
// axis. The wavelet transforms run on the GPU; a round pops as many coefficients as fit
// an eighth of the remaining budget (the paper pops one at a time).
#pragma once

#include <cstdint>

#include "host/vk/context.h"
#include "host/wavelet.h"
#include "tools/render/renderer.h"

namespace mcd::render {

struct AdaptiveOptions {
    int width = 256, height = 256;
    int averageSpp = 16;  // the budget: averageSpp x width x height samples in all
    int initialSpp = 4;
    int maxLevel = 5;
    WaveletBasis basis = WaveletBasis::Cdf97;
    float lowSum = 1.05f;  // squared low-pass renormalisation (the paper's 1.05)
    uint64_t seed = 1;
    std::function<void(uint64_t, uint64_t)> progress;  // (samples so far, budget)
};

struct AdaptiveResult {
    // color, variance (of the mean), spp (the sample density), min, max.
    std::vector<std::pair<std::string, Image>> layers;
    std::map<std::string, std::string> metadata;
    double seconds = 0;
    int rounds = 0;
    uint64_t samples = 0;
};

AdaptiveResult RenderAdaptive(vk::Context &context, const Scene &scene,
                              const AdaptiveOptions &options);

// |phi_k| of a level-k scale function of `basis` along one axis, from the synthesis low-pass
// cascade; profile[i] covers pixel offset origin + i from 2^k times the coefficient index.
struct ScaleProfile {
    int origin = 0;
    std::vector<double> cdf;  // normalised cumulative |phi_k|, cdf.back() == 1
};
ScaleProfile ScaleFunctionProfile(WaveletBasis basis, int level);

}  // namespace mcd::render
