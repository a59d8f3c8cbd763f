// Restoring an input's local means (host/common/local_mean.h), the CPU reference: every
// window summed from scratch, in double.
#pragma once

#include <cstddef>
#include <vector>

#include "host/image.h"

namespace mcd::ref {

// Values equal to the input's stay and count in no mean. Highlights: pixels whose input
// (channels summed, all finite) exceeds 16 x min(output, the output's tent mean of radius
// 2r) with at least 2 of 8 neighbours so too take the input back (a value kept already
// keeps its own) and stay; then up to 4 rings more, each read again against the tent mean
// without the values kept so far, of pixels so over and beside one already taken. Then at
// s = 4r and s = r in turn: over the box of radius s clipped to the image taken twice (a
// tent), m_in (of max(input, 0), NaN/Inf as 0), m_out and m_sq (of (that input -
// output)^2); where m_in, m_out > 0 and all finite, d = m_in - m_out is shrunk to
// d max(0, 1 - q / d^2), q = m_sq x the unclipped tent's sum of squared weights, and the
// output multiplied by (m_out + d) / m_out.
// With `variance` (of the pixel mean, 1 or the input's channels; else ignored) a highlight
// needs (input - output)^2 > 16 x its variance (channels summed) instead of the neighbours.
// With rebalance >= 0, once more at s = 4r after those, with q multiplied by rebalance.
// With pixelNoise, m_sq is the mean of those squares over the same clipped window weighted by
// the tent's squared weights (q: the variance of the tent mean of values each of variance
// its own square).
// With `left` (one flag per value) the values it marks stay and count in no mean instead of
// those equal to the input's; on return it also marks the highlights taken.
void RestoreLocalMeans(const Image &input, int r, Image *output,
                       const Image *variance = nullptr, double rebalance = -1,
                       bool pixelNoise = false, std::vector<bool> *left = nullptr);

// One scale of the restore alone (host/common/local_mean.h, RestoreLocalMeanAt): at each
// value not equal to the input's, with weights w_uv = t_u t_v of the clipped, renormalised
// tent of radius 2s (t = 2s + 1 - |offset| over its sum within the image), a = sum w clean,
// b = sum w moved, q = noiseWeight sum w^2 (clean - moved)^2 (kept values 0 in all three),
// the gain g = max(0, 1 - q / d^2) d / b, d = a - b, where a and b are > 0 and finite (a
// value with a gain); the output times 1 + sum w g / sum w over the values with a gain.
// With `left` (one flag per value), the values it marks are the kept ones instead.
void RestoreLocalMeanAt(const Image &input, int s, double noiseWeight, Image *output,
                        const std::vector<bool> *left = nullptr);

// Lone spikes (host/common/local_mean.h, CutSpikes): a pixel whose channels' sum (NaN if
// not finite) is > 0 and > 16 x (and <= 512 x) the median (lower middle) of its in-image
// neighbours' sums, with fewer than 2 of those neighbours so (none where a neighbour's sum is
// not finite) and its sum (as a float) above each of theirs not so over, takes per channel the
// median of its neighbours' values in the frame as given. Returns how many pixels. Where
// that median is 0, the 16 x and 512 x are of the median of the neighbours' sums above 0
// (none: not cut). With a variance (1 or color's channels, color's size; else as without),
// over 512 x is cut too where that median is > 0 and no neighbour is a light (CutLightRims
// below).
size_t CutSpikes(Image *color, const Image *variance = nullptr);

// A light's rims (host/common/local_mean.h, CutLightRims): a pixel whose channels' sum (NaN
// if not finite, as a float) is > 0 and > 16 x the median (lower middle) of its in-image
// neighbours' sums (none where one is not finite), that is no light, with a light within 2
// pixels (5x5) whose sum is above its own and a neighbour that is none, and at most 25 lights
// in its 9x9 window clipped to the image, takes per channel the
// median (lower middle) of its neighbours that are no lights, in the frame as given. A light:
// the sum finite and > 0, the channels' variances summed (in double) <= (0.01 x the sum)^2.
// Returns the pixels, in
// raster order; none where the variance has another size or channel count (1 or color's).
std::vector<size_t> CutLightRims(Image *color, const Image &variance);

// Bright clusters (host/common/local_mean.h, CutBrightClusters): the 8-connected groups of
// pixels whose channels' sum (as a float) is > 0 and > 16 x the median (lower middle) of
// their in-image neighbours' sums (none where one is not finite), joined by each pixel that
// is not such but has b >= 0.5 (below) and touches 2 or more such groups of 2 or more pixels
// within a 2x2 box whose every pixel has b >= 0.5. A group of 3 or more pixels within a 3x3
// box, each with n > 0 samples (the histograms' last channel) and b <= 0.3 n (b:
// the most samples in the last two bins over its colours), cluster sum k = round(sum b) >= 2,
// is cut when, with a = the sum of b (0 for pixels without samples) over the m pixels within
// searchHalf of the group's box but outside the box grown by 1 and t = max(k, round(k + a)),
// sum_{i >= k} C(t, i) s^i (1 - s)^(t - i) < 1e-4, s = size / (size + m), and a <= the sum of b
// over the group: each of its pixels takes per channel the median (lower middle) of its
// in-image neighbours outside the group in `input`. Returns the cut pixels in raster order,
// but those of a group holding a joining pixel, which go to `bridged` (if given) in raster
// order.
std::vector<size_t> CutBrightClusters(const Image &input, const Image &histograms,
                                      int searchHalf, Image *color,
                                      std::vector<size_t> *bridged = nullptr);

// Each output value clamped to input -+ k sqrt(max(variance, the mean of the variances of
// the 3x3 window clipped to the image but its largest one (0 for a 1x1 image))), per channel
// (the variance's one channel, or channel c), and not below 0 where the input is not
// negative; left where the input or the output is not finite. Where the pixel's variance is 0
// or a variance of the window is not finite or is negative, only a value below 0 whose input
// is not negative changes, to 0, on its own. The other channels a pixel bounds move to input
// + t (output - input), one t for the pixel: the largest that keeps every one of them in its
// range. Returns the number of values moved.
size_t BoundToNoise(const Image &input, const Image &variance, double k, Image *output);

// The bound's standard deviation of channel c (the variance's one channel, or channel c) at
// (x, y): the square root of the larger of the pixel's variance and its 3x3 window's
// (clipped to the image) mean without its largest value, the window summed in raster order
// less the largest; -1 where the pixel's variance is not above 0 or a variance of the
// window is not finite or is negative.
double NoiseSpread(const Image &variance, int c, int x, int y);

// Each output value held to [min - k s, max + k s], min and max over the finite input values
// of its channel in the (2 radius + 1)^2 window clipped to the image, widened by 1e-5 of the
// larger of |min| and |max|, s as BoundToNoise's
// spread over its k (the square root of the larger of the pixel's variance and its 3x3
// window's mean without the largest); the channels of a pixel whose variance is above 0, whose
// input and output are finite and whose window's variances are finite and not negative move
// to input + t (output - input), one t for the pixel: the largest that keeps every one of
// them in its range. Returns the number of values moved.
size_t BoundToInputRange(const Image &input, const Image &variance, int radius, double k,
                         Image *output);

// The frame's robust noise estimate (host/common/local_mean.h, FrameNoise): per channel
// z = color / a (a: the albedo's one channel or channel c, where > 0.02, else 1); per pixel
// e = min over the directions (0,1), (1,0), (1,1), (1,-1) with both neighbours inside of
// (z - (z_-d + z_+d) / 2)^2 / 1.5, over 0.0504 (4 directions) or 0.4549 (1), none where a
// difference is not finite; the variance is the median (lower middle) of the finite e of the
// clipped 5x5 window / 1.165 x a^2, 0 without any.
Image FrameNoise(const Image &color, const Image *albedo);

}  // namespace mcd::ref
