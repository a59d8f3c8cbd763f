// Frames built from layers for the tests that run a method through the library.
#pragma once

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

}  // namespace mcd::test
