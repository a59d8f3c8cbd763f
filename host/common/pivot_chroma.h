// Fits that tint a pixel (beyond the papers). pivot fits z = colour / pivot per channel, and
// where a shading edge the pivot does not show crosses a square, or a pixel's few samples all
// missed the light, one channel's fit can fall far from the others': the pixel comes out
// tinted though its neighbours and its own input agree on a colour. Such a pixel keeps the
// fit's brightness (its channels' sum) and takes the chroma of its window's input.
#pragma once

#include <cstddef>

#include "host/image.h"

namespace mcd {

// The window: the (2 kPivotChromaRadius + 1)^2 pixels around p within the image of p's
// object and part ids (when given), each with every colour, variance and pivot value finite
// and no variance or pivot value below 0. Its expected colour e_c = P_c(p) x sum C_c / sum
// P_c over the window (the ratio of sums: z's mean, no small pivot dividing), its variance
// P_c(p)^2 x sum V_c / (sum P_c)^2. The chroma's noise (rgb over its sum, linearised) summed
// over channels is its allowance. With every sum above 0, a pixel's weight is the product of
// three ramps, each linear between its two thresholds so that no pixel flips on a hair: its
// output's chroma off the window's (L1) by kPivotChromaFit allowances (0) to
// kPivotChromaFitFull (1); the window standing for the pixel: its input's chroma (where lit)
// off the window's by kPivotChromaAgree (1) to kPivotChromaAgreeNone (0) of the input's own
// allowances, and its input's sum off the window's by as many standard deviations (unless
// the input has variance 0).
constexpr int kPivotChromaRadius = 2;
constexpr double kPivotChromaFit = 1.5, kPivotChromaFitFull = 5;
constexpr double kPivotChromaAgree = 2, kPivotChromaAgreeNone = 4;

// A pixel of weight above 0 moves by its weight toward its channels' sum times the window's
// chroma, where every channel of that is at least 0 and, with `bound` > 0, within `bound`
// standard deviations of its input (NoiseSpread, as BoundToNoise holds the fits; unless the
// spread is unknown); pixels whose output is their input in every channel (kept values) and
// frames of one channel stay.
// `pivot` and `variance` have the colour's size and 1 or its channels; the ids one channel
// or none. Returns the pixels moved.
size_t KeepWindowChroma(const Image &color, const Image &pivot, const Image &variance,
                        const Image *objectId, const Image *partId, double bound,
                        Image *output);

}  // namespace mcd
