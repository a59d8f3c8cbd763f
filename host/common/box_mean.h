// Box means down the columns of a plane, each window's sum the one of its values added in
// order in double, whatever the way it is computed.
#pragma once

namespace mcd {

// out (w x h) = the means over windows of radius r down the columns of in, clipped to the
// plane: each the sum of the window's values in order from its top, in double, divided by
// their count, so a pixel's mean does not depend on where the plane starts. Where every
// partial sum of a column over the rows a band of windows reads is exact in double (finite
// values whose absolute sum is far below 2^53 units in the last place of the smallest
// non-zero one) the sums slide down the band, adding a row and taking one out: exact, hence
// the same bits, in a fraction of the time. Bands split over threads.
void BoxMeanColumns(const float *in, float *out, int w, int h, int r);

// The same along the rows (each window summed in order from its left; where the sums of the
// values a segment of a row's windows reads are exact, those windows' sums are differences
// of prefix sums): the bits of BoxMeanColumns on the transposed plane.
void BoxMeanRows(const float *in, float *out, int w, int h, int r);

}  // namespace mcd
