// Ray Histogram Fusion (Delbracio et al., IPOL 2015) step by step, the CPU reference of
// the GPU kernels that split Algorithm 2 and 3 into passes: the chi-square terms of one
// pixel pair (eq. 3 with the counts), patch distances summed from stored pair terms, the
// aggregation of eqs. 6-7 from a given selection, and the recombination of Algorithm 3.
// Written from the paper in double; the storage layouts are the kernels' (shaders/rhf/*.h),
// the arithmetic is not shared.
#pragma once

#include "host/image.h"

namespace mcd::ref {

// What pixel pair (p, q) adds to the chi-square distance: over the 3n bins i whose
// h_p[i] + h_q[i] > 1 (both counts n_p, n_q non-zero), the sum of
// (n_q h_p[i] - n_p h_q[i])^2 / (n_p n_q (h_p[i] + h_q[i])) and how many were counted.
// With brightVeto > 0 the pair is vetoed when its counted terms in the saturated bins (the
// last two of each colour) sum to more than brightVeto 2 n_p n_q / (n_p + n_q).
struct RhfPairTerms {
    double sum = 0;
    int counted = 0;
    bool vetoed = false;
    // The veto's two sides (saturated terms, bound), for telling near-ties apart.
    double saturated = 0, vetoBound = 0;
    // sum over the counted bins of term + 2 |d| (n_q h_p + n_p h_q + |d|) / den: the scale of
    // float round-off in `sum` (d = n_q h_p - n_p h_q cancels).
    double magnitude = 0;
};

// `hist`: 3n + 1 channels (the bins, then the count), as the kernels read them (scaled).
RhfPairTerms RhfPixelPairTerms(const Image &hist, int px, int py, int qx, int qy,
                               double brightVeto);

// Patch distances from stored pair terms: `sum` and `count` hold, for every pixel p and
// offset o = (dx, dy) with 0 <= dy <= b, |dx| <= b, the terms of pair (p, p + o) in channel
// dy (2b + 1) + dx + b (count -1: vetoed); a pair with dy < 0 is pair (p + o, p) of offset
// -o. Returns (2b + 1)^2 channels, (dy + b)(2b + 1) + dx + b: for centre p, the sums of the
// pairs (p + t, p + o + t) over the patch |t| <= w0 = min(w, distance to the edge), the
// first over the second + 1e-4; -1 where the candidate's patch leaves the image or a pair
// of it is vetoed.
Image RhfDistancesFromTerms(const Image &sum, const Image &count, int searchHalf,
                            int patchHalf);

// Eqs. 6-7 from a selection: `selected` has (2b + 1)^2 channels as RhfDistancesFromTerms
// returns, non-zero where centre p selects the candidate patch at p + o. Each centre's patch
// (half-size w0 = min(w, distance to the edge)) estimates its pixels by the mean of its
// selected candidates at the same place; every pixel is the mean of the estimates of the
// patches that cover it and select something, or keeps its value when none does.
Image RhfAggregate(const Image &color, const Image &selected, int searchHalf, int patchHalf);

// Algorithm 3, line 10: filtered - U(low) + U(coarse), U the bicubic upsampler onto
// filtered's grid (RhfBicubicUpsample).
Image RhfCombine(const Image &filtered, const Image &low, const Image &coarse);

}  // namespace mcd::ref
