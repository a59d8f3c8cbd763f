// Helpers the object floor's and the object lift's tests share: an object's luminance sum,
// a small cornell frame with or without ids, and a search of a run's plan.
#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "harness/frames.h"
#include "host/image.h"
#include "mcdenoise/mcdenoise.h"
#include "tools/render/renderer.h"

namespace mcd::test {

// Rec. 709 luminance of pixel i's first three channels.
inline double PixelLuminance(const Image &image, size_t i) {
    const size_t pixels = image.PixelCount();
    return 0.2126 * image.data[i] + 0.7152 * image.data[pixels + i] +
           0.0722 * image.data[2 * pixels + i];
}

// The luminance summed over the pixels of `ids` equal to id, and the sum of its magnitude.
inline std::pair<double, double> ObjectSum(const Image &image, const Image &ids, float id) {
    double sum = 0, magnitude = 0;
    for (size_t i = 0; i < image.PixelCount(); ++i)
        if (ids.data[i] == id) {
            sum += PixelLuminance(image, i);
            magnitude += std::abs(PixelLuminance(image, i));
        }
    return {sum, magnitude};
}

// A 32x24 cornell frame of 8 spp with every layer, its objectId layer only where `ids`.
inline Frame RenderCornell(bool ids) {
    render::RenderOptions options;
    options.width = 32, options.height = 24, options.spp = 8;
    options.layers = render::kLayersAll;
    Frame frame = RenderedFrame("cornell", options);
    if (!ids) frame.layers.erase("objectId");
    return frame;
}

// Whether a line of the run's plan holds `text`.
inline bool PlanHas(const Result &result, const std::string &text) {
    return std::any_of(result.plan.begin(), result.plan.end(), [&](const std::string &line) {
        return line.find(text) != std::string::npos;
    });
}

}  // namespace mcd::test
