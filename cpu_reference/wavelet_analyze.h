// Wavelet analysis of the CPU reference: the DWT written as plain convolutions (filter taps
// times samples) in double precision, from AWR section 3 and appendix A. It is the oracle
// for the GPU wavelet kernels and shares no code with them.
//
// Layout (host/wavelet.h): along an axis of length N > 1, the ceil(N/2) low-pass
// coefficients come first, then the floor(N/2) high-pass ones; N == 1 is passed through.
// Each level transforms rows, then columns, of the top-left LevelExtent(w, k) x
// LevelExtent(h, k) region (Mallat). Channels are independent.
#pragma once

#include <span>
#include <vector>

#include "cpu_reference/wavelet_filters.h"
#include "host/image.h"
#include "host/wavelet.h"

namespace mcd::ref {

// One 1D analysis step of x: returns [s_0..s_{nLow-1}, d_0..d_{nHigh-1}] with
// s[n] = sum_k h0[|k|] x[Ext(2n+k)], d[n] = sum_k h1[|k|] x[Ext(2n+1+k)] (Haar: pairs, see
// FilterBank). `bank` may be a transformed bank (absolute or squared taps).
std::vector<double> Analyze1D(std::span<const double> x, WaveletBasis basis,
                              const FilterBank &bank);
std::vector<double> Analyze1D(std::span<const double> x, WaveletBasis basis);

// Multi-level analysis of one [y][x] plane, all in double.
std::vector<double> AnalyzePlane(std::span<const double> plane, int width, int height,
                                 WaveletBasis basis, const FilterBank &bank, int levels);
std::vector<double> AnalyzePlane(std::span<const double> plane, int width, int height,
                                 WaveletBasis basis, int levels);

// Multi-level analysis of every channel with `bank`, in double, rounded to float at the end.
// Throws mcd::Error unless 0 <= levels <= MaxWaveletLevels.
Image AnalyzeImage(const Image &in, WaveletBasis basis, const FilterBank &bank, int levels);

// The forward DWT, `levels` levels deep.
Image WaveletAnalyze(const Image &in, WaveletBasis basis, int levels);

// The same loops with |taps| on |in|: every output is sum |h| |x| over its support, composed
// over the levels, a bound on the scale of float32 round-off in that coefficient.
Image WaveletAnalyzeMagnitude(const Image &in, WaveletBasis basis, int levels);

}  // namespace mcd::ref
