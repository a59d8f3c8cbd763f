// Frames built from layers for the tests that run a method through the library.
#pragma once

#include <functional>
#include <string>

#include "host/image.h"
#include "mcdenoise/mcdenoise.h"
#include "tools/render/renderer.h"

namespace mcd::test {

// A frame of a colour and its variance layer, what awr reads.
inline Frame ColorAndVariance(const Image &color, const Image &variance) {
    Frame frame;
    frame.width = color.width, frame.height = color.height;
    frame.layers["color"] = color;
    frame.layers["variance"] = variance;
    return frame;
}

// The built-in `scene` rendered with `options`, every layer it wrote in the frame.
Frame RenderedFrame(const std::string &scene, const render::RenderOptions &options);

// A frame of `spp` samples a pixel whose samples `sample(x, y, s)` gives (the same value in
// every colour), with rhf's histograms of 20 bins a colour and the variance of the mean as the
// renderer writes them.
Frame SampledFrame(int w, int h, const std::function<double(int, int, int)> &sample,
                   int spp = 16);

// How many of 16 samples a light's reflection in chrome gives the pixel at (dx, dy) from it:
// 1 and 2 in its row, 1 and 3 below (as glossy_lights' sphere reflects a bulb), else 0.
int ReflectionSamplesAt(int dx, int dy);

// A flat floor of 0.0133 a colour whose 16 samples a pixel fell in the second of rhf's 20
// bins a colour (the count last), on which Bright() gives a pixel bright samples.
struct HistogramFloor {
    static constexpr int kBins = 20;
    HistogramFloor(int w, int h);
    // Give (x, y) `samples` of its 16 in the last bin and the colour `value`.
    void Bright(int x, int y, float samples, float value);
    Image color, hist;
};

}  // namespace mcd::test
