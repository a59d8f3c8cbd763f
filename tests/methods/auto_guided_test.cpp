// Method auto's guided windows (--auto-window-bandwidth): the kernel against its CPU
// reference on random and edge inputs, bit-identical reruns, and what the guide is for: an
// error map's step along the guide's edge stays a step.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <cmath>
#include <random>
#include <string>

#include "auto/guided.h"
#include "cpu_reference/auto_combine.h"
#include "harness/compare.h"
#include "harness/gpu_auto.h"
#include "harness/gpu_fixture.h"
#include "harness/inputs.h"
#include "host/kernels/auto_guided.h"

namespace mcd::test {
namespace {

constexpr double kUnitRoundoff = 0x1p-24;

Image GpuGuided(vk::Context &ctx, const Image &errors, const Image &guide, int radius,
                float bandwidth) {
    vk::GpuImage in(ctx, errors.width, errors.height, errors.channels, "e");
    vk::GpuImage g(ctx, guide.width, guide.height, guide.channels, "g");
    vk::GpuImage out(ctx, errors.width, errors.height, errors.channels, "s");
    in.Upload(errors);
    g.Upload(guide);
    vk::Recorder recorder(ctx);
    RecordAutoSmoothGuided(ctx, recorder, in, g, radius, bandwidth, out);
    recorder.Submit();
    return out.Download();
}

// A sum of at most n = (2r+1)^2 weighted terms and one division: the tents' bound (4n+16)u,
// of the window's mean absolute value, plus the weights'. A weight is exp(-x), x the
// colour distance over bandwidth^2 capped at AUTO_GUIDED_MAX_EXPONENT (40): x carries a
// relative rounding of about (channels + 10)u (each channel's term about 7u, the sum over
// channels, the mean, the bandwidth), which exp turns into a relative x(channels + 10)u;
// Vulkan's exp adds 3 + 2x ulp and the tents 2u. A weight's relative error eps moves the
// weighted mean by at most 2 eps of the mean absolute value: 2 * 40 (channels + 12)u.
class AutoGuidedKernel : public GpuTestWithParam<KernelShape> {};

TEST_P(AutoGuidedKernel, MatchesReferenceAndRepeats) {
    const auto [w, h, channels, kind] = GetParam();
    std::string name = fmt::format("guided{}x{}{}", w, h, InputKindName(kind));
    // Error maps: one plane per candidate (1 to 3 here); a 3-channel guide of other seeds.
    Image errors = MakeInput(kind, w, h, channels, SeedFromName(name));
    // A guide of positive colours (a denoised frame's), non-finite where the kind has them.
    Image guide = MakeVarianceInput(kind, w, h, 3, SeedFromName(name + "guide"));
    for (int radius : {0, 1, 3})
        for (float bandwidth : {0.05f, 0.3f, 10.f}) {
            SCOPED_TRACE(fmt::format("radius {}, bandwidth {}", radius, bandwidth));
            Image expected = ref::AutoSmoothGuided(errors, guide, radius, bandwidth);
            Image magnitude = errors;
            for (float &v : magnitude.data) v = std::fabs(v);
            magnitude = ref::AutoSmoothGuided(magnitude, guide, radius, bandwidth);
            int n = (2 * radius + 1) * (2 * radius + 1);
            Image actual = GpuGuided(Ctx(), errors, guide, radius, bandwidth);
            double weights = 2.0 * AUTO_GUIDED_MAX_EXPONENT * (guide.channels + 12);
            EXPECT_TRUE(ImagesMatch(expected, actual, magnitude,
                                    {(4 * n + 16 + weights) * kUnitRoundoff, 0, 1e-10}));
            EXPECT_TRUE(
                BitIdentical(actual, GpuGuided(Ctx(), errors, guide, radius, bandwidth)));
        }
}

INSTANTIATE_TEST_SUITE_P(Cases, AutoGuidedKernel, testing::ValuesIn(KernelShapes()),
                         KernelShapeName);

class AutoGuidedWindow : public GpuTest {};

// Windows wider than the frame (the default radius 12 and the measured 20 on a 17x11
// frame): every window is clipped on both sides, and the kernel still matches its twin.
TEST_F(AutoGuidedWindow, WindowsWiderThanTheFrameMatchTheTwin) {
    const int w = 17, h = 11;
    Image errors = MakeInput(InputKind::Uniform, w, h, 2, SeedFromName("guidedwide"));
    Image guide = MakeVarianceInput(InputKind::Uniform, w, h, 3, SeedFromName("guidedwideg"));
    for (int radius : {12, 20}) {
        SCOPED_TRACE(fmt::format("radius {}", radius));
        Image expected = ref::AutoSmoothGuided(errors, guide, radius, 0.3);
        Image magnitude = errors;
        for (float &v : magnitude.data) v = std::fabs(v);
        magnitude = ref::AutoSmoothGuided(magnitude, guide, radius, 0.3);
        int n = (2 * radius + 1) * (2 * radius + 1);
        double weights = 2.0 * AUTO_GUIDED_MAX_EXPONENT * (guide.channels + 12);
        Image actual = GpuGuided(Ctx(), errors, guide, radius, 0.3f);
        EXPECT_TRUE(ImagesMatch(expected, actual, magnitude,
                                {(4 * n + 16 + weights) * kUnitRoundoff, 0, 1e-10}));
    }
}

// A flat guide gives the tents' windows back: every colour distance is 0.
TEST_F(AutoGuidedWindow, AFlatGuideIsTheTent) {
    const int w = 29, h = 17, radius = 4;
    Image errors = MakeInput(InputKind::Uniform, w, h, 2, SeedFromName("guidedflat"));
    Image guide(w, h, 3);
    for (float &v : guide.data) v = 0.5f;
    Image tent = GpuSmooth(Ctx(), errors, radius);
    Image reference = ref::AutoSmooth(errors, radius);
    for (bool gpu : {false, true}) {
        SCOPED_TRACE(gpu ? "gpu" : "cpu reference");
        Image guided = gpu ? GpuGuided(Ctx(), errors, guide, radius, 0.2f)
                           : ref::AutoSmoothGuided(errors, guide, radius, 0.2);
        EXPECT_TRUE(ImagesMatch(gpu ? tent : reference, guided, Image(), {1e-5, 1e-7, 1e-10}));
    }
}

// A guide above float's square root of its largest value (a squared term overflows in the
// kernel, which then leaves the channel out): the twin leaves it out too.
TEST_F(AutoGuidedWindow, AHugeGuideMatchesTheTwin) {
    const int w = 21, h = 13, radius = 3;
    Image errors = MakeInput(InputKind::Uniform, w, h, 2, SeedFromName("guidedhuge"));
    Image guide(w, h, 3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c) guide.At(c, y, x) = x < w / 2 ? 3e19f : 1.f;
    Image expected = ref::AutoSmoothGuided(errors, guide, radius, 0.2);
    Image actual = GpuGuided(Ctx(), errors, guide, radius, 0.2f);
    EXPECT_TRUE(ImagesMatch(expected, actual, Image(), {1e-5, 1e-7, 1e-10}));
}

// A frame whose guide is dark on the left and bright on the right, the error map noisy
// around 1 on the left and around 0 on the right (a candidate wrong on one side of an edge
// only): with the guided windows the two sides' means stay apart next to the edge, where
// the tents mix them. Seeded noise, the means over the two columns beside the edge.
TEST_F(AutoGuidedWindow, KeepsAnErrorsStepAtTheGuidesEdge) {
    const int w = 48, h = 32, edge = 24, radius = 12;
    std::mt19937 rng(SeedFromName("guidededge"));
    std::normal_distribution<float> noise(0.f, 0.5f);
    Image errors(w, h, 1), guide(w, h, 3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            errors.At(0, y, x) = (x < edge ? 1.f : 0.f) + noise(rng);
            for (int c = 0; c < 3; ++c) guide.At(c, y, x) = x < edge ? 0.1f : 0.8f;
        }
    auto Step = [&](const Image &smooth) {
        double left = 0, right = 0;
        for (int y = 0; y < h; ++y)
            left += smooth.At(0, y, edge - 1), right += smooth.At(0, y, edge);
        return (left - right) / h;
    };
    for (bool gpu : {false, true}) {
        SCOPED_TRACE(gpu ? "gpu" : "cpu reference");
        Image guided = gpu ? GpuGuided(Ctx(), errors, guide, radius, 0.2f)
                           : ref::AutoSmoothGuided(errors, guide, radius, 0.2);
        Image tent = gpu ? GpuSmooth(Ctx(), errors, radius) : ref::AutoSmooth(errors, radius);
        // The tents' step beside the edge is a small part of the true one (1).
        EXPECT_LT(Step(tent), 0.25);
        EXPECT_GT(Step(guided), 0.9);
        EXPECT_LT(Step(guided), 1.1);
    }
}

}  // namespace
}  // namespace mcd::test
