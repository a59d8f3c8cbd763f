// Frames built from samples (harness/frames.h).
#include "harness/frames.h"

#include <algorithm>
#include <vector>

#include "host/io/accumulate.h"

namespace mcd::test {

Frame RenderedFrame(const std::string &scene, const render::RenderOptions &options) {
    render::RenderResult rendered = render::Render(render::BuildScene(scene), options);
    Frame frame;
    frame.width = options.width, frame.height = options.height;
    for (auto &[name, image] : rendered.layers) frame.layers[name] = std::move(image);
    return frame;
}

Frame SampledFrame(int w, int h, const std::function<double(int, int, int)> &sample, int spp) {
    const int bins = 20;
    Image color(w, h, 3), variance(w, h, 3), hist(w, h, 3 * bins + 1);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            double sum = 0, squares = 0;
            std::vector<float> pixelHist(3 * bins, 0.f);
            for (int s = 0; s < spp; ++s) {
                const double v = sample(x, y, s), rgb[3] = {v, v, v};
                io::AddToRhfHistogram(rgb, bins, pixelHist.data());
                sum += v, squares += v * v;
            }
            const double mean = sum / spp;
            for (int c = 0; c < 3; ++c) {
                color.At(c, y, x) = float(mean);
                variance.At(c, y, x) =
                    float(std::max(0.0, (squares / spp - mean * mean) / (spp - 1)));
            }
            for (int i = 0; i < 3 * bins; ++i) hist.At(i, y, x) = pixelHist[i];
            hist.At(3 * bins, y, x) = float(spp);
        }
    Frame frame(w, h);
    frame.SetLayer("color", color);
    frame.SetLayer("hist", hist);
    frame.SetLayer("variance", variance);
    return frame;
}

int ReflectionSamplesAt(int dx, int dy) {
    if (dy == 0) return dx == 0 ? 1 : dx == 1 ? 2 : 0;
    if (dy == 1) return dx == -1 ? 1 : dx == 0 ? 3 : 0;
    return 0;
}

HistogramFloor::HistogramFloor(int w, int h)
    : color(w, h, 3, 0.0133f), hist(w, h, 3 * kBins + 1) {
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            for (int c = 0; c < 3; ++c) hist.At(c * kBins + 1, y, x) = 16;
            hist.At(3 * kBins, y, x) = 16;
        }
}

void HistogramFloor::Bright(int x, int y, float samples, float value) {
    for (int c = 0; c < 3; ++c) {
        color.At(c, y, x) = value;
        hist.At(c * kBins + 1, y, x) = 16 - samples;
        hist.At(c * kBins + kBins - 1, y, x) = samples;
    }
}

}  // namespace mcd::test
