// Restoring an input's local means after a method that biases them (beyond the papers):
// each output value is multiplied by m_in / m_out, the means of the input's finite values
// >= 0 and of the output over a tent window of radius 2r (a box of radius r twice, each
// clipped to the image), where both are positive and finite; values equal to the input's
// (the method left them: an emitter, a zero kept) count in neither mean and stay. A
// method that darkens an area (bayes's log domain, pivot's robust fits, auto's relative
// combination) gets its local brightness back at scales above the window; within it the
// method's own shape stays.
#pragma once

#include "host/image.h"

namespace mcd {

// Each plane's mean over the tent window of radius 2r around each pixel.
Image TentMean(const Image &image, int r);

// The factors applied, smallest and largest (1 and 1 where none was).
struct LocalMeanFactors {
    double lo = 1, hi = 1;
};

// `output` (the shape of `input`) scaled to `input`'s local means; r > 0.
LocalMeanFactors RestoreLocalMeans(const Image &input, int r, Image *output);

}  // namespace mcd
