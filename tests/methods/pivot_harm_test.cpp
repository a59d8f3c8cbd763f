// pivot on frames where its guide does not explain the colour (issue 29): a shading edge
// at low noise, which fails without the bound to the input's noise.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "harness/gpu_fixture.h"
#include "harness/inputs.h"
#include "host/api/device.h"
#include "host/metrics.h"
#include "mcdenoise/mcdenoise.h"

namespace mcd {
namespace {

using test::GpuTest;
using test::SeedFromName;

class PivotHarm : public GpuTest {};

// relMSE of `image` against `truth`.
double RelMse(const Image &image, const Image &truth) {
    return CompareImages(image, truth).relMse;
}

// A frame of constant albedo and normal whose colour is `truth` plus Gaussian noise of
// standard deviation `sigma` x (truth + 0.1); with `variance`, the noise's variance as the
// frame's variance layer.
Frame NoisyFrame(const Image &truth, double sigma, bool variance, const std::string &name) {
    std::mt19937_64 rng(SeedFromName(name));
    std::normal_distribution<float> unit(0, 1);
    Frame frame;
    frame.width = truth.width, frame.height = truth.height;
    Image color = truth, albedo(truth.width, truth.height, 3), normal = albedo;
    Image var = albedo;
    for (size_t i = 0; i < color.data.size(); ++i) {
        float sd = float(sigma * (truth.data[i] + 0.1));
        color.data[i] = std::max(0.f, truth.data[i] + sd * unit(rng));
        albedo.data[i] = 0.8f;
        var.data[i] = sd * sd;
    }
    for (size_t p = 0; p < normal.PixelCount(); ++p)
        normal.data[2 * normal.PixelCount() + p] = 1;
    frame.layers = {{"color", color}, {"albedo", albedo}, {"normal", normal}};
    if (variance) frame.layers["variance"] = var;
    return frame;
}

// A shadow's edge (0.1 beside 1.0) on one albedo at low noise, as in a 64-spp frame: the
// plane fits across it overshoot on both sides (below 0 on the dark side), by far more than
// the pixels' noise. Bound to 3 standard deviations of it (before the local means are
// restored, which then only scale), no value moves further, and the error is a fraction of
// the unbounded one.
TEST_F(PivotHarm, AnEdgeAtLowNoiseMovesNoFurtherThanItsNoise) {
    const int w = 48, h = 40;
    Image truth(w, h, 3);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) truth.At(c, y, x) = x < 20 + y / 4 ? 1.f : 0.1f;
    Frame frame = NoisyFrame(truth, 0.02, true, "pivot harm edge");
    const Image &color = frame.layers["color"], &variance = frame.layers["variance"];
    Device device = api::BorrowDevice(Ctx());
    Method pivot("pivot");
    // The default's shading-edge test keeps the fits from crossing the edge at all; without
    // it they overshoot, and the bound holds them.
    const double withEdgeTest = RelMse(pivot.Run(device, frame).image, truth);
    pivot.Set("pivot-edge", 0.f);
    double bounded = RelMse(pivot.Run(device, frame).image, truth);
    EXPECT_LE(withEdgeTest, bounded);
    pivot.Set("pivot-mean-radius", 0);
    Image fits = pivot.Run(device, frame).image;
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                // The pixel's variance or its 3x3 window's mean without the largest.
                std::vector<double> window;
                for (int j = std::max(0, y - 1); j <= std::min(h - 1, y + 1); ++j)
                    for (int i = std::max(0, x - 1); i <= std::min(w - 1, x + 1); ++i)
                        window.push_back(variance.At(c, j, i));
                std::sort(window.begin(), window.end());
                double rest = 0;
                for (size_t i = 0; i + 1 < window.size(); ++i) rest += window[i];
                double v =
                    std::max(rest / double(window.size() - 1), double(variance.At(c, y, x)));
                ASSERT_LE(std::fabs(fits.At(c, y, x) - color.At(c, y, x)),
                          3 * std::sqrt(v) * (1 + 1e-6) + 1e-7)
                    << c << " " << y << " " << x;
            }
    pivot.Set("pivot-mean-radius", 8);
    pivot.Set("pivot-bound", 0.f);
    double free = RelMse(pivot.Run(device, frame).image, truth);
    fmt::print("input {:.4g}, pivot {:.4g}, without the bound {:.4g}\n", RelMse(color, truth),
               bounded, free);
    EXPECT_LT(bounded, free / 5);
}

// A straight edge on a plain frame (no variance layer): the bound reads the frame's own
// noise estimate, whose smallest second difference runs along the edge (at a jog of the edge
// every direction crosses it and the estimate is high there).
TEST_F(PivotHarm, AnEdgeOnAPlainFrameIsBoundByItsEstimatedNoise) {
    const int w = 48, h = 40;
    Image truth(w, h, 3);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) truth.At(c, y, x) = x < 24 ? 1.f : 0.1f;
    Frame frame = NoisyFrame(truth, 0.02, false, "pivot harm plain edge");
    Device device = api::BorrowDevice(Ctx());
    Method pivot("pivot");
    // The bound's own effect: without the shading-edge test, which keeps the fits from
    // crossing the edge.
    const double withEdgeTest = RelMse(pivot.Run(device, frame).image, truth);
    pivot.Set("pivot-edge", 0.f);
    Result bounded = pivot.Run(device, frame);
    EXPECT_LE(withEdgeTest, RelMse(bounded.image, truth));
    bool planned = false;
    for (const std::string &line : bounded.plan)
        planned |= line.find("estimated from the frame") != std::string::npos;
    EXPECT_TRUE(planned);
    pivot.Set("pivot-bound", 0.f);
    double free = RelMse(pivot.Run(device, frame).image, truth);
    fmt::print("input {:.4g}, pivot {:.4g}, without the bound {:.4g}\n",
               RelMse(frame.layers["color"], truth), RelMse(bounded.image, truth), free);
    EXPECT_LT(RelMse(bounded.image, truth), free / 2);
}

// A glass's refracted pattern on a plain frame (issue 29, product_transparent): rings and
// a bright line that the albedo does not show, at a high relative noise. For the fits, a
// 3x3 sample variance of z counts the pattern as noise, so the quadrants' disagreement
// does not stop the squares and they smear it (`--pivot-noise estimate`: about the input's
// error, above it on some draws); with the frame's robust estimate, the default, pivot
// takes a fifth or more off both.
TEST_F(PivotHarm, APatternTheAlbedoDoesNotShowIsNotSmeared) {
    const int w = 64, h = 64;
    Image truth(w, h, 3);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                double r = std::hypot(x - 30.0, y - 34.0);
                double v = 0.3 + 0.25 * std::sin(0.3 * r);
                if (std::abs(x - y - 3) <= 0 && x > 8 && x < 56) v = 8;
                truth.At(c, y, x) = float(v);
            }
    Frame frame = NoisyFrame(truth, 0.5, false, "pivot harm pattern");
    Device device = api::BorrowDevice(Ctx());
    Method pivot("pivot");
    const double input = RelMse(frame.layers["color"], truth);
    Result robust = pivot.Run(device, frame);
    pivot.Set("pivot-noise", std::string("estimate"));
    const double sample = RelMse(pivot.Run(device, frame).image, truth);
    fmt::print("input {:.4g}, pivot {:.4g}, with the 3x3 sample variance {:.4g}\n", input,
               RelMse(robust.image, truth), sample);
    EXPECT_LT(RelMse(robust.image, truth), 0.8 * std::min(input, sample));
    bool planned = false;
    for (const std::string &line : robust.plan)
        planned |= line.find("estimated from the frame") != std::string::npos;
    EXPECT_TRUE(planned);
}

}  // namespace
}  // namespace mcd
