// Squared-filter wavelet analysis of a variance image (AWR eq. 9 and 10, appendix B):
// var(sum_i h_i B_i) ~ sum_i h_i^2 var(B_i) for uncorrelated pixels, so the DWT of the
// per-pixel variance with every tap squared estimates the variance of every coefficient
// (scale and wavelet). Same layout and level structure as WaveletAnalyze.
#pragma once

#include "host/image.h"
#include "host/wavelet.h"

namespace mcd::ref {

// Every squared 1D low-pass (high-pass) filter is rescaled to sum to lowSum (highSum); a
// value <= 0 keeps its natural sum (AWR section 4.1 renormalises the low-pass to 1.05).
// Haar: (v[2n] + v[2n+1]) / 2 for both filters at natural sums, an unpaired v stays v.
// Throws mcd::Error unless 0 <= levels <= MaxWaveletLevels.
Image WaveletSqAnalyze(const Image &variance, WaveletBasis basis, int levels, double lowSum = 0,
                       double highSum = 0);

}  // namespace mcd::ref
