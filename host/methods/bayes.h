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
#include "host/methods/staged_run.h"
#include "host/vk/context.h"
#include "host/vk/recorder.h"
#include "host/wavelet.h"

namespace mcd {

// The wavelet transform the shrinkage runs in: the foundation's decimated DWT (Mallat
// layout), or the stationary (undecimated, "a trous") transform of host/wavelet/swt.h:
// shift-invariant, 3 levels + 1 full-size planes per channel.
enum class BayesTransform { Dwt, Swt };

const char *BayesTransformName(BayesTransform transform);

struct BayesOptions {
    WaveletBasis basis = WaveletBasis::Haar;
    // swt: measured better than the paper's DWT on every cornell/interior frame (README).
    BayesTransform transform = BayesTransform::Swt;
    // swt: at most this many channels' coefficients at a time (0: as many as one binding
    // holds, vk::Context::BindingBytes); a smaller group needs less memory, same result.
    int swtGroupChannels = 0;
    int levels = 3;          // clamped to what the image allows
    float sn = 0.19f;        // noise s (the paper's "cabin" example)
    float pn = 1.5f;         // noise shape p
    float hpFactor = 2.f;    // the finest level's noise s is hpFactor * sn (paper: 2)
    float floorRel = 1e-3f;  // log floor: floorRel times the channel's median positive value
    // Estimate the finest level's noise s from the data (median absolute deviation of the
    // finest HH bands, all channels pooled, through the generalised Laplacian of shape pn);
    // then sn = that / hpFactor.
    bool noiseAuto = true;
    // --noise variance (beyond the paper; overrides noiseAuto): every band's noise s from
    // this per-pixel variance of the mean (same shape as the image), by
    // BayesVarianceNoise; hpFactor and sn are then unused. Not owned.
    const Image *variance = nullptr;
    // Exact zeros come out exactly 0 (the issue: black stays black). Off: they are denoised
    // like any pixel (from the log floor), which suits low-spp renders whose zeros are noise.
    bool restoreZeros = true;
    // Beyond the paper: scale each channel so its mean equals the input's (mean of the
    // finite, non-negative input values), undoing the log domain's pull toward the
    // geometric mean. Done on the host after download.
    bool keepMean = false;
    // Beyond the paper: restore the input's local means (0: off). Each output value is
    // multiplied by m_in / m_out, the means of the input's finite values >= 0 and of the
    // output over a tent window of radius 2 x meanRadius (a box of radius meanRadius twice,
    // each clipped to the image), where both are positive. The log domain estimates a
    // geometric mean, which lies below the mean by as much as the local noise is relative:
    // dark, noisy areas darkened most. Done on the host after download, after keepMean.
    int meanRadius = 8;
    // Shift invariance by cycle spinning (Coifman & Donoho): the average of the method
    // over the spins x spins shifts (dx, dy) in [0, spins)^2, each made by padding the
    // image at the top left by mirroring (x -> -x-1) and cropping back. 1: off.
    int spins = 1;
    // Shrink the orthonormal opponent transform of the log channels (log luminance, two
    // log chroma) instead of log R, G, B. Needs 3 channels.
    bool opponent = false;
    // Download every stage's buffer (for `mcdenoise diff`): one submission per stage.
    bool keepStages = false;
};

struct BayesBandFit {
    int channel, level, orientation;
    std::array<float, 8> params;  // s_n, p_n, s_c, p_c, fit, y_max, b, du (bayes.h)
};

// warnings: counts of zeros, negatives, NaN/Inf, floored values. With keepStages, stages in
// order: "log", "opponent" (--colour opponent), "analysis" (the Mallat layout, or the SWT's
// channels (3 levels + 1) planes), "moments" (1 channel, a row per band: E[y^2], E[y^4],
// max |y|, count), "fits" (a row per band: s_c, p_c, fit), "shrinkage", "synthesis",
// "opponent inverse", "exp"; with spins > 1 these are the unshifted run's, then "cycle
// spinning" (the average); "keep mean" and "local mean" last when on. A 1x1 image (no level) has "log" and
// "exp" only.
struct BayesResult : MethodResult {
    std::vector<BayesBandFit> fits;
    // The noise s used (estimated with noiseAuto; the mean over bands with variance).
    float sn = 0;
    int levels = 0;
};

// Denoise one image (all channels). Throws mcd::Error on bad options or an empty image;
// NaN/Inf/negative pixels are not an error: they come out 0 and are counted in warnings.
BayesResult BayesDenoise(vk::Context &context, const Image &color, const BayesOptions &options);

// Section 4.1: denoise the indirect part only and add the direct part back.
BayesResult BayesDenoiseSplit(vk::Context &context, const Image &direct, const Image &indirect,
                              const BayesOptions &options);

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
