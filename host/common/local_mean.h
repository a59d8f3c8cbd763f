// Restoring an input's local means after a method that biases them (beyond the papers). A
// method that darkens an area (bayes's log domain, pivot's robust fits, auto's relative
// combination) gets its local brightness back where the input's local mean says so with
// confidence, and keeps its own shape within the windows.
//
// Values equal to the input's (the method left them: an emitter, a zero kept) count in no
// mean and stay. First the highlights: a pixel whose input (its channels summed) is over 16
// times the output there or the output's tent mean of radius 2r there, with at least 2 of
// its 8 neighbours so too (a small light or a light's edge the method cut; a firefly stands
// alone), takes its input back (but its values kept already) and counts as left; with a
// variance layer, instead of the neighbours, its input must be over 4 standard deviations from
// the output, or its 8 neighbours within the frame (3 or more) each exact and lit (every
// sample equal, above 0): its spread is then its footprint's coverage of something bright (a
// small light in a mirror), which a single sample of many saw, not a rare path. A light's rim,
// dimmer than its core, passes only once the core is kept: up to 4 rings more grow from the
// kept highlights, each read against the tent mean without them (a rim the method cut and the
// restore spread made a glowing square around each small light). Then at each value, over a
// tent window of radius 2s (a box of radius s twice, each clipped to the image), m_in and m_out
// are the means of the input's finite values >= 0 and of the output. Their difference d = m_in
// - m_out is shrunk by the noise of m_in, estimated as the mean of (input - output)^2 over the
// same window times the tent's sum of squared weights, q: d' = d max(0, 1 - q / d^2)
// (positive-part James-Stein), and the output multiplied by (m_out + d') / m_out. A difference
// that comes from a few pixels (fireflies the method removed) should have q near d^2 and leave
// the method's output, rather than spreading their energy over a glowing square; a darkening
// shared by many pixels is restored. With `pixelNoise` (pivot, rhf, auto) q is the variance of
// the tent mean of independent values each of variance its own (input - output)^2: the sum of
// their squared weights times those, so one pixel's difference has q = d^2 wherever it lies in
// the window. The window's mean squared difference times the sum of squared weights (without)
// gives one pixel near the centre q = 4/9 d^2: its energy spread over the rounded square where
// its weight is over 4/9 of the peak's. This runs at s = 4r first and then at s = r on its
// result: what is uncertain at the fine scale is restored at the coarse one. The fine scale's
// shrinkage is lopsided where the noise is heavy-tailed: windows without a rare bright sample
// give the coarse gain back with confidence, windows with one keep it only in part, so the
// frame loses energy. A last pass at s = 4r, its noise weighted by `rebalance`, returns it over
// the coarse tents.
#pragma once

#include <string>
#include <vector>

#include "host/image.h"

namespace mcd {

// Each plane's mean over the tent window of radius 2r around each pixel.
Image TentMean(const Image &image, int r);

// Each plane's mean over the window of radius 2r around each pixel weighted by the tent's
// squared weights (of radius 2r: the product of the 1D tents' squares, each axis clipped to
// the image and renormalised). Times TentSquaredWeights(r), the variance of the tent mean of
// independent values whose variances these are.
Image TentSquaredMean(const Image &image, int r);

// The sum of the squared weights of an unclipped tent window of radius 2r: the factor from
// the mean of i.i.d. values' variance to the variance of their tent mean.
double TentSquaredWeights(int r);

// How far a pixel's restored value reads: the coarse windows, then the fine ones, then
// the coarse ones again where the restore rebalances.
inline int LocalMeanReach(int r, bool rebalance = false) {
    return 2 * 4 * r + 2 * r + (rebalance ? 2 * 4 * r : 0);
}

// The weight on the noise of the last coarse pass for pivot and rhf (RestoreLocalMeans'
// `rebalance`): 0 restores the coarse means whole (a rare bright sample's energy then
// spreads over its tent), 1 shrinks them as the first pass does.
constexpr double kLocalMeanRebalance = 0.25;
// auto's: its relative combination leans to the darker candidates where they disagree, so
// its restore gives back more.
constexpr double kLocalMeanRebalanceAuto = 0.1;

// The factors applied, smallest and largest (1 and 1 where none was).
struct LocalMeanFactors {
    double lo = 1, hi = 1;
};

// `output` (the shape of `input`) scaled to `input`'s local means; r > 0. `variance` (of
// the pixel mean, one channel or the input's; may be null, ignored unless of the input's
// size) tells highlights from fireflies in place of the neighbours.
// `rebalance` >= 0: the last coarse pass, its noise weighted so; < 0: none. `pixelNoise`:
// q from each value's own squared difference (TentSquaredMean), not the window's mean one.
// `left` (one flag per value; may be null): the values the method left, kept in place of
// those equal to the input's (a fit that gives a value back to within rounding, exactly on
// one side of a float and double pair and not on the other, is then restored on both); on
// return it holds them and the highlights taken back.
LocalMeanFactors RestoreLocalMeans(const Image &input, int r, Image *output,
                                   const Image *variance = nullptr, double rebalance = -1,
                                   bool pixelNoise = false, std::vector<bool> *left = nullptr);

// One scale of the restore alone, without the highlights, for a second input read after the
// restore: over the tent of radius 2s clipped to the image (weights 2s + 1 - |offset| per
// axis over their sum), the gain d / m_out, d = m_in - m_out shrunk by q, the variance of
// m_in's tent mean were each value's noise its own squared difference (the sum of the
// squared weights times those) times `noiseWeight`; each value scaled by 1 + the mean of
// those gains over the same tent (among the values that have one: m_in, m_out > 0, finite),
// so that a bright value, whose noise shuts the gain in every window that holds it, leaves
// no step at the edge of their square. The values equal to the input's are kept and count
// in no mean; with `left` (one flag per value), those it marks instead.
LocalMeanFactors RestoreLocalMeanAt(const Image &input, int s, double noiseWeight,
                                    Image *output, const std::vector<bool> *left = nullptr);
// Each plane of `image` over the tent of radius 2s clipped to the image (RestoreLocalMeanAt's
// means): along rows, then down columns, each value its window's weights (with `squared`,
// their squares) times the values, summed in double in order of rising offset and rounded
// to float once per pass.
Image ClippedTentFilter(const Image &image, int s, bool squared);
// RestoreLocalMeans with a last coarse pass of weight `rebalance` (kLocalMeanRebalance for
// pivot and rhf) and the noise of each value (`pixelNoise`); returns what the plan says of
// it ("the input's means over tents ...").
std::string RestoreLocalMeansRebalanced(const Image &input, int r, Image *output,
                                        const Image *variance,
                                        double rebalance = kLocalMeanRebalance);

// The restore checked against an independent half-buffer (beyond the papers), for a
// combination that also ran on half0 (auto beside the half-buffers). Where a frame's light
// is in rare bright samples (a glossy ring's reflections of small lights at 16 spp) the
// candidates take it off and the restore gives it back spread over its tents, onto pixels
// the reference keeps dark. `combined` and `combinedHalf` (the same combination of the
// candidates' runs on `half0`) are restored as RestoreLocalMeansRebalanced does, from
// `input` and `half0`; per pixel the share t of the restore, f = a + t (b - a), that the
// independent `half1` says lowers the relative squared error over the tent of radius 2s:
// t = sum w (a0 - h1)(a0 - b0) / sum w (a0 - b0)^2 clamped to [0, 1], w = 1 / (a^2 + 0.01)
// (channels' mean a), where a0, b0 are the half's combination unrestored and restored (the
// expectation of the sum is that of the reference's in place of h1: a0 and b0 do not
// depend on h1); t = 1 at a highlight the restore took back among exact lit neighbours (one
// sample saw it, so it lies in one half alone and the other cannot confirm it). relMSE
// prefers a dark output where the noise is heavy-tailed, so the
// restore's brightness is then kept to `floorShare` of the input's mean: t' = t + l (1 -
// t) with the least l in [0, 1] that gives it. Before that lift the checked output is
// taken times one gain g, at most `maxGain` and what the whole restore would add, towards
// that share: a small gain moves no light between pixels, where the rest of the restore
// puts it back spread over its tents (a glossy ring's light onto the wall around it); a
// large one would brighten every pixel alike. Half1 does not check the gain (nor the
// lift): both are a floor on brightness, as auto's bound on it asks; a gain also held to
// half1's least-squares gain of the checked half0 output lost (docs/methods/auto.md).
// `output`: `combined`'s shape.
constexpr double kRestoreCheckFloor = 0.99;
struct RestoreCheck {
    std::string restore;   // RestoreLocalMeansRebalanced's account of the restore
    double meanShare = 1;  // the mean of t
    double lift = 0;       // l
    double gain = 1;       // g
};
RestoreCheck RestoreLocalMeansChecked(const Image &input, const Image &half0,
                                      const Image &half1, const Image &combined,
                                      const Image &combinedHalf, int r, const Image *variance,
                                      double rebalance, int s, double floorShare, Image *output,
                                      double maxGain = 1);

// Lone spikes cut from a frame before a filter that averages each pixel with the alike ones
// around it (beyond the papers): rhf's histograms hardly tell a firefly from its
// neighbours, so its energy was spread evenly over the search window, a square. A pixel
// whose value (channels summed, all finite) is over kSpike times the median of its
// neighbours' (the 8 within the image, the lower middle of an even count), with fewer than 2
// of them so over and above each of the others (a light's rim beside its core is no spike;
// a pair of fireflies is cut whole), takes per channel its neighbours' median. The restore of
// local means (with each value's noise) then reads the cut energy as noise: a lone spike's
// comes back over the coarse tents only. Returns how many pixels were cut.
// A spike over kSpikeMost times the median stays: its energy, given back over the coarse
// tents (at r = 8 a centre weight of 1/4225), would light a glow one can see (a firefly
// on a dim emitter); the filter's bright veto keeps such a point mostly to itself.
// With `variance` (of the pixel mean, one channel or the frame's; see CutLightRims for a
// light) that bound holds only beside a light: a spike over it on a lit surface (a chrome
// sphere's reflections of small lights) is cut as the others are.
// Over black (a few samples of a dark pixel all 0: the median is 0) the ratio says nothing:
// there both bounds are read against the median of the neighbours above 0 (a firefly on a
// plane's edge beside a black background, which the filter spread into the black), and a
// spike with none stays.
constexpr double kSpike = 16, kSpikeMost = 512;
// `pixels`, when given, receives the pixels cut (ascending).
size_t CutSpikes(Image *color, const Image *variance = nullptr,
                 std::vector<size_t> *pixels = nullptr);

// A small light's rim cut from a frame before such a filter, and given back after it (beyond
// the papers). A pixel beside a small light's core that one of its few samples saw is no
// lone spike, but the filter spread it over its search window all the same: a lighter
// square beside each bulb. A light: a pixel whose value (channels summed, finite, > 0) has
// a standard deviation (`variance` of the pixel mean, one channel or the frame's, summed)
// of at most kLightNoise of it: nearly every sample saw the same. A pixel whose value is
// over kSpike times the median of its 8 neighbours', which is no light itself and
// has a light brighter than it within kRimReach pixels (a pixel filter as wide as Cycles'
// spreads a light's edge over two pixels, the inner one no light), a neighbour that is
// none, and at most kSmallLight lights within kRimWindow pixels (9x9; a small light: along
// a large light's edge, as cornell's at 4 spp, the filter spreads the rims along the edge,
// which is the edge's coverage), takes per channel
// the median of its neighbours that are no lights (from the frame as given); none without
// such neighbours.
// Returns the pixels cut (y * width + x, ascending); the caller gives them their input back
// after the filter. An empty or wrongly sized variance cuts nothing.
constexpr double kLightNoise = 0.01;
constexpr int kSmallLight = 25, kRimReach = 2, kRimWindow = 4;
std::vector<size_t> CutLightRims(Image *color, const Image &variance);
// Each of `pixels` takes per channel the median (the lower middle) of its neighbours within
// the frame not `skipped`, from `given` (a bright cluster's cut; rhf's probe making its run's
// cuts); one with none, or with one not finite (no median: as a spike's cut), keeps its value.
void TakeNeighbourMedians(const Image &given, const std::vector<size_t> &pixels,
                          const std::vector<char> &skipped, Image *cut);
// Each pixel's channels summed (in double, stored as float), NaN where the sum is not
// finite; whether pixel p of those sums is a light as CutLightRims reads one (its sum finite
// and > 0, its channels' variances summed at most (kLightNoise x its sum)^2).
Image ChannelSums(const Image &color);
bool Light(const Image &variance, const Image &sums, size_t p);

// Small clusters of bright samples cut from a frame before rhf's filter and given their
// input back after it (beyond the papers). rhf's distance leaves out a bin that holds at
// most one sample of the two pixels compared, and the bright veto reads only the counted
// terms, so a pixel that one bright sample of many saw is, to the filter, alike the pixels
// around it, and every pixel whose search window holds it averages it in: a square. Pair by
// pair one sample is no evidence; the search window is. A cluster: kClusterLeast or
// more 8-connected pixels within a box of kClusterSpan x kClusterSpan (a patch's at the
// default half-size; a longer one is a highlight's line, whose run the filter follows), each
// over kSpike times its neighbours' median (channels summed, as CutSpikes reads them), each
// with at most kClusterShare of its samples above the histograms' range (the last two bins of a
// colour, the most of its colours: the bright veto's default share for samples bright in one
// colour, over which it keeps the pixel apart from one with none; the veto sums its terms over
// the three colours, so it keeps apart fewer samples bright in all three) and together k >= 2.
// kClusterShare and kClusterSpan are fixed: they do not follow --bright-veto or --patch-half.
// Were the bright samples of the cluster's search window (within `searchHalf` of the
// cluster's box, outside the box grown by 1) and the cluster's spread alike over their
// pixels, the cluster's k of the T would be Binomial(T, cluster / (cluster + window
// pixels)). A cluster whose tail P(>= k) is under kClusterLevel and
// that holds at least as many bright samples as the rest of its window is a small feature the
// few samples saw on a surface that has none around it (a light's reflection on a dark glossy
// floor), not noise to spread; beside more bright samples (a highlight's line) the filter's
// averaging among them stays. The cluster's place and size are read off the same samples, so a
// pair of bright pixels side by side (about 8 T / window pixels likely by chance) is not
// enough: fireflies on a heavy-tailed texture make such pairs. A pixel that holds a bright
// sample but is not over kSpike times its neighbours' median joins the groups it touches when
// they are kBridgedGroups or more of at least kBridgedSize pixels, each of which holds a bright
// sample, spanning less than kClusterSpan (one longer than kClusterSpan would make the joined
// cluster too long to cut; without the bound the join would read the whole group): its bright
// neighbours lift its median, so the measure splits a small caustic at its middle into pairs
// (two lone fireflies with a pixel between them stay apart). Each pixel of a cluster cut takes
// per channel the median of its neighbours outside the cluster (from `input`, the frame as
// given) in `color`; the caller gives them their input back after the filter (spread, a light's
// reflection in chrome lit the dark pixels beside it where the reference keeps it sharp), but
// for a cluster so joined: it is no sharp point (its values fall off from pixel to pixel; the
// reference holds a blob wider than it), so its pixels go to `bridged` (if given; ascending)
// and the caller leaves their energy to the restore of local means, as a spike's. Returns the
// other cut pixels (ascending). Nothing without histograms of `input`'s size. The colour must
// be finite (the front ends' --non-finite sees to it): a median of neighbours holding NaN
// would put NaN into the filter's input.
constexpr int kClusterLeast = 3, kClusterSpan = 3, kBridgedGroups = 2, kBridgedSize = 2;
constexpr double kClusterShare = 0.3, kClusterLevel = 1e-4;
std::vector<size_t> CutBrightClusters(const Image &input, const Image &histograms,
                                      int searchHalf, Image *color,
                                      std::vector<size_t> *bridged = nullptr);

// Each value of `output` moved at most k standard deviations of the pixel's noise from
// the input (beyond the papers): a method's fits that overshoot an edge, smear a firefly or
// a light the guide does not show, or go negative, cannot leave a pixel farther from its
// input than its own noise allows. The variance is the larger of the pixel's and the mean
// over its 3x3 window clipped to the image without the window's largest value (one firefly
// beside a pixel must not free it to take the firefly's smear). Values whose input or
// output is not finite are left; so are values whose variance is 0 (every sample equal: at
// 4 spp half a dim interior's pixels, whose samples all missed the light) or whose window
// has a variance that is not finite or is negative, but for a floor: such a value below 0
// where its input is not becomes 0, that channel alone (its pixel's others moved with it to
// their input brought back a dim frame's grain). The other channels of a pixel move by one
// share t of their moves, the largest every channel's bound allows (a bound on one channel
// alone would tint the pixel), and not below 0 where the input is not negative. `variance`:
// of the pixel mean, 1 or the input's channels. Returns how many values moved.
size_t BoundToNoise(const Image &input, const Image &variance, double k, Image *output);

// The noise bound's standard deviation of channel c at (x, y), for BoundToNoise and
// BoundToInputRange: the square root of the larger of the pixel's variance and its 3x3
// window's (clipped to the image) mean without its largest value, the window summed in
// raster order less the largest (as cpu_reference sums it, so both agree to the bit); -1
// where the pixel's variance is not above 0 (every sample equal says nothing of the noise)
// or a variance of the window is not finite or is negative. `variance`: 1 or c + 1 channels
// or more.
double NoiseSpread(const Image &variance, int c, int x, int y);

// Each pixel of `output` held to the range of its input's neighbourhood, widened by its noise
// (beyond the papers): per channel [min - k s, max + k s], min and max over the finite input
// values of the (2 radius + 1)^2 window clipped to the image, s the noise bound's standard
// deviation (BoundToNoise: the larger of the pixel's variance and its 3x3 window's mean without
// the largest). A filter that averages cannot leave that range by more than the noise lets the
// truth; plane fits can, where they extrapolate a highlight's slope or its fireflies (a glossy
// ring's fits several times the brightest input around them), and the noise bound lets them,
// as a highlight's variance is large. Without the widening, a dim frame of few samples, whose
// windows all missed the light, lost its fits (every input 0 around a pixel that the light
// reaches). A pixel's channels move toward their input by one share t, the largest that keeps
// every channel in its range (a bound on one channel alone would tint it). Values whose
// variance is 0 (every sample equal: at a few samples per pixel, all of them missing the light;
// bounded, they kept the input's grain), whose input or output is not finite, or whose window
// has a variance that is not finite or is negative, are left. `variance`: 1 or the input's
// channels. Returns how many values moved.
//
// The range is widened by kRangeSlack of the window's largest magnitude: where the pixel is
// its window's extreme, a fit one rounding beyond it would otherwise set the share to 0 and
// take every channel back to its input (a jump from a rounding: the GPU's and the twin's
// fits then end the pass far apart); with the slack the share falls continuously from 1.
constexpr double kRangeSlack = 1e-5;
size_t BoundToInputRange(const Image &input, const Image &variance, int radius, double k,
                         Image *output);

// The variance of the pixel mean estimated from a frame without sample statistics, robust
// to the frame's own structure (beyond the papers): per channel z = color / albedo (its one
// channel or channel c; 1 where it is <= 0.02 or there is none); at each pixel e, the
// smallest r^2 / 1.5, r = z - (z_-d + z_+d) / 2, over the directions d of (1,0), (0,1),
// (1,1), (1,-1) whose two neighbours lie in the image, over that minimum's median for unit
// Gaussian noise (kFrameNoiseMedianOf4 for four directions, of one: kFrameNoiseMedianOf1; no
// e without a direction or where a difference is not finite). The result: the median of the e
// of the 5x5 window clipped to the image (the lower middle value of an even count) over
// kFrameNoiseWindowBias, times the albedo squared at the pixel; 0 where the window has no
// e. A 3x3 sample variance counts a line or an edge the albedo does not show as noise (a
// glass's refracted pattern then reads as noise and the plane fits smear it); a line
// covers less than half of the window, so its median is the noise beside it.
constexpr double kFrameNoiseMedianOf4 = 0.0504, kFrameNoiseMedianOf1 = 0.4549;
constexpr double kFrameNoiseWindowBias = 1.165;
Image FrameNoise(const Image &color, const Image *albedo);

}  // namespace mcd
