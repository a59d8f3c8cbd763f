// Method rhf: the GPU filter against the CPU reference (cpu_reference/rhf.h) on random
// histograms and edge sizes, the split paths, reruns, and the properties of issue #4.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "cpu_reference/rhf.h"
#include "harness/compare.h"
#include "harness/errors.h"
#include "harness/gpu_fixture.h"
#include "harness/inputs.h"
#include "host/error.h"
#include "host/methods/rhf.h"
#include "tools/render/renderer.h"

namespace mcd::test {
namespace {

constexpr double kUnitRoundoff = 0x1p-24;
constexpr int kBins = 20;

// A frame of a few flat regions with Monte Carlo noise: each pixel's samples are its
// region's colour times lognormal noise, binned as the renderer bins them; the colour is
// the samples' mean. Sample counts vary from 4 to 24 so the count terms matter.
struct Frame {
    Image color, hist;
};

// `Region(x, y)` gives a pixel's noise-free colour; by default diagonal bands.
Frame MakeFrame(int w, int h, uint64_t seed, int bins = kBins,
                std::function<const double *(int, int)> region = nullptr) {
    std::mt19937_64 rng(seed);
    std::uniform_int_distribution<int> spp(4, 24);
    std::normal_distribution<double> noise(0.0, 0.6);
    static const double regions[3][3] = {{0.2, 0.3, 0.4}, {0.9, 0.5, 0.1}, {2.5, 2.0, 1.5}};
    // Diagonal bands, so patches straddle region edges.
    if (!region) region = [](int x, int y) { return regions[((x + 2 * y) / 5) % 3]; };
    Frame f{Image(w, h, 3), Image(w, h, 3 * bins + 1)};
    std::vector<float> pixelHist(3 * bins);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const double *base = region(x, y);
            int n = spp(rng);
            std::fill(pixelHist.begin(), pixelHist.end(), 0.f);
            double sum[3] = {0, 0, 0};
            for (int k = 0; k < n; ++k) {
                double c[3];
                double m = std::exp(noise(rng) - 0.18);
                for (int ch = 0; ch < 3; ++ch) sum[ch] += c[ch] = base[ch] * m;
                render::AddToHistogram(c, bins, pixelHist.data());
            }
            for (int ch = 0; ch < 3; ++ch) f.color.At(ch, y, x) = float(sum[ch] / n);
            for (int i = 0; i < 3 * bins; ++i) f.hist.At(i, y, x) = pixelHist[i];
            f.hist.At(3 * bins, y, x) = float(n);
        }
    return f;
}

ref::RhfParams Params(const RhfOptions &o) {
    return {o.patchHalf, o.searchHalf, double(o.threshold), o.knn, o.scales, o.brightVeto};
}

// The method's default output: the reference's with negatives clamped to 0.
Image NonNegative(Image image) {
    for (float &v : image.data) v = std::max(v, 0.f);
    return image;
}

double MaxAbs(const Image &image) {
    double m = 0;
    for (float v : image.data) m = std::max(m, double(std::fabs(v)));
    return m;
}

// The output is, per scale, a mean of at most (2w+1)^2 means of at most (2b+1)^2 colours:
// float summation errs by at most (terms) unit round-offs of the largest colour. Each
// coarser scale comes back through a Gaussian (taps summing to 1) and two bicubic
// interpolations (absolute weights summing to 1.5625 per axis pair), which multiplies
// what it carries by at most ~4 per scale; 2000 round-offs of the largest colour cover
// three scales of the default window with room to spare. Selections are discrete: a
// distance within round-off of the threshold could flip, which random data never hits.
Tolerance ToleranceFor(const Image &color, const RhfOptions &o) {
    int side = 2 * o.searchHalf + 1, patch = 2 * o.patchHalf + 1;
    double terms = side * side + patch * patch + 2;
    double perScale = 2 * terms * kUnitRoundoff * MaxAbs(color);
    return {0, perScale * std::pow(4.0, o.scales - 1) * 2, 1e-9};
}

class RhfKernel : public GpuTest {};

// A float in a case's name: gtest names take [A-Za-z0-9_] only, so 0.8 is "0p8".
std::string NameOf(float v) {
    std::string name = fmt::format("{}", v);
    std::replace(name.begin(), name.end(), '.', 'p');
    return name;
}

// Each case is a test of its own, named by its parameters, so a failing one re-runs alone.
struct SingleScaleCase {
    int w, h, patchHalf, searchHalf, knn;
    float threshold;
};

class RhfKernelSingleScale : public GpuTestWithParam<SingleScaleCase> {};

TEST_P(RhfKernelSingleScale, MatchesReference) {
    const SingleScaleCase &c = GetParam();
    Frame f = MakeFrame(c.w, c.h, SeedFromName(fmt::format("rhf1 {}x{}", c.w, c.h)));
    RhfOptions o;
    o.patchHalf = c.patchHalf;
    o.searchHalf = c.searchHalf;
    o.knn = c.knn;
    o.threshold = c.threshold;
    o.scales = 1;
    Image expected = NonNegative(ref::Rhf(f.color, f.hist, Params(o)));
    RhfResult result = RhfDenoise(Ctx(), f.color, f.hist, o);
    EXPECT_TRUE(result.warnings.empty());
    EXPECT_TRUE(ImagesMatch(expected, result.image, {}, ToleranceFor(f.color, o)));
}

INSTANTIATE_TEST_SUITE_P(Cases, RhfKernelSingleScale,
                         testing::Values(SingleScaleCase{37, 23, 1, 6, 2, 0.8f},
                                         SingleScaleCase{1, 1, 1, 6, 2, 0.8f},
                                         SingleScaleCase{2, 2, 1, 6, 2, 0.8f},
                                         SingleScaleCase{5, 4, 1, 6, 2, 0.8f},
                                         SingleScaleCase{13, 9, 2, 3, 3, 0.5f},
                                         SingleScaleCase{16, 16, 0, 2, 1, 1.5f},
                                         SingleScaleCase{11, 3, 1, 6, 0, 0.8f}),
                         [](const testing::TestParamInfo<SingleScaleCase> &info) {
                             const SingleScaleCase &c = info.param;
                             return fmt::format("{}x{}_w{}_b{}_k{}_t{}", c.w, c.h, c.patchHalf,
                                                c.searchHalf, c.knn, NameOf(c.threshold));
                         });

struct MultiScaleCase {
    int w, h, searchHalf, scales, expectedScales;
};

class RhfKernelMultiScale : public GpuTestWithParam<MultiScaleCase> {};

TEST_P(RhfKernelMultiScale, MatchesReference) {
    const MultiScaleCase &c = GetParam();
    Frame f = MakeFrame(c.w, c.h, SeedFromName(fmt::format("rhfms {}x{}", c.w, c.h)));
    RhfOptions o;
    o.searchHalf = c.searchHalf;
    o.scales = c.scales;
    ASSERT_EQ(ref::RhfScalesUsed(c.w, c.h, Params(o)), c.expectedScales);
    Image expected = ref::Rhf(f.color, f.hist, Params(o));
    o.clampNegative = false;
    RhfResult result = RhfDenoise(Ctx(), f.color, f.hist, o);
    EXPECT_EQ(result.scalesUsed, c.expectedScales);
    EXPECT_TRUE(ImagesMatch(expected, result.image, {}, ToleranceFor(f.color, o)));
    o.clampNegative = true;
    EXPECT_TRUE(ImagesMatch(NonNegative(expected), RhfDenoise(Ctx(), f.color, f.hist, o).image,
                            {}, ToleranceFor(f.color, o)));
}

INSTANTIATE_TEST_SUITE_P(
    Cases, RhfKernelMultiScale,
    testing::Values(MultiScaleCase{40, 30, 6, 2, 2}, MultiScaleCase{29, 33, 3, 3, 3},
                    MultiScaleCase{27, 26, 6, 2, 2}, MultiScaleCase{23, 40, 6, 2, 1}),
    [](const testing::TestParamInfo<MultiScaleCase> &info) {
        const MultiScaleCase &c = info.param;
        return fmt::format("{}x{}_b{}_s{}", c.w, c.h, c.searchHalf, c.scales);
    });

// The bright veto (beyond the authors' tool): GPU against CPU with it off, at the default
// and strong, at one and two scales. About 2% of the brightest band's samples (2.5 with
// lognormal noise) lie above the histogram's range (7.5); they must trigger the veto, or
// the test would compare nothing new.
struct BrightVetoCase {
    int scales;
    float veto;
};

class RhfKernelBrightVeto : public GpuTestWithParam<BrightVetoCase> {};

TEST_P(RhfKernelBrightVeto, MatchesReference) {
    const auto [scales, veto] = GetParam();
    // The same frame for every case.
    Frame f = MakeFrame(31, 27, SeedFromName("rhf veto"));
    RhfOptions o;
    o.searchHalf = 4;
    o.scales = scales;
    o.brightVeto = veto;
    o.clampNegative = false;
    Image expected = ref::Rhf(f.color, f.hist, Params(o));
    EXPECT_TRUE(ImagesMatch(expected, RhfDenoise(Ctx(), f.color, f.hist, o).image, {},
                            ToleranceFor(f.color, o)));
    if (veto > 0) {
        RhfOptions off = o;
        off.brightVeto = 0;
        EXPECT_FALSE(ImagesMatch(expected, ref::Rhf(f.color, f.hist, Params(off)), {},
                                 ToleranceFor(f.color, o)))
            << "the veto changed nothing on this frame";
    }
}

std::vector<BrightVetoCase> BrightVetoCases() {
    std::vector<BrightVetoCase> cases;
    for (int scales : {1, 2})
        for (float veto : {0.f, 0.3f, 0.1f}) cases.push_back({scales, veto});
    return cases;
}

INSTANTIATE_TEST_SUITE_P(Cases, RhfKernelBrightVeto, testing::ValuesIn(BrightVetoCases()),
                         [](const testing::TestParamInfo<BrightVetoCase> &info) {
                             return fmt::format("s{}_veto{}", info.param.scales,
                                                NameOf(info.param.veto));
                         });

// Histograms split over several buffers and distances computed in thin strips (the
// paths big frames take) give the same bits as the one-buffer, one-strip run.
struct SplitCase {
    int planesPerSlot, stripRows;
};

class RhfKernelSplit : public GpuTestWithParam<SplitCase> {};

TEST_P(RhfKernelSplit, IsBitIdentical) {
    const auto [perSlot, strip] = GetParam();
    Frame f = MakeFrame(33, 31, SeedFromName("rhf split"));
    RhfOptions o;
    o.searchHalf = 4;
    Image whole = RhfDenoise(Ctx(), f.color, f.hist, o).image;
    o.planesPerSlot = perSlot;
    o.stripRows = strip;
    EXPECT_TRUE(BitIdentical(whole, RhfDenoise(Ctx(), f.color, f.hist, o).image));
}

INSTANTIATE_TEST_SUITE_P(Cases, RhfKernelSplit,
                         testing::Values(SplitCase{11, 0}, SplitCase{0, 3}, SplitCase{13, 1}),
                         [](const testing::TestParamInfo<SplitCase> &info) {
                             return fmt::format("planes{}_rows{}", info.param.planesPerSlot,
                                                info.param.stripRows);
                         });

TEST_F(RhfKernel, RerunsAreBitIdentical) {
    Frame f = MakeFrame(45, 38, SeedFromName("rhf rerun"));
    RhfOptions o;
    Image first = RhfDenoise(Ctx(), f.color, f.hist, o).image;
    EXPECT_TRUE(BitIdentical(first, RhfDenoise(Ctx(), f.color, f.hist, o).image));
}

class RhfProperties : public GpuTest {};

// Threshold 0 and k_NN 1 select only the patch itself: every estimate of a pixel is its
// own value, and a mean of equal values is that value up to the rounding of the sum.
TEST_F(RhfProperties, OnlyItselfLeavesTheImageUnchanged) {
    Frame f = MakeFrame(21, 17, SeedFromName("rhf identity"));
    RhfOptions o;
    o.threshold = 0;
    o.knn = 1;
    o.scales = 1;
    Image out = RhfDenoise(Ctx(), f.color, f.hist, o).image;
    EXPECT_TRUE(ImagesMatch(f.color, out, {}, {20 * kUnitRoundoff, 0, 1e-12}));
}

// At two scales too: the coarse scale then selects nothing (k_NN is 0 there), so u_1 is
// D(u) and the recombination adds U(D(u)) - U(D(u)), the same bits computed twice.
TEST_F(RhfProperties, OnlyItselfAtTwoScalesLeavesTheImageUnchanged) {
    Frame f = MakeFrame(30, 28, SeedFromName("rhf identity 2"));
    RhfOptions o;
    o.threshold = 0;
    o.knn = 1;
    o.scales = 2;
    RhfResult result = RhfDenoise(Ctx(), f.color, f.hist, o);
    ASSERT_EQ(result.scalesUsed, 2);
    // (u - a) + a rounds twice: a few units of round-off of the larger of u and a.
    EXPECT_TRUE(ImagesMatch(f.color, result.image, {},
                            {0, 8 * kUnitRoundoff * MaxAbs(f.color), 1e-12}));
}

// Any selection averages equal values: a constant colour stays constant, at every scale.
TEST_F(RhfProperties, ConstantStaysConstant) {
    Frame f = MakeFrame(40, 36, SeedFromName("rhf constant"));
    for (float &v : f.color.data) v = 0.7f;
    RhfOptions o;
    Image out = RhfDenoise(Ctx(), f.color, f.hist, o).image;
    EXPECT_TRUE(ImagesMatch(f.color, out, {}, {200 * kUnitRoundoff, 0, 1e-12}));
}

// Identical histograms everywhere: every distance is 0, so every patch of the clamped
// window is averaged. Checked against that average written directly.
TEST_F(RhfProperties, IdenticalHistogramsSelectTheWholeWindow) {
    const int w = 19, h = 14;
    Frame f = MakeFrame(w, h, SeedFromName("rhf identical"));
    for (int i = 0; i < f.hist.channels; ++i)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) f.hist.At(i, y, x) = f.hist.At(i, 0, 0);
    RhfOptions o;
    o.scales = 1;
    o.searchHalf = 4;
    o.knn = 0;
    Image out = RhfDenoise(Ctx(), f.color, f.hist, o).image;
    Image direct(w, h, 3);
    const int pw = o.patchHalf, b = o.searchHalf;
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                double total = 0;
                int estimates = 0;
                for (int cy = y - pw; cy <= y + pw; ++cy)
                    for (int cx = x - pw; cx <= x + pw; ++cx) {
                        if (cx < 0 || cy < 0 || cx >= w || cy >= h) continue;
                        int w0 = std::min({pw, cx, cy, w - 1 - cx, h - 1 - cy});
                        if (std::abs(x - cx) > w0 || std::abs(y - cy) > w0) continue;
                        double mean = 0;
                        int n = 0;
                        for (int qy = std::max(cy - b, w0); qy <= std::min(cy + b, h - 1 - w0);
                             ++qy)
                            for (int qx = std::max(cx - b, w0);
                                 qx <= std::min(cx + b, w - 1 - w0); ++qx, ++n)
                                mean += f.color.At(c, qy + y - cy, qx + x - cx);
                        total += mean / n;
                        ++estimates;
                    }
                direct.At(c, y, x) = float(total / estimates);
            }
    EXPECT_TRUE(ImagesMatch(direct, out, {}, ToleranceFor(f.color, o)));
}

// Two scales across a 100:1 edge (an area light beside a dim ceiling): the bicubic
// recombination overshoots below 0 on the dark side. By default those values come out 0,
// counted in the plan, and the rest is the raw output bit for bit.
TEST_F(RhfProperties, RecombinationUndershootIsClampedAndCounted) {
    const int w = 40, h = 32;
    static const double light[3] = {12, 12, 12}, ceiling[3] = {0.1, 0.1, 0.1};
    Frame f = MakeFrame(w, h, SeedFromName("rhf overshoot"), kBins,
                        [](int x, int) { return x < 17 ? light : ceiling; });
    RhfOptions o;
    o.clampNegative = false;
    Image raw = RhfDenoise(Ctx(), f.color, f.hist, o).image;
    size_t negative = 0;
    for (float v : raw.data) negative += v < 0;
    ASSERT_GT(negative, 0u) << "the edge no longer overshoots: the test needs a stronger one";
    o.clampNegative = true;
    RhfResult clamped = RhfDenoise(Ctx(), f.color, f.hist, o);
    EXPECT_TRUE(BitIdentical(NonNegative(raw), clamped.image));
    std::string plan;
    for (const std::string &line : clamped.plan) plan += line + "\n";
    EXPECT_NE(plan.find(fmt::format("clamped {} negative value(s) to 0", negative)),
              std::string::npos)
        << plan;
}

// A frame of one flat colour (identical histograms) but for one pixel holding a light:
// `brightSamples` of the pixel's `spp` samples see `bright`, the others `dim`.
Frame OneLightFrame(int w, int h, int lx, int ly, int spp, int brightSamples, double dim,
                    double bright) {
    Frame f{Image(w, h, 3), Image(w, h, 3 * kBins + 1)};
    std::vector<float> flat(3 * kBins, 0.f), light(3 * kBins, 0.f);
    const double dimRgb[3] = {dim, dim, dim}, brightRgb[3] = {bright, bright, bright};
    for (int k = 0; k < spp; ++k) {
        render::AddToHistogram(dimRgb, kBins, flat.data());
        render::AddToHistogram(k < brightSamples ? brightRgb : dimRgb, kBins, light.data());
    }
    float lightMean = float((brightSamples * bright + (spp - brightSamples) * dim) / spp);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            bool isLight = x == lx && y == ly;
            for (int c = 0; c < 3; ++c) f.color.At(c, y, x) = isLight ? lightMean : float(dim);
            for (int i = 0; i < 3 * kBins; ++i)
                f.hist.At(i, y, x) = (isLight ? light : flat)[i];
            f.hist.At(3 * kBins, y, x) = float(spp);
        }
    return f;
}

// A light in one pixel of a flat region. The authors' distance averages the light pixel's
// large terms with the zero terms of eight alike pixels, so every patch holding it is
// "similar" and the light spreads. With the veto every patch pair holding it is left out,
// and the rest are identical: the frame comes back as it was. Two lights: 4 samples of 12
// against 0.1 (the saturated bins' terms give 3.05 per colour, 9.15 against 0.3 x 4), and
// fireflies' partly seen point, 7 of 64 samples of 3800 against 1.42 (7 per colour, 21
// against 0.3 x 64 = 19.2: the default's bound is a 10% difference in the share of such
// samples).
struct OneLightCase {
    int spp, brightSamples;
    double dim, bright;
};

class RhfPropertiesOneLight : public GpuTestWithParam<OneLightCase> {};

TEST_P(RhfPropertiesOneLight, BrightVetoKeepsItInPlace) {
    const int w = 15, h = 13, lx = 7, ly = 6;
    const OneLightCase &c = GetParam();
    Frame f = OneLightFrame(w, h, lx, ly, c.spp, c.brightSamples, c.dim, c.bright);
    float lightMean = f.color.At(1, ly, lx);
    RhfOptions o;
    o.scales = 1;
    Image kept = RhfDenoise(Ctx(), f.color, f.hist, o).image;
    // Means of equal values: a few round-offs of the light's value.
    EXPECT_TRUE(ImagesMatch(f.color, kept, {}, {0, 16 * kUnitRoundoff * lightMean, 1e-12}));
    EXPECT_TRUE(
        ImagesMatch(ref::Rhf(f.color, f.hist, Params(o)), kept, {}, ToleranceFor(f.color, o)));
    o.brightVeto = 0;
    Image spread = RhfDenoise(Ctx(), f.color, f.hist, o).image;
    EXPECT_LT(spread.At(1, ly, lx), 0.5f * lightMean)
        << "the authors' distance no longer spreads the light";
    EXPECT_GT(spread.At(1, ly, lx + 1), 1.5f * c.dim);
}

INSTANTIATE_TEST_SUITE_P(Cases, RhfPropertiesOneLight,
                         testing::Values(OneLightCase{4, 4, 0.1, 12},
                                         OneLightCase{64, 7, 1.42, 3800}),
                         [](const testing::TestParamInfo<OneLightCase> &info) {
                             const OneLightCase &c = info.param;
                             return fmt::format("{}of{}_at{}", c.brightSamples, c.spp,
                                                c.bright);
                         });

TEST_F(RhfProperties, BadPixelsGiveFiniteOutputAndCountedWarnings) {
    const int w = 24, h = 20, n3 = 3 * kBins;
    Frame f = MakeFrame(w, h, SeedFromName("rhf bad"));
    float nan = std::numeric_limits<float>::quiet_NaN(),
          inf = std::numeric_limits<float>::infinity();
    f.color.At(0, 3, 4) = nan;
    f.color.At(2, 10, 11) = inf;
    f.color.At(1, 0, 0) = -inf;
    f.hist.At(n3, 5, 5) = 0;                                // no samples
    for (int i = 0; i <= n3; ++i) f.hist.At(i, 7, 20) = 0;  // empty histogram
    f.hist.At(3, 12, 2) = nan;                              // a NaN bin
    f.hist.At(n3, 19, 23) = -2;                             // a negative count
    RhfOptions o;
    RhfResult result = RhfDenoise(Ctx(), f.color, f.hist, o);
    for (float v : result.image.data) ASSERT_TRUE(std::isfinite(v));
    std::string all;
    for (const std::string &s : result.warnings) all += s + "\n";
    EXPECT_NE(all.find("3 pixel(s) have a NaN/Inf colour"), std::string::npos) << all;
    EXPECT_NE(all.find("2 pixel(s) have NaN/Inf/negative histogram"), std::string::npos) << all;
    // The count-0 pixel, the empty one, and the negative count set to 0.
    EXPECT_NE(all.find("3 pixel(s) have no samples"), std::string::npos) << all;
    // All histograms empty: nothing is counted, every distance is 0, still finite.
    for (float &v : f.hist.data) v = 0;
    result = RhfDenoise(Ctx(), f.color, f.hist, o);
    for (float v : result.image.data) ASSERT_TRUE(std::isfinite(v));
}

TEST_F(RhfProperties, BadShapesAndOptionsAreErrors) {
    Frame f = MakeFrame(8, 8, 1);
    RhfOptions o;
    Image wrong(8, 8, 60);
    EXPECT_THROW(RhfDenoise(Ctx(), f.color, wrong, o), Error);
    Image small(4, 8, f.hist.channels);
    EXPECT_THROW(RhfDenoise(Ctx(), f.color, small, o), Error);
    o.knn = 1000;
    EXPECT_THROW(RhfDenoise(Ctx(), f.color, f.hist, o), Error);
    o = {};
    o.threshold = -1;
    EXPECT_THROW(RhfDenoise(Ctx(), f.color, f.hist, o), Error);
    o = {};
    o.brightVeto = -0.1f;
    EXPECT_THROW(RhfDenoise(Ctx(), f.color, f.hist, o), Error);
    o.brightVeto = std::numeric_limits<float>::quiet_NaN();
    EXPECT_THROW(RhfDenoise(Ctx(), f.color, f.hist, o), Error);
}

}  // namespace
}  // namespace mcd::test

namespace mcd::test {
namespace {

class RhfLimits : public GpuTest {};

// A frame whose selection mask cannot be one binding is refused up front, naming the
// window and the limit: 640x1024 with search half-window 20 needs 53 words a pixel.
TEST_F(RhfLimits, RefusesAMaskAboveTheBindingLimit) {
    const int w = 640, h = 1024;
    size_t maskBytes = size_t(53) * w * h * 4;
    if (maskBytes <= Ctx().Limits().maxStorageBufferRange)
        GTEST_SKIP() << "this device binds " << Ctx().Limits().maxStorageBufferRange
                     << " bytes: the frame fits, nothing to refuse";
    Image color(w, h, 3, 0.5f), hist(w, h, 7, 1.f);  // 2 bins a channel and the count
    RhfOptions o;
    o.searchHalf = 20;
    std::string error = ErrorOf([&] { RhfDenoise(Ctx(), color, hist, o); });
    EXPECT_TRUE(Contains(error, "selection mask")) << error;
    EXPECT_TRUE(Contains(error, "search half-window 20")) << error;
}

}  // namespace
}  // namespace mcd::test
