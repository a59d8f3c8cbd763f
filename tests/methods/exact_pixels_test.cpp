// Pixels a frame knows exactly (host/common/exact_pixels.h) against the CPU reference, and
// awr and rhf keeping them.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>

#include "cpu_reference/exact_pixels.h"
#include "harness/frames.h"
#include "harness/gpu_fixture.h"
#include "harness/inputs.h"
#include "host/api/device.h"
#include "host/common/exact_pixels.h"
#include "mcdenoise/mcdenoise.h"
#include "tools/render/renderer.h"

namespace mcd::test {
namespace {

// Random values with zeros, negatives, NaN and Inf; a variance that is often exactly 0.
void MakeImages(int w, int h, int channels, int varianceChannels, Image *input, Image *variance,
                Image *output) {
    std::mt19937_64 rng(SeedFromName("exact pixels " + std::to_string(w) + "x" +
                                     std::to_string(h) + "x" + std::to_string(channels)));
    std::uniform_real_distribution<float> unit(0, 1);
    *input = Image(w, h, channels);
    *output = Image(w, h, channels);
    *variance = Image(w, h, varianceChannels);
    for (size_t i = 0; i < input->data.size(); ++i) {
        float u = unit(rng);
        input->data[i] = u < 0.1f    ? 0.f
                         : u < 0.2f  ? -unit(rng)
                         : u < 0.25f ? std::numeric_limits<float>::quiet_NaN()
                         : u < 0.3f  ? std::numeric_limits<float>::infinity()
                                     : 10 * unit(rng);
        output->data[i] = unit(rng);
    }
    for (float &v : variance->data) v = unit(rng) < 0.5f ? 0.f : unit(rng);
}

TEST(ExactPixels, MatchesReference) {
    for (int channels : {1, 3})
        for (int varianceChannels : {1, channels})
            for (auto [w, h] : {std::pair{1, 1}, {7, 5}, {33, 17}}) {
                Image input, variance, output;
                MakeImages(w, h, channels, varianceChannels, &input, &variance, &output);
                Image expected = output, got = output;
                ref::KeepExactPixels(input, variance, &expected);
                size_t kept = KeepExactPixels(input, variance, &got);
                // Values are copied, never computed: bit for bit.
                ASSERT_EQ(got.data, expected.data) << w << "x" << h << "x" << channels;
                size_t changed = 0, exact = 0;
                for (int c = 0; c < channels; ++c)
                    for (size_t p = 0; p < input.PixelCount(); ++p) {
                        float in = input.Plane(c)[p];
                        float v = variance.Plane(varianceChannels == 1 ? 0 : c)[p];
                        bool isExact = v == 0 && std::isfinite(in) && in > 0;
                        exact += isExact;
                        changed += got.Plane(c)[p] != output.Plane(c)[p];
                        // Black, negative and non-finite values stay the method's.
                        if (!isExact) {
                            EXPECT_EQ(got.Plane(c)[p], output.Plane(c)[p]);
                        }
                    }
                EXPECT_EQ(kept, exact);
                if (w * h > 1) {
                    EXPECT_GT(changed, 0u);
                }
            }
}

// The energy moved into exact values goes back: against the reference, and its sum.
TEST(ExactPixels, EnergyReturnsToWhereItCameFrom) {
    for (int reach : {1, 3, 8})
        for (auto [w, h] : {std::pair{1, 1}, {7, 5}, {33, 17}}) {
            Image input, variance, output;
            MakeImages(w, h, 3, 3, &input, &variance, &output);
            Image expected = output, got = output;
            ref::KeepExactPixels(input, variance, &expected, reach);
            KeepExactPixels(input, variance, &got, reach);
            // Double sums in another order, then one float rounding.
            for (size_t i = 0; i < got.data.size(); ++i)
                ASSERT_NEAR(got.data[i], expected.data[i],
                            1e-6 * (std::fabs(expected.data[i]) + 1))
                    << i << " reach " << reach;
            Image again = output;
            KeepExactPixels(input, variance, &again, reach);
            EXPECT_EQ(again.data, got.data);
        }
    // A bright value spread over an exact emitter around it comes back to it.
    Image input(9, 9, 1, 1.f), variance(9, 9, 1, 0.f), output(9, 9, 1, 2.f);
    input.At(0, 4, 4) = 100;
    variance.At(0, 4, 4) = 1e4;
    output.At(0, 4, 4) = 20;  // 80 spread as +1 over the 80 others
    KeepExactPixels(input, variance, &output, 8);
    EXPECT_NEAR(output.At(0, 4, 4), 100, 1e-3);
    EXPECT_EQ(output.At(0, 0, 0), 1.f);
}

TEST(ExactPixels, VarianceOfAnotherSizeKeepsNothing) {
    Image input(4, 3, 3, 1.f), output(4, 3, 3, 2.f);
    Image wrong(3, 4, 3, 0.f), twoChannels(4, 3, 2, 0.f);
    Image expected = output;
    EXPECT_EQ(KeepExactPixels(input, wrong, &output), 0u);
    EXPECT_EQ(KeepExactPixels(input, twoChannels, &output), 0u);
    ref::KeepExactPixels(input, wrong, &expected);
    EXPECT_EQ(output.data, expected.data);
    EXPECT_EQ(output.data, Image(4, 3, 3, 2.f).data);
}

TEST(ExactPixels, VarianceFromTheSampleRange) {
    Image min(2, 1, 1), max(2, 1, 1), spp(2, 1, 1, 4.f);
    min.data = {1.f, 1.f};
    max.data = {1.f, 3.f};
    ExactLayers layers;
    EXPECT_TRUE(ExactVariance(layers).Empty());
    layers.min = &min, layers.max = &max, layers.spp = &spp;
    Image variance = ExactVariance(layers);
    ASSERT_EQ(variance.data.size(), 2u);
    EXPECT_EQ(variance.data[0], 0.f);
    EXPECT_FLOAT_EQ(variance.data[1], 1.f);
    Image layer(2, 1, 1, 0.5f);
    layers.variance = &layer;
    EXPECT_EQ(ExactVariance(layers).data, layer.data);
}

class ExactPixelsMethods : public GpuTest {};

// The fireflies scene at 4 spp has an emitter (every sample equal) around a far brighter
// point seen by one sample in four. awr and rhf used to spread that point over the emitter;
// they keep every exact pixel now.
TEST_F(ExactPixelsMethods, AwrAndRhfKeepAnEmitterBesideAFirefly) {
    render::RenderOptions options;
    options.width = 64, options.height = 64, options.spp = 4;
    options.layers = render::kLayersHist;
    Frame frame = RenderedFrame("fireflies", options);
    const Image &color = frame.layers.at("color"), &variance = frame.layers.at("variance");
    size_t exact = 0;
    for (size_t i = 0; i < color.data.size(); ++i)
        exact += variance.data[i] == 0 && color.data[i] > 0;
    ASSERT_GT(exact, 50u) << "the scene's emitter is not in the frame";
    Device device = api::BorrowDevice(Ctx());
    for (const char *name : {"awr", "rhf"}) {
        Result result = Method(name).Run(device, frame);
        size_t moved = 0;
        for (size_t i = 0; i < color.data.size(); ++i)
            moved += variance.data[i] == 0 && color.data[i] > 0 &&
                     result.image.data[i] != color.data[i];
        EXPECT_EQ(moved, 0u) << name;
        // The energy the filter had put into the emitter goes back: the frame's sum stays
        // within 2% of the input's.
        double in = 0, out = 0;
        for (size_t i = 0; i < color.data.size(); ++i)
            in += color.data[i], out += result.image.data[i];
        EXPECT_NEAR(out, in, 0.02 * in) << name;
    }
}

}  // namespace
}  // namespace mcd::test
