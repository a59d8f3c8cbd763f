// Method `auto`'s object floor (issue 29): the relative combination leans to the darkest
// candidate where the candidates disagree, and where different candidates are dark at
// different pixels an object's mean falls below every candidate's. Per object id, where
// the combination's luminance summed over the object is below a level (a share) of the
// darkest candidate's, each pixel of the object moves toward the candidates' weighted mean
// by the one fraction that brings the sum to that level (docs/methods/auto.md).
#pragma once

#include <cstddef>
#include <vector>

#include "host/image.h"

namespace mcd {

// The fewest pixels an object needs for the floor to move it.
constexpr size_t kAutoObjectFloorMinPixels = 64;

// The largest scale the object lift gives an object.
constexpr double kAutoObjectLiftMaxScale = 2;

// One object the floor moved.
struct AutoObjectMove {
    float id = 0;
    size_t pixels = 0;
    // The object's luminance sums: the combination's before the floor, the darkest
    // candidate's (the target), the weighted mean's.
    double before = 0, target = 0, weighted = 0;
    int darkest = 0;   // that candidate's index
    double alpha = 0;  // the fraction moved toward the weighted mean, in (0, 1]
};

// The weighted mean of `outputs` (each `image`'s shape) under `weights` (one plane per
// output, as the combination returns them), per channel over the pairs of a positive finite
// weight and a finite value; `image`'s value where there is no such pair. Throws where the
// shapes do not match.
Image AutoWeightedMean(const std::vector<const Image *> &outputs, const Image &weights,
                       const Image &image);

// The floor's target after the local-mean restore: `restored` plus the weighted mean's
// excess over the unrestored `combination`, so the floor keeps the restore's change; with
// `input` (the frame's colour), that value moved `inputShare` (in [0, 1]) of the way to the
// input, whose light lies in the pixels where the samples found it (a glossy band's specks),
// not where the candidates spread it. Throws where the shapes do not match.
Image AutoFloorTarget(const Image &weightedMean, const Image &combination,
                      const Image &restored, const Image *input = nullptr,
                      float inputShare = 0);

// Floor `image` per object of `ids` (image's size, its first channel the id) at `level` times
// the darkest of `outputs`' sums (the candidates') by moving toward `weighted` (image's
// shape). Luminance is
// Rec. 709's of the first three channels, else the channels' mean. Pixels with a
// non-finite id or value in any image are left out of the sums and left as they are.
// Objects whose darkest sum is not positive, and objects of fewer than `minPixels` pixels
// that count (their sums are too few pixels to floor; counted in `small` where given), are
// left as they are. Id 0 is an object like any other. Returns the objects moved, by id.
std::vector<AutoObjectMove> AutoObjectFloor(const Image &ids,
                                            const std::vector<const Image *> &outputs,
                                            const Image &weighted, double level, Image *image,
                                            size_t minPixels = kAutoObjectFloorMinPixels,
                                            size_t *small = nullptr);

// The input floor (the lift): the input is the unbiased estimate of each object's light, so
// an object whose output luminance sum is below the input's by more than k standard errors
// of the input's sum (more than its noise explains) is scaled up to that bound.

// One object the lift scaled.
struct AutoObjectLift {
    float id = 0;
    size_t pixels = 0;
    // The object's luminance sums: the output's before the lift, the input's, the input's
    // standard error and the bound (the input's less k standard errors).
    double before = 0, input = 0, error = 0, bound = 0;
    double scale = 1;     // the scale it took: to the bound, at most kAutoObjectLiftMaxScale
    bool halves = false;  // the error is the halves' disagreement over the object
};

// The variance of each pixel's luminance (Rec. 709's of the first three channels, else the
// channels' mean, as the floor's) in an image of one channel: from `variance` (the variance
// of the pixel mean per channel) with the channels taken as fully correlated, the upper
// bound of the luminance's variance (sqrt of it is the weighted sum of the channels'
// standard deviations); else from the half-buffers, a quarter of the squared difference of
// their luminances. Either may be null; both null returns an empty image. Throws where the
// sizes do not match `color`'s.
Image AutoLuminanceVariance(const Image &color, const Image *variance, const Image *half0,
                            const Image *half1);

// Lift `image` per object of `ids` (image's size, its first channel the id): an object whose
// luminance sum is below the sum of `input` (image's shape) less `k` standard errors of it
// is scaled to that bound. The standard error's square is the sum of `lumVariance`
// (AutoLuminanceVariance) over the object, or, where `half0` and `half1` (input's shape) are
// given (image's size) and larger, a quarter of the squared difference of their sums: noise
// shared by the object's pixels (a jittered accumulation moves every edge at once) is in that
// one and not in the pixels' sum. Pixels with a non-finite id or value in any image are left
// out of the sums and left as they are; objects of fewer than `minPixels` pixels that count
// (counted in `small` where given) and objects whose sum is not positive are left as they
// are. Scales the channels the luminance reads (the first three of four, alpha kept), by
// at most kAutoObjectLiftMaxScale. Returns the objects lifted, by id.
std::vector<AutoObjectLift> AutoObjectLiftToInput(const Image &ids, const Image &input,
                                                  const Image &lumVariance, const Image *half0,
                                                  const Image *half1, double k, Image *image,
                                                  size_t minPixels = kAutoObjectFloorMinPixels,
                                                  size_t *small = nullptr);

// The object guard (issue 29), before the combination: a candidate that fades a small object
// (blurs it into its surroundings) keeps its window estimates nearly as they were, the
// object's error being a small part of each window's, yet its luminance summed over the
// object departs from the input's by many standard errors of the input's sum. Per object of
// at least `minPixels` pixels and per candidate, t = (the candidate's sum - the input's) /
// that standard error (as the lift's: the variance summed over the object, or the halves'
// difference over it where larger; at least kAutoGuardRelative of the input's sum). Where
// t < -z (with `both`, |t| > z) the candidate's estimate on the object's pixels is
// multiplied by exp(min((t^2 - z^2) / 2, kAutoGuardMostLog)), as the mean guard's (z 0:
// off).
struct AutoObjectGuard {
    float z = 0;
    bool both = false;  // brightening too, not only darkening
    size_t minPixels = kAutoObjectFloorMinPixels;
};

// One object and candidate the guard weighed down.
struct AutoObjectGuardHit {
    float id = 0;
    size_t pixels = 0;
    int candidate = 0;
    double t = 0, factor = 1;
};

struct AutoObjectGuardResult {
    // One plane per candidate, each pixel's factor on its estimate (1: unguarded).
    Image factors;
    std::vector<AutoObjectGuardHit> hits;
    size_t small = 0;  // objects of fewer than minPixels pixels, left out
};

// The guard's factors for `outputs` (the candidates', `input`'s shape) on the frame of
// `input`, `ids` and `lumVariance` (AutoLuminanceVariance), with `half0` and `half1` where
// given. Pixels with a non-finite id or value in any image are left out of the sums and
// keep factor 1. Throws where the sizes do not match.
AutoObjectGuardResult AutoObjectGuardFactors(const Image &ids, const Image &input,
                                             const Image &lumVariance, const Image *half0,
                                             const Image *half1,
                                             const std::vector<const Image *> &outputs,
                                             const AutoObjectGuard &guard);

// Multiply each finite estimate of `smooth` (one plane per candidate), read as at least
// floorError, by `factors` (smooth's shape) where the factor is not 1; empty factors: none.
void AutoApplyObjectGuard(Image &smooth, const Image &factors, float floorError);

}  // namespace mcd
