// Highlights taken out of a frame before a filter and added back after (beyond the papers). A
// small light or a light's rim is far brighter than the frame around it and has a large
// variance; a wavelet filter shrinks every detail around it by that variance, so its energy
// spreads into the dim pixels nearby (rings and blotches around lights), where each unit
// costs far more relative error than it saves at the light. A pixel whose input (its channels
// summed) is over k times the median of the same sums over the window of radius r around it
// (and over a floor of 1e-3 of the frame's mean sum), with at least 2 of its 8 neighbours so
// too (a lone firefly is noise the filter should spread), and, given a variance, 2 standard
// deviations above its window's median (a firefly, one sample's deviation about its mean, is
// not), is a highlight; so is one 4 standard deviations above with one bright neighbour
// (most of its samples saw the light: a small light's two-pixel reflection in a mirror
// sphere, whose shrunk details rang dark holes around it). The filter reads, at
// that pixel, each channel's median over the window (and the variance's), and the difference
// is added back after, so the highlight keeps its input and the frame its energy. A light
// wider than half the window is its own median inside, so highlights then grow into
// neighbours over k times the background their seed read and k times the frame's mean (a
// bulb's interior and rim), 2 standard deviations above it or, beside a highlight 4 above it,
// no brighter than that highlight (a rim pixel one sample of the light hit); a region that
// would still grow after the last round is a light larger than a bulb, and its growth is
// undone.
#pragma once

#include <cstddef>
#include <vector>

#include "host/image.h"

namespace mcd {

// How many rings highlights grow at most from the pixels over k times their window's median.
constexpr int kHighlightGrowRounds = 4;

struct HighlightSplit {
    Image base;                   // the input, highlights replaced by their windows' medians
    Image baseVariance;           // the same for the variance (empty without one)
    std::vector<char> highlight;  // per pixel
    size_t count = 0;             // highlights, grown ones included
    size_t grown = 0;             // of those, the ones the growth added
    size_t sparse = 0;            // of those, the sparse lights AddSparseLights added
    // What AddSparseLights reads again: the pixels over k times their window's median of the
    // channel sums and the floor (empty for a frame with NaN/Inf), and the frame's mean sum.
    std::vector<char> overWindow;
    double mean = 0;
};

// The split of `color` (and `variance`, the input's size or null) at ratio k over windows of
// radius r. A frame with NaN/Inf values has no highlights (the filter refuses it or says so).
// `frameMean` (HighlightFrameMean of the whole frame) stands in for the color's own mean where
// >= 0, so a tile reads the frame's.
HighlightSplit SplitHighlights(const Image &color, const Image *variance, double k, int r,
                               double frameMean = -1);

// How far a sparse light's brightest sample may stand above the highlights' (AddSparseLights).
constexpr double kSparseLightSampleRatio = 2;

// A glossy surface's reflection of a light that one sample per pixel saw is a streak of dim
// glints, each under k times the frame's mean, and the filter spread it across the edge it
// lies on into the dark side. Such a pixel is a sparse light too from kStreakMeanShare x k
// times the mean, with at least kStreakNeighbours of its 8 neighbours over k times their
// windows' medians (and the floor), and its largest sample at most kStreakSampleRatio times
// the highlights' median one: a glossy reflection is dimmer than the light it reflects, while
// a caustic's firefly carries its light's full value.
constexpr double kStreakMeanShare = 0.5;
constexpr int kStreakNeighbours = 2;
constexpr double kStreakSampleRatio = 0.5;

// A two-pixel reflection's dimmer pixel, which the reflection's faint edge covers, has its
// largest sample at most kPartnerSampleRatio times its sparse light's; a caustic's fireflies
// side by side each carry about the light's full value.
constexpr double kPartnerSampleRatio = 0.25;

// Sparse lights: a light's reflection one or two pixels wide that one or two of its samples saw
// stands under 2 of its standard deviations, as a firefly does, and the filter spread it into
// a bright square with dark dots where the reference is dim. A firefly of a rare path weighted
// by a small density is far brighter than any light the frame shows; a reflection's sample is
// no brighter than the light it reflects (nor is a caustic's: those are kept too). Given the
// per-pixel largest sample `maxSample` (the color's shape), given the split SplitHighlights
// made of `color` and `variance` at k and r (its window test and mean read again), a pixel not
// yet a highlight whose channels sum to over k times its window's median (and the floor) and k
// times the frame's mean (or, for a streak's pixel, the kStreak* terms above), and whose
// largest sample (channels summed) is at most kSparseLightSampleRatio times `lightSample`
// (HighlightSampleMedian of the whole frame, so a tile compares with the frame's lights; < 0:
// that of the split's own highlights), becomes a highlight: reconstructed at its window's
// medians, given its input back after. So does a two-pixel reflection's dimmer pixel: the one
// neighbour over its window (and the floor) of such a pixel, with no other neighbour so itself
// (a sparse light's or its partner's other such neighbours are a streak's, a line's or a light
// rim's), not a highlight, with its largest sample at most kPartnerSampleRatio times that
// pixel's. Nothing with a `lightSample` of 0 (no highlights to compare with); returns how many
// it added (also counted in split->count and split->sparse).
size_t AddSparseLights(const Image &color, const Image *variance, const Image &maxSample,
                       double k, int r, double lightSample, HighlightSplit *split);

// What sparse lights compare with: the median (the upper one) over the highlights of
// maxSample's channel sums; 0 (sparse lights off) without highlights or where maxSample has
// NaN/Inf values.
double HighlightSampleMedian(const Image &maxSample, const std::vector<char> &highlight);

// The mean of the color's channel sums, as SplitHighlights reads it.
double HighlightFrameMean(const Image &color);

// `output` plus (color - base) at the highlights.
void AddHighlights(const Image &color, const HighlightSplit &split, Image *output);

// Crests near lights cut: each value of `output` at a pixel that is not a highlight but within
// `reach` (Chebyshev distance) of one is lowered to the largest input value of its channel over
// the window of radius r around it, highlights left out. The synthesis spreads what is left of
// a light's noisy rim into a glow beside it; a mean of the samples there is no higher than the
// highest of them. Returns how many values moved.
size_t LowerToInputMaximumNearHighlights(const Image &color, const std::vector<char> &highlight,
                                         int reach, int r, Image *output);

// Lights sure of themselves and their rims (beyond the papers). A large light's interior is no
// highlight (it is its own window's median), and its rim, pixels some of whose samples saw the
// light, is noisy: the filter spread the rim into the dim pixels beyond it, a bright band
// where the reference is dark. A light pixel has channels summing to over k times the frame's
// mean and kLightRimSigmas of its standard deviations (the sum's, from the variance) above 0:
// most of its samples saw the light. A rim pixel is not a light, has a light among its 8
// neighbours, and its largest sample (channels summed) is at least kLightRimSampleShare times
// the brightest such light's sum: a sample of it saw that light.
constexpr double kLightRimSigmas = 4;
constexpr double kLightRimSampleShare = 0.5;
// A light pixel at least this share of the brightest light beside it, kFullLightSigmas of its
// standard deviations (the sum's) below its value, is the light's full interior, not a pixel
// its edge crosses: its neighbours are the rim, lit or not. A crossed pixel's samples are the
// light's or the ceiling's, so its noise may lift it over the share; its standard deviation
// keeps it out (the row past it was left to the spread: issue 29, cornell 256x256).
constexpr double kFullLightShare = 0.75;
constexpr double kFullLightSigmas = 2;
// How far beyond a rim its spread is cut.
constexpr int kLightRimReach = 1;
// Within kFullLightReach of a full light (a sharp light's edge: the pixels past it see none
// of its light) each value, the rim and the full light's neighbours left out, is held between
// the lower of its own input and the mean of its (2 kRimMeanRadius + 1)^2 window (lights and
// rims left out) minus kRimCutSigmas of that mean's standard deviations, and the higher of its
// input and that mean plus as many. The window's maximum is itself a high draw of the noise,
// so it left the crests past the rim too high, and the synthesis's trough a few rows out, held
// only by the input's minimum, drew a dark line beside the light (issue 29). A soft light's
// glow (out of focus, a caustic) has no full light beside it and keeps the maximum.
constexpr int kFullLightReach = 4;
constexpr int kRimMeanRadius = 2;
constexpr double kRimCutSigmas = 2;

struct LightRims {
    std::vector<char> light, rim, full;  // per pixel
    size_t lights = 0, rims = 0;
};

// The lights, full lights and rims of `color` at ratio k over `frameMean` (HighlightFrameMean
// of the whole frame), from `variance` (the color's shape) and `maxSample` (the color's shape,
// or null: no rims). None where variance or color has NaN/Inf or a negative variance, or the
// shapes differ.
LightRims FindLightRims(const Image &color, const Image &variance, const Image *maxSample,
                        double k, double frameMean);

// Values beyond lights' rims held to their window. A pixel that is neither a light, a rim nor
// a full light's neighbour (its rim, whether or not a sample saw the light) is moved as
// follows. Within kFullLightReach of a full light (whether or not within `reach` of a light or
// rim), each value of `output` is held within the bounds above from the mean of its window of
// radius kRimMeanRadius, whatever r is (`variance` is the per-pixel variance of the mean, the
// color's shape): crests and troughs alike. Elsewhere within `reach` of a light or rim, each
// value is lowered to the largest input value of its channel over the window of radius r
// around it, lights and rims left out: a mean of the samples there is no higher than the
// highest of them. Returns how many values moved.
size_t ClampBeyondLightRims(const Image &color, const Image &variance, const LightRims &rims,
                            int reach, int r, Image *output);

// How many of (x, y)'s 8 neighbours inside the w x h frame are marked: a highlight is a
// cluster, a lone marked pixel a firefly.
int MarkedNeighbours(const std::vector<char> &marked, int w, int h, int x, int y);

}  // namespace mcd
