// The stationary (undecimated, "a trous") wavelet transform of the CPU reference, written
// from its definition (shaders/wavelet/swt.h gives the layout): at level j the DWT's
// filter taps (cpu_reference/wavelet_filters.h) spread 2^j apart, no decimation, plain
// convolutions in double; the inverse averages the two polyphase DWT reconstructions.
// Shares no code with the GPU kernels.
#pragma once

#include <span>
#include <vector>

#include "cpu_reference/wavelet_filters.h"
#include "host/image.h"
#include "host/wavelet.h"

namespace mcd::ref {

// Whether an axis of length n is transformed at `level`: while the level's tap spacing
// 2^level is still shorter than the axis (else its high band is empty, as the DWT's).
bool SwtAxisTransformed(int n, int level);

// One 1D analysis step of x with holes `step`: low and high bands of x's length. When
// `transform` is false, low = x and high = 0. `bank` may be squared or absolute.
void SwtAnalyze1D(std::span<const double> x, WaveletBasis basis, const FilterBank &bank,
                  int step, bool transform, std::vector<double> *low,
                  std::vector<double> *high);

// The inverse of SwtAnalyze1D: x(m) = 1/2 sum_k (g0[k] L(m - k step) + g1[k] H(m - k step));
// Haar: the mean of the reconstructions from the pairs at m and m - step (the first alone
// for m < step). When `transform` is false, x = low. `bank` may be absolute.
std::vector<double> SwtSynthesize1D(std::span<const double> low, std::span<const double> high,
                                    WaveletBasis basis, const FilterBank &bank, int step,
                                    bool transform);

// Multi-level 2D analysis of one [y][x] plane: 3 levels + 1 planes of width x height in the
// order of shaders/wavelet/swt.h (detail planes level by level, the low plane last).
std::vector<std::vector<double>> SwtAnalyzePlane(std::span<const double> plane, int width,
                                                 int height, WaveletBasis basis,
                                                 const FilterBank &bank, int levels);
// And its inverse.
std::vector<double> SwtSynthesizePlane(const std::vector<std::vector<double>> &planes,
                                       int width, int height, WaveletBasis basis,
                                       const FilterBank &bank, int levels);

// Every channel: an image of channels (3 levels + 1) planes, rounded to float at the end.
// Throws mcd::Error unless 0 <= levels <= MaxWaveletLevels.
Image SwtAnalyzeImage(const Image &in, WaveletBasis basis, const FilterBank &bank, int levels);
Image WaveletSwtAnalyze(const Image &in, WaveletBasis basis, int levels);
// Squared taps at their natural sums: per-coefficient noise variance from a per-pixel
// variance of independent pixels (sum h^2 var), composed over the levels like the DWT's.
Image WaveletSwtSqAnalyze(const Image &variance, WaveletBasis basis, int levels);
// |taps| on |in|: the scale of float32 round-off in every coefficient.
Image WaveletSwtAnalyzeMagnitude(const Image &in, WaveletBasis basis, int levels);

// The inverse of WaveletSwtAnalyze: coefficients of channels (3 levels + 1) planes back to
// `channels` planes. Throws mcd::Error when the plane count does not match.
Image SwtSynthesizeImage(const Image &coefficients, WaveletBasis basis, const FilterBank &bank,
                         int levels);
Image WaveletSwtSynthesize(const Image &coefficients, WaveletBasis basis, int levels);
Image WaveletSwtSynthesizeMagnitude(const Image &coefficients, WaveletBasis basis, int levels);

}  // namespace mcd::ref
