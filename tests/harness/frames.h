// Frames built from layers for the tests that run a method through the library.
#pragma once

#include <functional>

#include "host/image.h"
#include "mcdenoise/mcdenoise.h"

namespace mcd::test {

// A frame of a colour and its variance layer, what awr reads.
inline Frame ColorAndVariance(const Image &color, const Image &variance) {
    Frame frame;
    frame.width = color.width, frame.height = color.height;
    frame.layers["color"] = color;
    frame.layers["variance"] = variance;
    return frame;
}

// A frame of `spp` samples a pixel whose samples `sample(x, y, s)` gives (the same value in
// every colour), with rhf's histograms of 20 bins a colour and the variance of the mean as the
// renderer writes them.
Frame SampledFrame(int w, int h, const std::function<double(int, int, int)> &sample,
                   int spp = 16);

}  // namespace mcd::test
