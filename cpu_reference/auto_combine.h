// The auto method's combination of candidate denoisers, the CPU reference: Stein's unbiased
// risk estimate of each candidate's per-pixel error with a Monte Carlo divergence (Stein
// 1981; Ramani, Blu and Unser 2008, eq. 8: div f ~ b . (f(y + eps b) - f(y)) / eps), its
// box mean, and the per-pixel weights (or selection) by the estimates. Plain loops in
// double; nothing is shared with the GPU path.
#pragma once

#include <vector>

#include "host/image.h"

namespace mcd::ref {

// relMSE's offset (the metric's "+ 0.01").
constexpr double kAutoRelOffset = 0.01;

// One plane: the mean over channels of
//   [(f - y)^2 - v + o + 2 sqrt(max(v, 0)) b (fp - f) / epsilon] / d,
//   d = max(g^2 + 0.01, max(v, 0) / noiseCap)  (g^2 + 0.01 when noiseCap is 0),
// an unbiased estimate (over the noise and b) of (f - r)^2 / (g^2 + 0.01) for y = r +
// noise of variance v, f = F(y), fp = F(y + epsilon sqrt(v) b), b = +-1, to first order in
// epsilon; g (the guide) stands in for the unknown r in relMSE's denominator, the same for
// every candidate. The denominator's floor v / noiseCap bounds the estimate's own noise,
// which is of the order of v / d, at noiseCap; it weighs the pixels the same for every
// candidate. The offset o (0 without `offset`) makes it the estimate for an f that is not
// a function of y alone: for f = D + G(I), y = D + I (Xu and Pattanaik's split, the
// direct part kept), E[(f - r)^2] = E[(f - y)^2] - v + 2 Cov(f, y), and Cov(f, y) =
// Cov(D, y) + Cov(G(I), y) = (v - c) + c E[G'(I)] with c = Cov(I, y) (Stein's lemma for
// jointly Gaussian I, y): so o = 2 (v - c), and fp = D + G(I + epsilon (c / sqrt(v)) b)
// makes the divergence term 2 c G'.
Image AutoEstimate(const Image &color, const Image &variance, const Image &probe,
                   const Image &guide, const Image &output, const Image &perturbed,
                   double epsilon, double noiseCap, const Image *offset = nullptr);

// The variance of the pixel mean estimated from a frame without sample statistics, per
// channel: z = y / a with a the albedo (its one channel, or channel c) where a > 0.02, else
// 1 (and 1 everywhere without an albedo); at each pixel the smallest over the directions
// (1,0), (0,1), (1,1), (1,-1) whose two neighbours are in the image of r^2 / 1.5, r = z -
// (z_-d + z_+d) / 2 (the variance of r is 1.5 v_z for noise of locally constant variance
// v_z; along an edge the step cancels, a firefly is large in every direction), over its
// mean for unit Gaussian noise (0.27848 for the minimum of 4 directions inside the image,
// 1 for the one direction of the border rows and columns); the mean of those over the
// (2 radius + 1)^2 window clipped to the image (finite values only), times a^2 at the
// pixel; 0 where the window has no finite value.
Image AutoNoise(const Image &color, const Image *albedo, int radius);

// Per plane, the mean of the finite values over the (2 radius + 1)^2 window clipped to the
// image, each weighted by the tent (radius + 1 - |u - x|)(radius + 1 - |v - y|); NaN where
// the window has none.
Image AutoSmooth(const Image &errors, int radius);

// The guide's relative colour distance between pixels (y, x) and (v, u): the mean over its
// channels of (a - b)^2 / (a^2 + b^2 + 0.01), each channel's term 0 where it is not finite or
// where the kernel's float squares overflow.
double AutoGuideDistance(const Image &guide, int y, int x, int v, int u);

// As AutoSmooth, each tent weight times exp(-min(AutoGuideDistance / bandwidth^2, 40)) (guide:
// the errors' size, any channels): the windows keep to pixels of the guide's colour, so that
// estimates are not mixed across the edges where the candidates' errors change.
Image AutoSmoothGuided(const Image &errors, const Image &guide, int radius, double bandwidth);

struct AutoCombined {
    Image color;    // C planes
    Image weights;  // K planes, summing to 1 (or all 0 where the input is kept)
};

// candidates[k] (C planes each), errors (K planes). Weights: max(e_k, floorError)^-power,
// select: 1 for the smallest e_k (the first on ties); 0 for a candidate whose estimate or
// output is not finite at the pixel; where every weight is 0 the input color is kept. With
// medianUnderFloor, where every usable estimate is under floorError (all weigh the same)
// the output is the per-channel median of the usable candidates instead of their mean.
AutoCombined AutoCombine(const Image &color, const std::vector<Image> &candidates,
                         const Image &errors, bool select, double power, double floorError,
                         bool medianUnderFloor = false);

// The relative combination: weights w_k = max(e_k, floorError)^-power over the usable
// candidates (as AutoCombine), equal instead where every usable e_k is under the floor or
// the mean over channels of variance / (u^2 + 0.01) exceeds noiseLimit, u the value below
// with equal weights. Per channel the output minimises sum_k w_k (f - c_k)^2 / (c_k^2 +
// 0.01), relMSE's term with candidate k standing for the reference:
// f = sum_k w_k c_k / (s_k + 0.01) / sum_k w_k / (s_k + 0.01), s_k = max(c_k^2, m^2 /
// darkLimit) with m the weighted mean (s_k = c_k^2 for u, and where the noise ratio made
// the weights equal), the weighted mean where that sum is 0 or beyond a float (a value
// whose square is beyond a float weighs nothing there, as in the kernel's float
// arithmetic). The weights returned are the ones used; where they are 0 (not equal, and
// their total 0 or beyond a float) the input is kept.
AutoCombined AutoCombineRelative(const Image &color, const std::vector<Image> &candidates,
                                 const Image &errors, const Image &variance, double power,
                                 double floorError, double noiseLimit, double darkLimit);

}  // namespace mcd::ref
