// Auto stage 1: a per-pixel estimate of a candidate's relative squared error, without the
// reference, by Stein's unbiased risk estimate (SURE) with a Monte Carlo divergence
// (Ramani, Blu and Unser 2008): with y the noisy color, v the variance of its mean, f the
// candidate's output on y and fp its output on y + eps sqrt(v) b (b = +-1 per value),
//   e = (1/C) sum_c [(f - y)^2 - v + o + 2 sqrt(v) b (fp - f) / eps] / d,
//   d = max(g^2 + 0.01, v / cap)  (d = g^2 + 0.01 when cap is 0),
// g a guide for the unknown reference in relMSE's denominator (the same for every
// candidate); cap bounds v / d, the size of the estimate's own noise at the pixel, so that
// one pixel whose mean is pure noise (a light seen by one sample) cannot swamp a window.
// o is 0 for a candidate that is a function of y alone. For bayes's split output
// f = D + g(I), y = D + I, it is 2 (v - c) with c = Cov(I, y), and fp is the output with
// I perturbed by eps (c / sqrt(v)) b: then E[e d] = E[(f - r)^2] by Stein's lemma on I
// (host/api/method_auto.cpp).
// One invocation per pixel; the output has one plane.
#ifndef MCD_SHADERS_AUTO_ESTIMATE_H
#define MCD_SHADERS_AUTO_ESTIMATE_H

#include "auto/auto.h"

#define AUTO_ESTIMATE_COLOR 0
#define AUTO_ESTIMATE_VARIANCE 1
#define AUTO_ESTIMATE_PROBE 2
#define AUTO_ESTIMATE_OUTPUT 3
#define AUTO_ESTIMATE_PERTURBED 4
#define AUTO_ESTIMATE_ERROR 5
#define AUTO_ESTIMATE_GUIDE 6
#define AUTO_ESTIMATE_OFFSET 7
#define AUTO_ESTIMATE_BINDINGS 8

#ifdef __cplusplus
#include <cstddef>
namespace mcd::shader {
struct AutoEstimatePush {
#else
layout(push_constant) uniform AutoEstimatePush {
#endif
    int width;
    int height;
    int channels;
    // The perturbation's size in standard deviations of the mean (> 0).
    float epsilon;
    // The largest v / d (>= 0; 0: no bound).
    float noiseCap;
#ifdef __cplusplus
};
static_assert(sizeof(AutoEstimatePush) == 20);
static_assert(offsetof(AutoEstimatePush, epsilon) == 12);
static_assert(offsetof(AutoEstimatePush, noiseCap) == 16);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
