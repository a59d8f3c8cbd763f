// Highlights taken out of a frame before a filter (host/common/highlights.h), the CPU
// reference: every window sorted in full.
#pragma once

#include <vector>

#include "host/image.h"

namespace mcd::ref {

// s(p) = the sum of p's channels. Without NaN/Inf in `color`, p is a candidate where s(p) >
// k max(upper median of s over the window of radius r clipped to the image, 1e-3 x the mean
// of s) and, with `variance`, e(p) = the sum over channels of (color - its channel's upper
// median over the window) is > 0 and e^2 > 4 x the sum of p's variances (2 standard
// deviations). A candidate is a highlight (a seed) with at least 2 candidate neighbours of its
// 8, or with 1 where e^2 > 16 x that sum (p 4 standard deviations above: a small light's
// reflection most samples saw). `base` (and `baseVariance`, when `variance` is given) are the
// inputs with each channel at a seed replaced by its window's upper median. Then up to 4
// rounds of growth: a pixel not marked, with a neighbour q marked before the round whose base
// channels sum to b, is marked where s > k max(b, the mean of s over the frame) and, with
// `variance`, (s - b)^2 > 4 x the sum of its variances, or by the rim rule: q is sure of its
// light (s_q - b > 0 with (s_q - b)^2 > 16 x the sum of q's variances) and s_q >= s (a rim
// pixel one sample of the light hit stands under 2 of its standard deviations, as a firefly
// does). It takes the base (and base variance) of the first such q in row order. A fifth
// round only checks: a connected region (8 neighbours) with a pixel that would still grow is
// a large light, and its grown pixels get their input (and variance) back. Returns the
// highlight mask.
std::vector<char> SplitHighlights(const Image &color, const Image *variance, double k, int r,
                                  Image *base, Image *baseVariance);

// Sparse lights (host/common/highlights.h): nothing where `color` has NaN/Inf. m = lightSample
// where >= 0, else the upper median over the highlights of the sum of maxSample's channels (0
// when there is none or maxSample has NaN/Inf). Nothing when m <= 0. A pixel p not a highlight
// becomes one where s(p) > k max(upper median of s over the window of radius r, 1e-3 x the
// mean of s) and the sum of its maxSample channels is <= 2 m, where s(p) > k x the mean of s
// or (a streak) s(p) > k / 2 x that mean, at least 2 of its 8 neighbours in the frame pass the
// window test, and that sum is <= m / 2. Then a sparse light with exactly one neighbour that
// passes the window test adds that neighbour where that neighbour has no other neighbour that
// passes it, is neither a highlight nor a sparse light and its maxSample sum is <= 0.25 x the
// sparse light's.
// Each added pixel's base (and baseVariance) channels become their window's upper medians of
// color (and variance).
void AddSparseLights(const Image &color, const Image *variance, const Image &maxSample,
                     double k, int r, double lightSample, std::vector<char> *highlight,
                     Image *base, Image *baseVariance);

// Crests beyond lights' rims (host/common/highlights.h): nothing where color or variance has
// NaN/Inf, variance a negative value, or maxSample (when given) NaN/Inf. s(p) and v(p) are the
// sums of p's color and variance channels (in float, in channel order); m = frameMean where
// >= 0, else the mean of s over the frame; p is a light where s > k m, s > 0 and s^2
// >= 16 v; a rim (with maxSample) where it is not a light, a light L lies among its 8
// neighbours and the sum of its maxSample channels is >= 0.5 x the largest s(L) of those.
// A light is full where s - 2 sqrt(v) >= 0.75 x the largest s of the lights among its 8
// neighbours.
// Where p is neither, has no full light among its 8 neighbours and a light or rim lies within
// `reach` of it, each channel of output is min(output, the maximum of color over p and the
// pixels of the window of radius r around p that are neither). Where p is neither, has no full
// light among its 8 neighbours and a full light lies within 4 of it, each channel of output is
// instead clamped to [min(color at p, m - 2 sqrt(V) / n), max(color at p, m + 2 sqrt(V) / n)],
// m the mean of color and V the sum of variance over the n pixels of the window of radius 2
// around p that are neither light nor rim.
void ClampBeyondLightRims(const Image &color, const Image &variance, const Image *maxSample,
                          double k, double frameMean, int reach, int r, Image *output);

// Where p is not a highlight and a highlight lies within `reach` of it (max(|dx|, |dy|)),
// each channel of output is min(output, the maximum of color over the non-highlight pixels of
// the window of radius r around p clipped to the frame), finite values only.
void LowerToInputMaximumNearHighlights(const Image &color, const std::vector<char> &highlight,
                                       int reach, int r, Image *output);

// output += color - base at the highlights, in float.
void AddHighlights(const Image &color, const Image &base, const std::vector<char> &highlight,
                   Image *output);

}  // namespace mcd::ref
