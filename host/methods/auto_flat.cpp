#include "host/methods/auto_flat.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "host/error.h"

namespace mcd {
namespace {

// Per pixel: |next right - this| + |next down - this| of each channel of `image` read by
// `value`, summed over the channels (0 past the last column and row).
template <typename Value>
std::vector<float> ForwardSteps(int w, int h, int channels, Value value) {
    std::vector<float> steps(size_t(w) * h, 0.f);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float sum = 0;
            for (int c = 0; c < channels; ++c) {
                const float v = value(c, y, x);
                if (x + 1 < w) sum += std::abs(value(c, y, x + 1) - v);
                if (y + 1 < h) sum += std::abs(value(c, y + 1, x) - v);
            }
            steps[size_t(y) * w + x] = sum;
        }
    return steps;
}

float MeanColour(const Image &image, int y, int x) {
    return (image.At(0, y, x) + image.At(1, y, x) + image.At(2, y, x)) / 3.f;
}

}  // namespace

AutoFlatResult AutoTakeNforWhereFlat(const Image &albedo, const Image &normal,
                                     const Image &nfor, const AutoFlatSettings &s,
                                     Image *output) {
    const int w = output->width, h = output->height;
    for (const Image *image : {&albedo, &normal, &nfor})
        if (image->width != w || image->height != h || image->channels < 3)
            throw Error("auto flat: the layers and the output differ in size or lack colour",
                        ErrorKind::Internal);
    if (output->channels < 3)
        throw Error("auto flat: the output lacks colour", ErrorKind::Internal);
    auto at = [](const Image &image) {
        return [&image](int c, int y, int x) { return image.At(c, y, x); };
    };
    std::vector<float> albedoSteps = ForwardSteps(w, h, 3, at(albedo));
    std::vector<float> normalSteps = ForwardSteps(w, h, 3, at(normal));
    std::vector<float> shadingSteps = ForwardSteps(w, h, 1, [&](int, int y, int x) {
        return std::log(std::max(MeanColour(*output, y, x), 0.f) + 0.01f);
    });
    std::vector<char> edge(size_t(w) * h);
    for (size_t i = 0; i < edge.size(); ++i)
        edge[i] = !(albedoSteps[i] + normalSteps[i] <= s.featureStep) ||
                  !(shadingSteps[i] <= s.shadingStep);
    // Flat: no edge within the 3x3 window; nfor agreeing there.
    std::vector<size_t> taken;
    double nforLight = 0, outputLight = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            bool flat = true;
            for (int v = std::max(y - 1, 0); v <= std::min(y + 1, h - 1) && flat; ++v)
                for (int u = std::max(x - 1, 0); u <= std::min(x + 1, w - 1); ++u)
                    if (edge[size_t(v) * w + u]) flat = false;
            if (!flat) continue;
            const float a = MeanColour(*output, y, x), n = MeanColour(nfor, y, x);
            if (!(std::abs(n - a) < s.agreement * (std::abs(a) + 0.01f))) continue;
            taken.push_back(size_t(y) * w + x);
            nforLight += n;
            outputLight += a;
        }
    AutoFlatResult result;
    result.pixels = taken.size();
    result.light = outputLight > 0 ? nforLight / outputLight : 0;
    result.taken = !taken.empty() && outputLight > 0 && result.light >= s.keep;
    if (!result.taken) return result;
    const size_t pixels = output->PixelCount();
    for (size_t i : taken)
        for (int c = 0; c < 3; ++c) output->data[c * pixels + i] = nfor.data[c * pixels + i];
    return result;
}

}  // namespace mcd
