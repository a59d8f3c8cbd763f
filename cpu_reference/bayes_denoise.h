// Method `bayes` (Xu & Pattanaik section 4), the CPU reference of the pipeline, stage by
// stage: log domain (eqs. 4-5), decimated DWT (the wavelet references), per-band moments,
// the moment solver and the posterior mean of every coefficient by direct integration
// (cpu_reference/bayes_model.h), synthesis, exp with exact zeros restored.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "cpu_reference/bayes_model.h"
#include "host/image.h"
#include "host/params/bayes.h"
#include "host/wavelet.h"

namespace mcd::ref {

// Per channel: floorRel times the median of the channel's finite positive values (element
// n/2 of them sorted; 1 when there are none), at least 1e-30, rounded to float. The median, not
// the mean: one 1e8 firefly must not raise the floor of the whole channel. Values below it
// (zeros, negatives, tiny) take its log.
std::vector<double> BayesFloors(const Image &color, double floorRel);

// log(max(v, floor_c)); NaN, Inf and values <= floor_c take log(floor_c), but with fillMissed
// (--zeros restore), in a dark pixel
// (no channel finite and above its floor) not inside dark (no opposite pair of 3x3 neighbour
// pixels both dark; coordinates clamped to the frame), a sample that missed the light, the
// values in [0, floor_c] take the mean of log(max(v, floor_c)) over the in-frame 3x3
// neighbour pixels that are not dark (log(floor_c) when none is).
Image BayesLog(const Image &color, const std::vector<double> &floors, bool fillMissed);

// exp(z), or exactly 0 where the original value was NaN/Inf/negative, and, when
// restoreZeros, where it was 0 inside black: an opposite pair of its 3x3 neighbour pixels
// (clamped to the frame) both without a finite positive channel (black stays black; a lone
// zero among lit pixels is a sample that missed the light and takes exp(z)).
// z is clamped to [-87, 88].
Image BayesExp(const Image &logImage, const Image &original, bool restoreZeros = true);

// One detail band of the Mallat layout: [x0, x1) x [y0, y1) of channel `channel`.
struct BayesBand {
    int channel, level, orientation;  // orientation 0 HL, 1 LH, 2 HH
    int x0, y0, x1, y1;
};
// All detail bands in the order of shaders/bayes/bayes.h.
std::vector<BayesBand> BayesBands(int width, int height, int channels, int levels);
// The same bands of the stationary wavelet transform (cpu_reference/wavelet_swt.h): full
// size, `channel` is the band's plane of the coefficient image (band b of channel c is plane
// b + c), and a band whose axis is not transformed at its level is empty (x0 = x1).
std::vector<BayesBand> BayesSwtBands(int width, int height, int channels, int levels);

struct BandMoments {
    double m2 = 0, m4 = 0, maxAbs = 0;
    int64_t count = 0;
};
BandMoments MeasureBand(const Image &coefficients, const BayesBand &band);

// The noise s of a band: hpFactor * sn at the finest level (the paper's high-pass band
// uses 2 s_n), sn elsewhere.
double BandNoiseS(int level, double sn, double hpFactor);

// Every detail coefficient replaced by its posterior mean (direct integral per
// coefficient); the coarsest low-low band is kept.
Image BayesShrinkDirect(const Image &coefficients, const std::vector<BayesBand> &bands,
                        const std::vector<BandFit> &fits, const std::vector<double> &bandSn,
                        double pn);

// --noise variance: the noise s of every band (order of BayesBands) from the per-pixel
// variance V of the mean of `color`: per pixel sigma^2 = log(1 + V / max(Y, floor)^2)
// (the delta method's V / Y^2 to first order, exact for log-normal Y; NaN/negative V is 0,
// +Inf V is FLT_MAX, NaN/Inf Y is the floor), through the DWT with squared taps
// (var(sum h_i z_i) = sum h_i^2 var(z_i) for independent pixels; WaveletSqAnalyze at
// natural sums), the mean over the band, and s = sigma sqrt(Gamma(1/p) / Gamma(3/p)) for
// a generalised Laplacian of shape p. `opponent`: the mean over channels for every channel.
// `swt`: through the stationary transform's squared analysis and its bands instead.
std::vector<double> BayesVarianceNoise(const Image &color, const Image &variance,
                                       const std::vector<double> &floors, WaveletBasis basis,
                                       int levels, double pn, bool opponent, bool swt = false);

// What a reference run is given besides the method's parameters (host/params/bayes.h,
// taken as doubles; transform Swt runs the stationary transform, Dwt the decimated one).
struct BayesRefRun {
    // The per-pixel variance of the mean (not owned): with --noise variance, and auto when
    // given, every band's noise s is BayesVarianceNoise of it (sn and hpFactor unused).
    const Image *variance = nullptr;
    // --noise mad, and auto without a variance: the s_n the GPU run estimated (the estimate
    // is host code on the GPU's coefficients, a median, not a kernel), so that the stages
    // after it compare the same model. Required then.
    double madSn = -1;
    // Keep every stage, named and laid out as host/methods/bayes.h's BayesResult::stages.
    bool keepStages = false;
};
struct BayesRefResult {
    Image image;
    std::vector<BandMoments> moments;
    std::vector<BandFit> fits;
    std::vector<std::pair<std::string, Image>> stages;
};
// The whole method on one image (no direct/indirect split); levels are clamped to what
// the image allows. With spins > 1 the result is the mean over the shifts and the
// moments/fits/stages are the unshifted run's (then "cycle spinning", the mean).
BayesRefResult BayesDenoise(const Image &color, const BayesParams &params,
                            const BayesRefRun &run = {});

}  // namespace mcd::ref
