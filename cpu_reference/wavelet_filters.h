// Wavelet filter banks of the CPU reference, written from AWR appendix A (Overbeck et al.
// 2009): LeGall 5/3 and CDF (Daubechies) 9/7, plus Haar. Double precision; the GPU lifting
// path is diffed against convolutions with these taps and never reads them.
#pragma once

#include <vector>

#include "host/wavelet.h"

namespace mcd::ref {

// One biorthogonal filter bank.
//
// LeGall53, Cdf97: symmetric odd-length filters stored as half filters, index 0 is the
// centre tap and tap k is also tap -k (as printed in appendix A). Low-pass coefficient n is
// centred on sample 2n, high-pass coefficient n on sample 2n+1.
//
// Haar: the two taps that act on the pair (2n, 2n+1), in that order, not half filters:
// analysisLow = {1, 1}/sqrt2, analysisHigh = {-1, 1}/sqrt2, and the synthesis taps give
// x[2n] = synthesisLow[0] s + synthesisHigh[0] d, x[2n+1] = synthesisLow[1] s +
// synthesisHigh[1] d. An unpaired last sample (odd length) is extended half-sample
// symmetrically: x[N] = x[N-1].
struct FilterBank {
    std::vector<double> analysisLow, analysisHigh, synthesisLow, synthesisHigh;
};

const FilterBank &GetFilterBank(WaveletBasis basis);

// Sum of all taps of the full filter that `taps` describes in `basis`'s storage.
double FullFilterSum(const std::vector<double> &taps, WaveletBasis basis);

// The bank with every tap replaced by its absolute value (for round-off bounds).
FilterBank AbsoluteFilterBank(const FilterBank &bank);

// The bank with every tap squared (AWR eq. 9-10, appendix B). The squared analysis low
// (high) filter is rescaled to sum to lowSum (highSum); a value <= 0 keeps its natural sum.
// Synthesis taps are squared without rescaling.
FilterBank SquaredFilterBank(const FilterBank &bank, WaveletBasis basis, double lowSum = 0,
                             double highSum = 0);

// Whole-sample symmetric (mirror-periodic, period 2(n-1)) extension: maps any integer
// position p to [0, n-1], keeping its parity. Needs n >= 2.
int MirrorIndex(int p, int n);

// Throws mcd::Error unless 0 <= levels <= MaxWaveletLevels(width, height).
void CheckWaveletLevels(int width, int height, int levels, const char *caller);

}  // namespace mcd::ref
