// Method `bayes`: Bayesian wavelet shrinkage in the log domain (Xu & Pattanaik, section 4)
// on the GPU. log (eqs. 4-5) -> decimated DWT -> per-band E[y^2], E[y^4] -> (s_c, p_c) per
// band from eqs. 17-18 -> a per-band table of the posterior mean (eq. 11) -> every detail
// coefficient through its band's table -> synthesis -> exp, exact zeros restored.
// Colour: by default every channel is shrunk on its own, with its own bands and fits;
// `opponent` shrinks log luminance and two log chroma channels instead (3 channels).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "host/image.h"
#include "host/methods/run_setup.h"
#include "host/methods/staged_run.h"
#include "host/params/bayes.h"
#include "host/vk/context.h"
#include "host/vk/recorder.h"
#include "host/wavelet.h"

namespace mcd {

const char *BayesTransformName(BayesTransform transform);

struct BayesBandFit {
    int channel, level, orientation;
    std::array<float, 8> params;  // s_n, p_n, s_c, p_c, fit, y_max, b, du (bayes.h)
};

// warnings: counts of zeros, negatives, NaN/Inf, floored values. With setup.keepStages,
// stages in order: "log", "opponent" (--colour opponent), "analysis" (the Mallat layout, or
// the SWT's channels (3 levels + 1) planes), "moments" (1 channel, a row per band: E[y^2],
// E[y^4], max |y|, count), "fits" (a row per band: s_c, p_c, fit), "shrinkage",
// "synthesis", "opponent inverse", "exp"; with spins > 1 these are the unshifted run's,
// then "cycle spinning" (the average); "keep mean" and "local mean" last when on. A 1x1 image
// (no level) has "log" and "exp" only.
struct BayesResult : MethodResult {
    std::vector<BayesBandFit> fits;
    // The noise s used (estimated with --noise mad; the mean over bands with variance).
    float sn = 0;
    int levels = 0;
};

// Denoise one image (all channels). `variance`, the per-pixel variance of the mean (same
// shape as the image; not owned), is what --noise variance reads, and --noise auto when
// given. Throws mcd::Error on bad parameters, an empty image, --noise variance without
// `variance`, or --zeros restore where the zeros it would keep black are too dense to be
// black (a tenth of the values, half of them beside a lit value); NaN/Inf/negative pixels are
// not an error: they come out 0 and are counted in warnings. The keep-mean scaling is done on
// the host after download.
BayesResult BayesDenoise(vk::Context &context, const Image &color, const BayesParams &params,
                         const RunSetup &setup = {}, const Image *variance = nullptr);

// --zeros restore: throw mcd::Error (invalid argument, the message's first word "bayes"
// then `layer`) where the zeros it would keep black are too dense to be black, after the
// parameters' own checks. BayesDenoise calls it unless setup.zerosDecided; a tiled or probe
// run decides on its whole frame with it and its parts skip it.
void CheckBayesZeros(const Image &color, const BayesParams &params,
                     const std::string &layer = "");

// Negative values of the indirect layer down to this many float epsilons times direct's
// magnitude (8 to 16 units in the last place of direct) are the rounding of direct +
// indirect = color, not negative light.
constexpr int kSplitRoundingEpsilons = 8;

// The indirect layer bayes denoises: its negative values within kSplitRoundingEpsilons of
// direct (an indirect composed as color - direct, by accumulate or from Blender's light
// passes, where all the light is direct) set to 0 and counted in `rounded`.
Image SplitIndirect(const Image &direct, const Image &indirect, size_t *rounded);

// Section 4.1: denoise the indirect part only (SplitIndirect) and add the direct part back.
BayesResult BayesDenoiseSplit(vk::Context &context, const Image &direct, const Image &indirect,
                              const BayesParams &params, const RunSetup &setup = {},
                              const Image *variance = nullptr);

// The per-channel log floors (floorRel times the median finite positive value, 1 if none,
// at least 1e-30), and the s of a generalised Laplacian of shape p whose median absolute
// value is `mad`.
std::vector<float> BayesFloors(const Image &color, float floorRel);
double BayesScaleFromMad(double mad, double p);

const char *BayesFitName(int fit);

// --noise variance: the noise s of every band (band order of shaders/bayes/bayes.h) from the
// per-pixel variance of the mean of `color` (see the derivation in bayes.cpp). The squared-
// filter analysis runs on the GPU (its dispatch timings appended to `timings` when given),
// the rest on the host. Non-finite or negative variances
// count as 0; `opponent` gives every channel the mean over channels. `transform` picks the
// squared analysis and the bands (the stationary transform's: full-size planes).
std::vector<float> BayesVarianceNoise(vk::Context &context, const Image &color,
                                      const Image &variance, const std::vector<float> &floors,
                                      WaveletBasis basis, int levels, float pn, bool opponent,
                                      std::vector<vk::DispatchTiming> *timings = nullptr,
                                      BayesTransform transform = BayesTransform::Dwt,
                                      int swtGroupChannels = 0);

}  // namespace mcd
