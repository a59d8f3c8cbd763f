// Wavelet synthesis of the CPU reference: the inverse of wavelet_analyze.h, written as
// plain convolutions of the synthesis taps with the coefficients, in double precision.
// Levels are undone coarsest first; inside a level, columns then rows.
#pragma once

#include <span>
#include <vector>

#include "cpu_reference/wavelet_filters.h"
#include "host/image.h"
#include "host/wavelet.h"

namespace mcd::ref {

// One 1D synthesis step from c = [s_0..s_{nLow-1}, d_0..d_{nHigh-1}]:
// x[p] = sum over positions q, |q-p| within the tap's filter, of g0[|p-q|] s[Ext(q)/2]
// (q even) or g1[|p-q|] d[(Ext(q)-1)/2] (q odd) (Haar: pairs, see FilterBank).
std::vector<double> Synthesize1D(std::span<const double> c, WaveletBasis basis,
                                 const FilterBank &bank);
std::vector<double> Synthesize1D(std::span<const double> c, WaveletBasis basis);

// Multi-level synthesis of one [y][x] coefficient plane, all in double.
std::vector<double> SynthesizePlane(std::span<const double> coefficients, int width, int height,
                                    WaveletBasis basis, const FilterBank &bank, int levels);
std::vector<double> SynthesizePlane(std::span<const double> coefficients, int width, int height,
                                    WaveletBasis basis, int levels);

// Multi-level synthesis of every channel with `bank`, in double, rounded to float at the
// end. Throws mcd::Error unless 0 <= levels <= MaxWaveletLevels.
Image SynthesizeImage(const Image &coefficients, WaveletBasis basis, const FilterBank &bank,
                      int levels);

// The inverse DWT of `levels` levels.
Image WaveletSynthesize(const Image &coefficients, WaveletBasis basis, int levels);

// The same loops with |taps| on |coefficients|: a bound on the scale of float32 round-off.
Image WaveletSynthesizeMagnitude(const Image &coefficients, WaveletBasis basis, int levels);

}  // namespace mcd::ref
