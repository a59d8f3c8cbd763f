// Means over a squared tent along the rows or the columns of a plane (the restore's noise,
// local_mean.h), each value a function of its window alone, whatever the way it is computed.
#pragma once

namespace mcd {

// out (w x h) = each value's mean over the 4s + 1 values along its row around it (s >= 1),
// weighted by the squared tent (2s + 1 - |d|)^2 at offset d and clipped to the plane: the
// weighted sum rounded to double, over the clipped weights' sum. Where the window's values
// are finite and their exponents close enough (SquaredTentExact) the sum is exact: integers
// of 128 bits in units of the smallest value's last place, and along a line whose windows all
// are, three running sums of the squared tent's third difference (six taps), so a value
// costs a few operations whatever s. Other windows are summed one by one in double from
// their first value. Either way a value depends on its window alone, so a tile gives the
// whole frame's values. Lines split over threads.
void SquaredTentMeanRows(const float *in, float *out, int w, int h, int s);

// The same down the columns.
void SquaredTentMeanColumns(const float *in, float *out, int w, int h, int s);

// Whether the `count` values at `values` are summed exactly over a squared tent of radius
// 2s: all finite, the largest's exponent within the bound for s of the smallest non-zero's.
bool SquaredTentExact(const float *values, int count, int s);

}  // namespace mcd
