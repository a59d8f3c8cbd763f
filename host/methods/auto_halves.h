// Beside the half-buffers: the estimates of the candidates' errors made to weigh them as the
// windows can tell them apart (docs/methods/auto.md, "Accumulated frames: the estimates'
// noise and the halves' shared bias"). Each estimate (F(half0) - half1)^2 - Var(half1),
// averaged over a window, is unbiased but noisy, and biased low for a candidate that keeps
// a bias the two halves share (a frame of jittered 1-spp renders keeps some in both); one
// such estimate near zero takes all the weight of 1 / e^2.
#pragma once

#include <string>
#include <vector>

#include "host/image.h"

namespace mcd {

struct AutoHalvesSettings {
    // Each estimate is raised to at least half1's variance over the window (in relMSE's
    // units), at most this times the median of the candidates' estimates at the pixel: an
    // estimate below what the noise lets the window resolve weighs no more than that (0:
    // off).
    float floor = 0;
    // A candidate whose estimate over the whole window (the frame) is above this times the
    // median of the candidates' is left out (0: off).
    float drop = 0;
    float floorError = 1e-5f;  // the smallest estimate the median reads
    // Each candidate's floor times (its estimate over the frame / the smallest of those
    // left in) ^ this, so that where the noise hides the differences the weights follow the
    // frame's ranking instead of going equal (0: the same floor for all).
    float rank = 0;
    // Per candidate, the method it is a variant of; with `power` > 0 each estimate left in,
    // after the floor and read as max(e, floorError), is multiplied by (the number of that
    // method's candidates left in) ^ (1 / power), so that under weights 1 / e^power a
    // method's variants, whose errors go together, share one candidate's weight (empty: each
    // weighs alone). Not where every estimate left in is under floorError (equal weights).
    std::vector<int> method;
    float power = 0;
    // The candidates left out, decided over the whole frame (a combination in strips: each
    // strip's window alone would decide otherwise); null: this window's estimates decide.
    const std::vector<bool> *dropped = nullptr;
    // The whole frame's estimates and noise the rank reads, from a combination in strips;
    // null: this window's.
    const std::vector<double> *frameEstimates = nullptr;
    double frameNoise = 0;
};

struct AutoHalvesResult {
    std::vector<bool> dropped;           // per candidate
    std::vector<double> frameEstimates;  // per candidate, the mean of its finite estimates
    double median = 0;      // theirs, which the drop compares with where it is above 1e-4
    double frameNoise = 0;  // the mean of the noise plane
    // Per candidate, the factor AutoVariantFactors put on its estimate (1: weighs alone).
    std::vector<float> variants;
};

// Sums over a frame's rows, strip after strip in order, of each candidate's finite window
// means and of half1's noise: the whole frame's means, to the bit, from a combination in
// strips (each strip's window holds rows [rowBegin, rowEnd) of its own).
struct AutoHalvesSums {
    std::vector<double> sum;
    std::vector<size_t> count;
    double noiseSum = 0;
    size_t noiseCount = 0;
    int rowBegin = 0, rowEnd = 0;
    void Add(const Image &smooth, const Image &noise);
    std::vector<double> Means() const;
    double NoiseMean() const { return noiseCount ? noiseSum / double(noiseCount) : 0; }
};

// Which candidates `drop` leaves out, given each one's estimate over the frame (the mean of
// its finite window means) and their median, which the ratio is taken against: none where
// that median is under 1e-4 or under 0.01 x half1's variance over the frame (`frameNoise`).
std::vector<bool> AutoHalvesDropped(const std::vector<double> &frameEstimates, float drop,
                                    double frameNoise, double *median);

// Each candidate's factor on its estimate that makes a method's variants share one weight
// under weights 1 / e^power: (its method's candidates left in) ^ (1 / power), at most the
// largest float; 1 for every candidate where `method` is empty or power is not above 0.
std::vector<float> AutoVariantFactors(const std::vector<int> &method,
                                      const std::vector<bool> &dropped, float power);

// `smooth`: K planes, the candidates' window means of their estimates; `noise`: one plane,
// the window mean of half1's variance over relMSE's denominator (>= 0). Returns what was
// left out; a left-out candidate's plane becomes +inf (weight 0), and the others' floor
// reads the median of those left in.
AutoHalvesResult AutoAdjustHalvesEstimates(Image &smooth, const Image &noise,
                                           const AutoHalvesSettings &settings);

// The guard of the local means (issue 29): a candidate that fades or ghosts a small object
// (blurs it into its surroundings) keeps the estimates' wide windows nearly as they were,
// yet its mean over the object departs from the input's by more than the input's noise
// allows. At each pixel t is the root mean square over channels of the candidate's
// departure from the colour, each averaged over tents of `radius`, in standard errors of
// the colour's tent mean (from the variance of the pixel mean, with kAutoGuardRelative of
// that mean, or kAutoGuardLeastError if more, as its least standard error); a NaN variance
// leaves the pixel unguarded. Where t > z the estimate, read as at least
// floorError, is multiplied by exp(min((t^2 - z^2) / 2, kAutoGuardMostLog)): how much less
// likely a departure of t than one of z is under the input's noise (normal), so that a
// departure well past the noise takes the candidate's weight there (z 0: off).
struct AutoMeanGuard {
    float z = 0;
    int radius = 2;
    float floorError = 1e-5f;
};

// The largest log of the guard's factor, so that a departure far past the least standard error
// lowers a candidate's weight, finitely, instead of dropping it.
constexpr double kAutoGuardMostLog = 16;
// The least standard error of a tent mean, as a share of it: a window of exact values
// (every sample alike) holds a candidate to its mean within this, not to the bit.
constexpr float kAutoGuardRelative = 0.01f;
// The least standard error of a tent mean, absolute: where the colour is exactly 0 (a black
// background), a departure must be real, not a bleed of rounding, to count.
constexpr float kAutoGuardLeastError = 1e-4f;

// `smooth`: K planes, one per output of `outputs` (each of `color`'s shape); `variance`:
// the variance of `color`'s pixel mean, per channel. Returns, per candidate, the share of
// the pixels whose estimate it raised.
std::vector<double> AutoGuardLocalMeans(Image &smooth, const Image &color,
                                        const std::vector<const Image *> &outputs,
                                        const Image &variance, const AutoMeanGuard &guard);

}  // namespace mcd
