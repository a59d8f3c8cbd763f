// Highlights taken out before a filter (host/common/highlights.h) against the CPU reference,
// and awr keeping a small light's energy at the light.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>

#include "cpu_reference/highlights.h"
#include "harness/gpu_fixture.h"
#include "harness/inputs.h"
#include "host/api/device.h"
#include "host/common/highlights.h"
#include "host/metrics.h"
#include "mcdenoise/mcdenoise.h"

namespace mcd::test {
namespace {

// A dim noisy frame with bright blocks (lights), lone fireflies and constants.
void MakeFrame(int w, int h, int channels, Image *color, Image *variance) {
    std::mt19937_64 rng(SeedFromName("highlights " + std::to_string(w) + "x" +
                                     std::to_string(h) + "x" + std::to_string(channels)));
    std::uniform_real_distribution<float> unit(0, 1);
    *color = Image(w, h, channels);
    *variance = Image(w, h, channels);
    for (size_t i = 0; i < color->data.size(); ++i) {
        float u = unit(rng);
        color->data[i] = u < 0.01f ? 500 * unit(rng) : u < 0.05f ? 0.f : unit(rng);
        variance->data[i] = unit(rng) * unit(rng);
    }
    for (int c = 0; c < channels; ++c)
        for (int y = h / 3; y < std::min(h, h / 3 + 3); ++y)
            for (int x = w / 4; x < std::min(w, w / 4 + 4); ++x)
                color->At(c, y, x) = 100 + 300 * unit(rng);
}

TEST(Highlights, MatchesReference) {
    for (int channels : {1, 3})
        for (auto [w, h] : {std::pair{1, 1}, {3, 2}, {17, 13}, {40, 31}})
            for (double k : {4.0, 16.0}) {
                Image color, variance;
                MakeFrame(w, h, channels, &color, &variance);
                HighlightSplit got = SplitHighlights(color, &variance, k, 3);
                Image base, baseVariance;
                std::vector<char> mask =
                    ref::SplitHighlights(color, &variance, k, 3, &base, &baseVariance);
                // Medians are copied values and the sums the same float sums: bit for bit.
                ASSERT_EQ(got.highlight, mask) << w << "x" << h << "x" << channels;
                EXPECT_EQ(got.base.data, base.data);
                EXPECT_EQ(got.baseVariance.data, baseVariance.data);
                Image output(w, h, channels, 0.25f), expected = output;
                AddHighlights(color, got, &output);
                ref::AddHighlights(color, base, mask, &expected);
                EXPECT_EQ(output.data, expected.data);
                if (w >= 17) EXPECT_GT(got.count, 0u) << "the bright block is a highlight";
            }
}

TEST(Highlights, LoneFireflyAndNonFiniteFramesHaveNone) {
    Image color(9, 9, 3, 0.1f);
    for (int c = 0; c < 3; ++c) color.At(c, 4, 4) = 1000;  // a lone firefly
    EXPECT_EQ(SplitHighlights(color, nullptr, 16, 3).count, 0u);
    for (int c = 0; c < 3; ++c) color.At(c, 4, 5) = color.At(c, 5, 4) = 1000;
    HighlightSplit three = SplitHighlights(color, nullptr, 16, 3);
    EXPECT_EQ(three.count, 3u);
    EXPECT_FLOAT_EQ(three.base.At(0, 4, 4), 0.1f);
    color.At(1, 0, 0) = std::numeric_limits<float>::quiet_NaN();
    EXPECT_EQ(SplitHighlights(color, nullptr, 16, 3).count, 0u);
}

class HighlightsAwr : public GpuTest {};

// A small light (exact inside, a noisy rim) on a dim floor with a small variance: awr's
// shrinkage by the rim's variance rings the light into the floor, far worse than its input.
TEST_F(HighlightsAwr, SmallLightDoesNotRingIntoTheFloor) {
    const int w = 48, h = 40;
    Image truth(w, h, 3, 0.05f), color(w, h, 3), variance(w, h, 3);
    std::mt19937_64 rng(SeedFromName("highlights awr light"));
    std::normal_distribution<float> normal(0, 1);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                int dx = std::abs(x - 20), dy = std::abs(y - 17);
                bool inside = dx <= 2 && dy <= 2, rim = std::max(dx, dy) == 3;
                float t = inside ? 400.f : rim ? 150.f : 0.05f;
                float sd = inside ? 0.f : rim ? 40.f : 0.01f;
                truth.At(c, y, x) = t;
                color.At(c, y, x) = std::max(0.f, t + sd * normal(rng));
                variance.At(c, y, x) = sd * sd;
            }
    Frame frame;
    frame.width = w, frame.height = h;
    frame.layers["color"] = color;
    frame.layers["variance"] = variance;
    Device device = api::BorrowDevice(Ctx());
    double input = CompareImages(color, truth).relMse;
    Method awr("awr");
    Result split = awr.Run(device, frame);
    awr.Set("awr-highlights", 0.f);
    Result whole = awr.Run(device, frame);
    double withSplit = CompareImages(split.image, truth).relMse;
    double without = CompareImages(whole.image, truth).relMse;
    // The rim's energy no longer rings into the floor: a fraction of the error (the
    // light's interior, wider than half the window, still rings).
    EXPECT_GT(without, input) << "the case no longer shows the ringing";
    EXPECT_LT(withSplit, 0.5 * without);
    // The energy stays as awr leaves it: within 1% of the input's sum.
    double sumIn = 0, sumOut = 0;
    for (size_t i = 0; i < color.data.size(); ++i)
        sumIn += color.data[i], sumOut += split.image.data[i];
    EXPECT_NEAR(sumOut, sumIn, 0.02 * sumIn);
}

}  // namespace
}  // namespace mcd::test
