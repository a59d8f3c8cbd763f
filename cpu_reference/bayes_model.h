// Method `bayes` (Xu & Pattanaik), the CPU reference of the statistical model: generalised
// Laplacian moments (eq. 16), the per-band moment solver (eqs. 12, 17-18) and the
// posterior mean (eq. 11) by direct discrete integration, all in double. Shares no code
// with the GPU path (constants only, from shaders/bayes/bayes.h).
#pragma once

#include <cstdint>

namespace mcd::ref {

// Second and fourth moments of f(x; s, p) = exp(-|x/s|^p) / Z (eq. 16).
double GlSecondMoment(double s, double p);
double GlFourthMoment(double s, double p);
// Kurtosis E[x^4] / E[x^2]^2 = Gamma(5/p) Gamma(1/p) / Gamma(3/p)^2 (independent of s,
// decreasing in p: 25.2 at p = 0.5, 6 at 1, 3 at 2), through lgamma.
double GlKurtosis(double p);

struct BandFit {
    int fit = 0;  // BAYES_FIT_*
    double sc = 0, pc = 0;
};

// (s_c, p_c) from the band's E[y^2], E[y^4] and the noise (s_n, p_n), eqs. 17-18:
// sigma_c^2 = m2 - sigma_n^2; m4_c = m4 - m4_n - 6 sigma_c^2 sigma_n^2; p_c by bisection of
// the (monotone) kurtosis m4_c / sigma_c^4 over [BAYES_P_LO, BAYES_P_HI]; s_c from sigma_c^2.
// Fallbacks (never NaN): m2 <= sigma_n^2 (1 + BAYES_MIN_SIGNAL_FRACTION) -> NO_SIGNAL;
// kurtosis above the bracket's -> P_LOW, below it or m4_c <= 0 -> P_HIGH; s_n == 0 ->
// NO_NOISE
// (s_n < BAYES_MIN_NOISE_S, which 0 is); count == 0 -> EMPTY. Non-finite moments are NO_SIGNAL.
BandFit SolveBand(double m2, double m4, int64_t count, double sn, double pn);

// Posterior mean c^(y) of eq. 11 for the band's fit: for NO_SIGNAL 0, NO_NOISE y; otherwise
// the ratio of int c pn(y-c) pc(c) dc to int pn(y-c) pc(c) dc by the midpoint rule on the
// grid c = a sinh(t), a = min(s_n, s_c), t uniform over [asinh(-R/a), asinh((|y|+R)/a)],
// R = max(s_n T^(1/p_n), s_c T^(1/p_c)), T = BAYES_TAIL (beyond it every term is below
// exp(-T) of the peak), with step dt = min(1/S, s_n / (S (|y| + s_n T^(1/p_n) + a))),
// S = BAYES_STEPS_PER_WIDTH, so the spacing is at most s_n/S over [0, y] and a/S near 0
// (the posterior's peak lies in [0, y] and is no narrower than those); point count clamped to
// [BAYES_MIN_POINTS, BAYES_MAX_POINTS]. Sums by log-sum-exp (two passes): no 0/0.
// Odd: c^(-y) = -c^(y).
double PosteriorMean(double y, const BandFit &fit, double sn, double pn);

}  // namespace mcd::ref
