// Method rhf: the GPU filter against the CPU reference (cpu_reference/rhf.h) on random
// histograms and edge sizes, the split paths, reruns, and the properties of issue #4.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
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
#include "host/common/parallel.h"
#include "host/error.h"
#include "host/kernels/rhf_blockmax.h"
#include "host/kernels/rhf_select.h"
#include "host/methods/rhf.h"
#include "host/methods/run_memo.h"
#include "host/vk/buffer.h"
#include "host/vk/recorder.h"
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
Tolerance ToleranceFor(const Image &color, const RhfParams &o) {
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
    RhfParams o;
    o.patchHalf = c.patchHalf;
    o.searchHalf = c.searchHalf;
    o.knn = c.knn;
    o.threshold = c.threshold;
    o.scales = 1;
    Image expected = NonNegative(ref::Rhf(f.color, f.hist, o));
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
    RhfParams o;
    o.searchHalf = c.searchHalf;
    o.scales = c.scales;
    ASSERT_EQ(ref::RhfScalesUsed(c.w, c.h, o), c.expectedScales);
    Image expected = ref::Rhf(f.color, f.hist, o);
    o.keepNegative = true;
    RhfResult result = RhfDenoise(Ctx(), f.color, f.hist, o);
    EXPECT_EQ(result.scalesUsed, c.expectedScales);
    EXPECT_TRUE(ImagesMatch(expected, result.image, {}, ToleranceFor(f.color, o)));
    o.keepNegative = false;
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

// The kernel against the CPU twin with `o`; where `off` (o with its option off) differs from
// o, the option must change the twin's output, or the comparison would test nothing new.
void ExpectRhfMatchesWithOption(vk::Context &ctx, const Frame &f, const RhfParams &o,
                                const RhfParams &off, bool optionOn, const char *what) {
    Image expected = ref::Rhf(f.color, f.hist, o);
    EXPECT_TRUE(ImagesMatch(expected, RhfDenoise(ctx, f.color, f.hist, o).image, {},
                            ToleranceFor(f.color, o)));
    if (optionOn) {
        EXPECT_FALSE(
            ImagesMatch(expected, ref::Rhf(f.color, f.hist, off), {}, ToleranceFor(f.color, o)))
            << "the " << what << " changed nothing on this frame";
    }
}

class RhfKernelBrightVeto : public GpuTestWithParam<BrightVetoCase> {};

TEST_P(RhfKernelBrightVeto, MatchesReference) {
    const auto [scales, veto] = GetParam();
    // The same frame for every case.
    Frame f = MakeFrame(31, 27, SeedFromName("rhf veto"));
    RhfParams o;
    o.searchHalf = 4;
    o.scales = scales;
    o.brightVeto = veto;
    o.keepNegative = true;
    RhfParams off = o;
    off.brightVeto = 0;
    ExpectRhfMatchesWithOption(Ctx(), f, o, off, veto > 0, "veto");
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

// The pooled bright veto (beyond the authors' tool, the finest scale): GPU against CPU with
// it off (the default), at bounds 1, 2 and 6 (the one the docs measure), at one and two
// scales, the bright veto on (BrightVetoCase::veto holds the pool's bound here). The frame's
// brightest band holds samples above the histogram's range; the pool must change the
// output, or the test would compare nothing new.
class RhfKernelBrightPool : public GpuTestWithParam<BrightVetoCase> {};

TEST_P(RhfKernelBrightPool, MatchesReference) {
    const auto [scales, pool] = GetParam();
    Frame f = MakeFrame(33, 29, SeedFromName("rhf pool"));
    RhfParams o;
    o.searchHalf = 4;
    o.scales = scales;
    o.brightPool = pool;
    o.keepNegative = true;
    RhfParams off = o;
    off.brightPool = 0;
    ExpectRhfMatchesWithOption(Ctx(), f, o, off, pool > 0, "pooled veto");
}

std::vector<BrightVetoCase> BrightPoolCases() {
    std::vector<BrightVetoCase> cases;
    for (int scales : {1, 2})
        for (float pool : {0.f, 1.f, 2.f, 6.f}) cases.push_back({scales, pool});
    return cases;
}

INSTANTIATE_TEST_SUITE_P(Cases, RhfKernelBrightPool, testing::ValuesIn(BrightPoolCases()),
                         [](const testing::TestParamInfo<BrightVetoCase> &info) {
                             return fmt::format("s{}_pool{}", info.param.scales,
                                                NameOf(info.param.veto));
                         });

// The pooled veto where the boxes are cut at the frame's edges: bright samples on the
// border rows and columns only (random counts), GPU against CPU at bounds 2 and 6.
TEST_F(RhfKernel, BrightPoolAtTheEdgesMatchesReference) {
    const int w = 23, h = 19;
    Frame f = MakeFrame(w, h, SeedFromName("rhf pool edges"));
    std::mt19937_64 rng(SeedFromName("rhf pool edge bins"));
    std::uniform_int_distribution<int> bright(0, 6);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c) {
                float &last = f.hist.At(c * kBins + kBins - 1, y, x);
                last = x < 2 || y < 2 || x >= w - 2 || y >= h - 2 ? float(bright(rng)) : 0.f;
            }
    RhfParams o;
    o.searchHalf = 4;
    o.scales = 1;
    o.keepNegative = true;
    const Image off = ref::Rhf(f.color, f.hist, o);
    for (float pool : {2.f, 6.f}) {
        SCOPED_TRACE(fmt::format("pool {}", pool));
        o.brightPool = pool;
        Image expected = ref::Rhf(f.color, f.hist, o);
        EXPECT_TRUE(ImagesMatch(expected, RhfDenoise(Ctx(), f.color, f.hist, o).image, {},
                                ToleranceFor(f.color, o)));
        EXPECT_FALSE(ImagesMatch(expected, off, {}, ToleranceFor(f.color, o)))
            << "the pooled veto changed nothing on this frame";
    }
}

// A saturated field touching the frame's edges (every pixel the same many bright samples)
// is filtered at its border as inside: a box cut at the edge holds fewer bright samples
// but the same rate, so the pooled veto leaves every candidate in, on the GPU and in the
// reference, and each gives its output without the veto, to the bit.
TEST_F(RhfKernel, BrightPoolKeepsASaturatedFieldsBorder) {
    const int w = 21, h = 17, spp = 16;
    Frame f = MakeFrame(w, h, SeedFromName("rhf pool saturated"));
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            for (int i = 0; i < 3 * kBins; ++i) f.hist.At(i, y, x) = 0.f;
            for (int c = 0; c < 3; ++c) f.hist.At(c * kBins + kBins - 1, y, x) = float(spp);
            f.hist.At(3 * kBins, y, x) = float(spp);
        }
    for (int patchHalf : {1, 2})
        for (float pool : {2.f, 6.f}) {
            SCOPED_TRACE(fmt::format("patch half {} pool {}", patchHalf, pool));
            RhfParams o;
            o.searchHalf = 4;
            o.patchHalf = patchHalf;
            o.scales = 1;
            o.keepNegative = true;
            const Image cpuOff = ref::Rhf(f.color, f.hist, o),
                        gpuOff = RhfDenoise(Ctx(), f.color, f.hist, o).image;
            o.brightPool = pool;
            EXPECT_TRUE(BitIdentical(cpuOff, ref::Rhf(f.color, f.hist, o)));
            EXPECT_TRUE(BitIdentical(gpuOff, RhfDenoise(Ctx(), f.color, f.hist, o).image));
        }
}

// The pool's counts the host uploads against the CPU reference's, to the bit: random
// histograms (the bins' fractions as the renderer splits samples), the edges cut.
TEST(RhfBrightPool, HostMatchesReference) {
    for (auto [w, h] : {std::pair{1, 1}, {2, 3}, {17, 11}})
        for (int patchHalf : {0, 1, 2}) {
            SCOPED_TRACE(fmt::format("{}x{} w {}", w, h, patchHalf));
            Frame f = MakeFrame(w, h, SeedFromName(fmt::format("rhf pool {}x{}", w, h)));
            std::mt19937_64 rng(SeedFromName(fmt::format("rhf pool bins {}x{}", w, h)));
            std::uniform_real_distribution<float> fraction(0.f, 3.f);
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x)
                    for (int c = 0; c < 3; ++c)
                        if (rng() % 3 == 0)
                            f.hist.At(c * kBins + kBins - 1, y, x) = fraction(rng);
            std::vector<float> host = RhfBrightPool(f.hist, patchHalf),
                               cpu = ref::RhfBrightPool(f.hist, patchHalf);
            ASSERT_EQ(host.size(), cpu.size());
            EXPECT_EQ(std::memcmp(host.data(), cpu.data(), host.size() * sizeof(float)), 0);
            EXPECT_GT(*std::max_element(cpu.begin(), cpu.end()), 0.f);
        }
}

// --explain's selection line names the nearest count and the threshold in their places,
// with the pooled veto's text after the threshold only when it is on.
TEST_F(RhfKernel, PlanNamesTheSelection) {
    Frame f = MakeFrame(21, 19, SeedFromName("rhf plan"));
    RhfParams o;
    o.searchHalf = 4;
    o.knn = 3;
    o.threshold = 0.75f;
    auto planOf = [&](const RhfParams &params) {
        std::string plan;
        for (const std::string &line : RhfDenoise(Ctx(), f.color, f.hist, params).plan)
            plan += line + "\n";
        return plan;
    };
    const std::string off = planOf(o);
    EXPECT_NE(
        off.find("selection of 4 nearest (itself + k_NN) + distance < 0.75 in 1 strip(s)"),
        std::string::npos)
        << off;
    EXPECT_EQ(off.find("pooled"), std::string::npos) << off;
    o.brightPool = 6;
    const std::string on = planOf(o);
    EXPECT_NE(on.find("selection of 4 nearest (itself + k_NN) + distance < 0.75, no candidate "
                      "whose bright samples pooled"),
              std::string::npos)
        << on;
    EXPECT_NE(on.find("> 6 (P/aP^2 + Q/aQ^2) in 1 strip(s)"), std::string::npos) << on;
}

// Histograms split over several buffers and distances computed in thin strips (the
// paths big frames take) give the same bits as the one-buffer, one-strip run; at two
// scales the buffers are downsampled in turn through one scratch.
struct SplitCase {
    int planesPerSlot, stripRows, scales;
};

class RhfKernelSplit : public GpuTestWithParam<SplitCase> {};

TEST_P(RhfKernelSplit, IsBitIdentical) {
    const auto [perSlot, strip, scales] = GetParam();
    Frame f = MakeFrame(33, 31, SeedFromName("rhf split"));
    RhfParams o;
    o.searchHalf = 4;
    o.scales = scales;
    Image whole = RhfDenoise(Ctx(), f.color, f.hist, o).image;
    RunSetup split;
    split.planesPerSlot = perSlot;
    split.stripRows = strip;
    EXPECT_TRUE(BitIdentical(whole, RhfDenoise(Ctx(), f.color, f.hist, o, split).image));
}

INSTANTIATE_TEST_SUITE_P(Cases, RhfKernelSplit,
                         testing::Values(SplitCase{11, 0, 1}, SplitCase{0, 3, 1},
                                         SplitCase{13, 1, 1}, SplitCase{11, 0, 2},
                                         SplitCase{13, 2, 2}),
                         [](const testing::TestParamInfo<SplitCase> &info) {
                             return fmt::format("planes{}_rows{}_s{}", info.param.planesPerSlot,
                                                info.param.stripRows, info.param.scales);
                         });

TEST_F(RhfKernel, RerunsAreBitIdentical) {
    Frame f = MakeFrame(45, 38, SeedFromName("rhf rerun"));
    RhfParams o;
    Image first = RhfDenoise(Ctx(), f.color, f.hist, o).image;
    EXPECT_TRUE(BitIdentical(first, RhfDenoise(Ctx(), f.color, f.hist, o).image));
}

// auto's runs share the selections (RunSetup::memo): a run on another colour over the same
// histograms, one with another patch size on the same colour, and one at two scales after
// those at one scale (which takes scale 0's aggregation of the same colour and selection,
// not the other patch size's), give what they give alone; a colour with a NaN (which
// empties its pixel's histogram) neither takes nor leaves one.
TEST_F(RhfKernel, SharedSelectionsAreBitIdentical) {
    Frame f = MakeFrame(37, 34, SeedFromName("rhf memo"));
    Image perturbed = f.color, broken = f.color;
    std::mt19937 rng(SeedFromName("rhf memo probe"));
    for (float &v : perturbed.data) v += (rng() & 1u) ? 0.05f : -0.05f;
    broken.data[5] = std::numeric_limits<float>::quiet_NaN();
    RhfParams one, wider, two;
    one.searchHalf = wider.searchHalf = two.searchHalf = 4;
    wider.patchHalf = one.patchHalf + 1;
    two.scales = 2;
    RunMemo memo;
    RunSetup shared;
    shared.memo = &memo;
    for (const RhfParams &o : {one, wider, two})
        for (const Image *color : {&f.color, &perturbed, &broken}) {
            SCOPED_TRACE(fmt::format("{} scale(s), patch half {}, colour {}", o.scales,
                                     o.patchHalf,
                                     color == &f.color     ? "as made"
                                     : color == &perturbed ? "perturbed"
                                                           : "with a NaN"));
            EXPECT_TRUE(BitIdentical(RhfDenoise(Ctx(), *color, f.hist, o).image,
                                     RhfDenoise(Ctx(), *color, f.hist, o, shared).image));
        }
    // The finest scale's selection of each patch size and the coarse one's; scale 0's
    // aggregation of each finite colour per patch size, made at one scale and taken at two.
    EXPECT_EQ(memo.CountWithPrefix("rhf.mask"), 3u);
    EXPECT_EQ(memo.CountWithPrefix("rhf.filtered0"), 4u);
    // What the histograms hold that the filter cannot use, counted once.
    EXPECT_EQ(memo.CountWithPrefix("rhf.unusable"), 1u);
    EXPECT_EQ(memo.Size(), 8u);
}

// A run at two scales on a colour no earlier run aggregated takes the selections alone, and
// one whose every selection is kept (its histograms not uploaded) gives what it gives alone.
TEST_F(RhfKernel, KeptSelectionsWithoutTheirAggregationAreBitIdentical) {
    Frame f = MakeFrame(41, 36, SeedFromName("rhf memo two scales"));
    Image brighter = f.color;
    for (float &v : brighter.data) v *= 1.5f;
    RhfParams one, two;
    one.searchHalf = two.searchHalf = 4;
    two.scales = 2;
    RunMemo memo;
    RunSetup shared;
    shared.memo = &memo;
    RhfDenoise(Ctx(), f.color, f.hist, one, shared);
    EXPECT_TRUE(BitIdentical(RhfDenoise(Ctx(), brighter, f.hist, two).image,
                             RhfDenoise(Ctx(), brighter, f.hist, two, shared).image));
    EXPECT_EQ(memo.CountWithPrefix("rhf.mask"), 2u);
    // Every selection kept now: a third colour at two scales uploads no histograms.
    Image darker = f.color;
    for (float &v : darker.data) v *= 0.5f;
    EXPECT_TRUE(BitIdentical(RhfDenoise(Ctx(), darker, f.hist, two).image,
                             RhfDenoise(Ctx(), darker, f.hist, two, shared).image));
    EXPECT_EQ(memo.CountWithPrefix("rhf.mask"), 2u);
}

class RhfProperties : public GpuTest {};

// No k_NN and a threshold just above 0 select only the patch itself (k_NN 1 now takes one
// neighbour besides it, as the tool does): every estimate of a pixel is its own value,
// and a mean of equal values is that value up to the rounding of the sum.
TEST_F(RhfProperties, OnlyItselfLeavesTheImageUnchanged) {
    Frame f = MakeFrame(21, 17, SeedFromName("rhf identity"));
    RhfParams o;
    o.threshold = 1e-30f;
    o.knn = 0;
    o.scales = 1;
    Image out = RhfDenoise(Ctx(), f.color, f.hist, o).image;
    EXPECT_TRUE(ImagesMatch(f.color, out, {}, {20 * kUnitRoundoff, 0, 1e-12}));
}

// At two scales too: the coarse scale then selects only itself as well, so u_1 is D(u)
// and the recombination adds U(D(u)) - U(D(u)), the same bits computed twice.
TEST_F(RhfProperties, OnlyItselfAtTwoScalesLeavesTheImageUnchanged) {
    Frame f = MakeFrame(30, 28, SeedFromName("rhf identity 2"));
    RhfParams o;
    o.threshold = 1e-30f;
    o.knn = 0;
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
    RhfParams o;
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
    RhfParams o;
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
    RhfParams o;
    o.scales = 2;
    o.keepNegative = true;
    Image raw = RhfDenoise(Ctx(), f.color, f.hist, o).image;
    size_t negative = 0;
    for (float v : raw.data) negative += v < 0;
    ASSERT_GT(negative, 0u) << "the edge no longer overshoots: the test needs a stronger one";
    o.keepNegative = false;
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
    RhfParams o;
    o.scales = 1;
    Image kept = RhfDenoise(Ctx(), f.color, f.hist, o).image;
    // Means of equal values: a few round-offs of the light's value.
    EXPECT_TRUE(ImagesMatch(f.color, kept, {}, {0, 16 * kUnitRoundoff * lightMean, 1e-12}));
    EXPECT_TRUE(ImagesMatch(ref::Rhf(f.color, f.hist, o), kept, {}, ToleranceFor(f.color, o)));
    o.brightVeto = 0;
    o.brightPool = 0;
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
    RhfParams o;
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

// Sanitize's rows split over threads: the same output bits and the same counts as one loop.
TEST_F(RhfProperties, BadPixelsSameBitsWhenSplitOverThreads) {
    const int w = 23, h = 19, n3 = 3 * kBins;
    Frame f = MakeFrame(w, h, SeedFromName("rhf bad split"));
    f.color.At(0, 3, 4) = std::numeric_limits<float>::quiet_NaN();
    f.color.At(2, 18, 11) = std::numeric_limits<float>::infinity();
    f.hist.At(n3, 5, 5) = 0;
    f.hist.At(3, 12, 2) = std::numeric_limits<float>::quiet_NaN();
    f.hist.At(n3, 0, 22) = -2;
    RhfParams o;
    RhfResult serial, split;
    {
        ForceParallelParts force(1);
        serial = RhfDenoise(Ctx(), f.color, f.hist, o);
    }
    {
        ForceParallelParts force(5);
        split = RhfDenoise(Ctx(), f.color, f.hist, o);
    }
    ASSERT_EQ(serial.image.data.size(), split.image.data.size());
    EXPECT_EQ(0, std::memcmp(serial.image.data.data(), split.image.data.data(),
                             serial.image.data.size() * sizeof(float)));
    EXPECT_EQ(serial.warnings, split.warnings);
    EXPECT_EQ(serial.warnings.size(), 3u);
}

// With a memo the histograms' unusable values are counted once: runs on other finite colours
// over the same histograms warn and give what they give alone, and runs over other
// histograms with other unusable values through the same memo count their own.
TEST_F(RhfProperties, BadHistogramsSharedAcrossRunsWarnAsAlone) {
    const int w = 22, h = 18, n3 = 3 * kBins;
    Frame f = MakeFrame(w, h, SeedFromName("rhf bad shared"));
    Image other = f.hist;
    f.hist.At(n3, 5, 5) = 0;
    f.hist.At(3, 12, 2) = std::numeric_limits<float>::quiet_NaN();
    f.hist.At(n3, 0, 21) = -2;
    // Another NaN bin and no sample-less pixel: one warning where f.hist gives two.
    other.At(7, 9, 14) = std::numeric_limits<float>::quiet_NaN();
    Image brighter = f.color;
    for (float &v : brighter.data) v *= 1.5f;
    RhfParams o;
    o.searchHalf = 4;
    RunMemo memo;
    RunSetup shared;
    shared.memo = &memo;
    for (const Image *hist : {&f.hist, &other})
        for (const Image *color : {&f.color, &brighter}) {
            SCOPED_TRACE(fmt::format("histograms {}, colour {}", hist == &f.hist ? 1 : 2,
                                     color == &f.color ? "as made" : "brighter"));
            RhfResult alone = RhfDenoise(Ctx(), *color, *hist, o);
            RhfResult taken = RhfDenoise(Ctx(), *color, *hist, o, shared);
            EXPECT_TRUE(BitIdentical(alone.image, taken.image));
            EXPECT_EQ(alone.warnings, taken.warnings);
            EXPECT_EQ(taken.warnings.size(), hist == &f.hist ? 2u : 1u);
        }
    EXPECT_EQ(memo.CountWithPrefix("rhf.unusable"), 2u);
}

TEST_F(RhfProperties, BadShapesAndOptionsAreErrors) {
    Frame f = MakeFrame(8, 8, 1);
    RhfParams o;
    Image wrong(8, 8, 60);
    EXPECT_TRUE(
        ThrowsError(ErrorKind::InvalidArgument, [&] { RhfDenoise(Ctx(), f.color, wrong, o); }));
    Image small(4, 8, f.hist.channels);
    EXPECT_TRUE(
        ThrowsError(ErrorKind::InvalidArgument, [&] { RhfDenoise(Ctx(), f.color, small, o); }));
    o.knn = 1000;
    EXPECT_TRUE(ThrowsError(ErrorKind::InvalidArgument,
                            [&] { RhfDenoise(Ctx(), f.color, f.hist, o); }));
    o = {};
    o.threshold = -1;
    EXPECT_TRUE(ThrowsError(ErrorKind::InvalidArgument,
                            [&] { RhfDenoise(Ctx(), f.color, f.hist, o); }));
    o = {};
    o.brightVeto = -0.1f;
    EXPECT_TRUE(ThrowsError(ErrorKind::InvalidArgument,
                            [&] { RhfDenoise(Ctx(), f.color, f.hist, o); }));
    o.brightVeto = std::numeric_limits<float>::quiet_NaN();
    EXPECT_TRUE(ThrowsError(ErrorKind::InvalidArgument,
                            [&] { RhfDenoise(Ctx(), f.color, f.hist, o); }));
}

// The bin maxima per block (blockmax.comp) against ref::RhfBlockMax, bit for bit (a max
// of products in float): widths below, at and past a block, empty pixels (count 0, whose
// bins are left out even when non-zero), whole empty blocks, histograms split over several
// buffers (the count plane in a buffer of its own or sharing one), a histScale below 1.
class RhfBlockmaxKernel : public GpuTest {};

TEST_F(RhfBlockmaxKernel, MatchesReference) {
    std::mt19937_64 rng(SeedFromName("rhf block maxima"));
    std::uniform_real_distribution<float> bin(0.f, 3.f);
    struct Case {
        int w, h, bins, perSlot;
        float scale;
    };
    for (Case c : {Case{1, 1, 1, 0, 1.f}, Case{8, 3, 2, 0, 1.f}, Case{37, 5, 3, 4, 0.37f},
                   Case{17, 4, 3, 3, 1.f}, Case{9, 2, 20, 7, 2.5f}}) {
        SCOPED_TRACE(fmt::format("{}x{}, {} bins, {} planes per buffer, scale {}", c.w, c.h,
                                 c.bins, c.perSlot, c.scale));
        const int planes = 3 * c.bins + 1, perSlot = c.perSlot > 0 ? c.perSlot : planes;
        Image hist(c.w, c.h, planes);
        for (int y = 0; y < c.h; ++y)
            for (int x = 0; x < c.w; ++x) {
                // Every third pixel empty, and the second block of row 1 wholly.
                bool empty = (x + y) % 3 == 2 || (y == 1 && x / 8 == 1);
                for (int i = 0; i < planes - 1; ++i)
                    hist.At(i, y, x) = rng() % 4 ? bin(rng) : 0.f;
                hist.At(planes - 1, y, x) = empty ? 0.f : float(1 + rng() % 16);
            }
        RhfHistogram gpu;
        gpu.width = c.w;
        gpu.height = c.h;
        gpu.planes = planes;
        gpu.planesPerSlot = perSlot;
        for (int first = 0; first < planes; first += perSlot) {
            int count = std::min(perSlot, planes - first);
            vk::Buffer &slot = gpu.slots.emplace_back(
                Ctx(), size_t(count) * hist.PixelCount() * sizeof(float), "hist");
            slot.Upload(hist.Plane(first), size_t(count) * hist.PixelCount() * sizeof(float));
        }
        Image expected = ref::RhfBlockMax(hist, c.scale, 8);
        vk::Buffer out(Ctx(), expected.data.size() * sizeof(float), "blockMax");
        vk::Recorder recorder(Ctx());
        RecordRhfBlockMax(Ctx(), recorder, gpu, c.scale, out);
        recorder.Submit();
        std::vector<float> got(expected.data.size());
        out.Download(got.data(), got.size() * sizeof(float));
        ASSERT_EQ(expected.width, RhfBlocks(c.w));
        for (size_t i = 0; i < got.size(); ++i)
            ASSERT_EQ(std::bit_cast<uint32_t>(expected.data[i]),
                      std::bit_cast<uint32_t>(got[i]))
                << "at " << i << ": " << expected.data[i] << " against " << got[i];
    }
}

// The selection kernel against the reference's selection sort on distances drawn from a
// few values, so that ties at the cut are the rule: every nearest from 0 past the window,
// thresholds below, at and between the values, vetoed and out-of-window candidates (-1).
class RhfSelectKernel : public GpuTest {};

TEST_F(RhfSelectKernel, MatchesTheToolsSortOnTies) {
    std::mt19937_64 rng(SeedFromName("rhf select ties"));
    const float values[] = {-1.f, 0.f, 0.5f, 1.f, 1.f, 2.f};
    for (int b : {0, 1, 2, 3}) {
        const int side = 2 * b + 1, offsets = side * side, w = 9, rows = 3;
        for (int nearest : {0, 1, 2, 3, 5, offsets - 1, offsets, offsets + 3})
            for (float threshold : {0.f, 0.5f, 1.f, 1.5f, 3.f}) {
                SCOPED_TRACE(
                    fmt::format("b {} nearest {} threshold {}", b, nearest, threshold));
                std::vector<float> d(size_t(offsets) * rows * w);
                for (float &v : d) v = values[rng() % 6];
                vk::Buffer dist(Ctx(), d.size() * sizeof(float), "dist"),
                    mask(Ctx(), size_t(RhfMaskWords(b)) * rows * w * sizeof(uint32_t), "mask");
                dist.UploadFloats(d);
                vk::Recorder recorder(Ctx());
                RecordRhfSelect(Ctx(), recorder, w, rows, b, 0, rows, nearest, threshold, dist,
                                dist, 0.f, 1, mask);
                recorder.Submit();
                std::vector<uint32_t> bits(size_t(RhfMaskWords(b)) * rows * w);
                mask.Download(bits.data(), bits.size() * sizeof(uint32_t));
                for (int y = 0; y < rows; ++y)
                    for (int x = 0; x < w; ++x) {
                        // The window column by column (offset o = dy * side + dx).
                        std::vector<double> valid;
                        std::vector<int> offsetOf;
                        for (int dx = 0; dx < side; ++dx)
                            for (int dy = 0; dy < side; ++dy) {
                                int o = dy * side + dx;
                                float v = d[(size_t(o) * rows + y) * w + x];
                                if (v < 0) continue;
                                valid.push_back(v);
                                offsetOf.push_back(o);
                            }
                        std::vector<bool> picked = ref::RhfSelect(valid, nearest, threshold);
                        std::vector<bool> gpu(offsets, false), cpu(offsets, false);
                        for (size_t i = 0; i < valid.size(); ++i) cpu[offsetOf[i]] = picked[i];
                        for (int o = 0; o < offsets; ++o)
                            gpu[o] = bits[(size_t(o / 32) * rows + y) * w + x] >> (o % 32) & 1u;
                        ASSERT_EQ(cpu, gpu) << fmt::format("centre ({}, {})", x, y);
                    }
            }
    }
}

}  // namespace
}  // namespace mcd::test

namespace mcd::test {
namespace {

// Issue #20: the sampling, interpolation, rescale and kNN count of the authors' tool.
class RhfToolAlignment : public GpuTest {};

const Image *StageOf(const RhfResult &result, const std::string &name) {
    for (const auto &[stageName, image] : result.stages)
        if (stageName == name) return &image;
    return nullptr;
}

// A ramp along x through D_1 lands where the tool samples: output x is the Gaussian of the
// input centred on 2x + 0.5 (between fine pixels 2x and 2x + 1), its taps running from
// 2x + 1 - h to 2x + 1 + h, one further right than left, which moves the mean by
// delta = sum_i g(i - h + 0.5) (i - h + 0.5) over the normalised taps. Mirrored edges
// give the ramp's mirror image there. CPU and GPU (the "color s1" stage) alike.
TEST_F(RhfToolAlignment, RampThroughTheDownsamplerLandsWhereTheToolSamples) {
    const int w = 32, h = 30;
    Frame f = MakeFrame(w, h, SeedFromName("rhf ramp"));
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) f.color.At(c, y, x) = float(x);
    double sigma = 0.55 * std::sqrt(3.0);
    int radius = int(std::ceil(sigma * std::sqrt(4 * std::log(10.0))));
    ASSERT_EQ(radius, 3);
    std::vector<double> g;
    double total = 0, delta = 0;
    for (int i = -radius; i <= radius; ++i)
        total += g.emplace_back(std::exp(-0.5 * std::pow((i + 0.5) / sigma, 2)));
    for (int i = -radius; i <= radius; ++i) delta += g[i + radius] / total * (i + 0.5);
    Image cpu = ref::RhfGaussianDownsample(f.color, 1, sigma);
    RhfParams o;
    o.scales = 2;
    o.searchHalf = 4;
    RunSetup setup;
    setup.keepStages = true;
    RhfResult result = RhfDenoise(Ctx(), f.color, f.hist, o, setup);
    const Image *gpu = StageOf(result, "color s1");
    ASSERT_NE(gpu, nullptr);
    ASSERT_EQ(cpu.width, w / 2);
    for (int x = 0; x < w / 2; ++x) {
        SCOPED_TRACE(fmt::format("x = {}", x));
        double expected = 0;
        if (x >= 2 && x <= w / 2 - 3) {
            expected = 2 * x + 0.5 + delta;  // taps inside the image
        } else {
            for (int i = -radius; i <= radius; ++i)
                expected += g[i + radius] / total * ref::RhfMirror(2 * x + 1 + i, w);
        }
        // 7 products of values below w: a few round-offs of w.
        EXPECT_NEAR(cpu.At(1, 5, x), expected, 8 * kUnitRoundoff * w);
        EXPECT_NEAR(gpu->At(1, 5, x), expected, 8 * kUnitRoundoff * w);
    }
    EXPECT_GT(delta, 1e-3);  // the asymmetry is there, and small
    EXPECT_LT(delta, 3e-3);
    EXPECT_EQ(ref::RhfMirror(-1, 5), 0);
    EXPECT_EQ(ref::RhfMirror(5, 5), 4);
    EXPECT_EQ(ref::RhfMirror(-11, 5), 0);
    EXPECT_EQ(ref::RhfMirror(12, 5), 2);
}

// The upsampler aligns pixel centres: fine x reads coarse (x + 0.5) / 2 - 0.5, and Keys'
// kernel (a = -0.5) reproduces a ramp exactly, so a coarse ramp i comes back as
// x / 2 - 0.25 away from the edges.
TEST(RhfReference, RampThroughTheUpsamplerKeepsPixelCentres) {
    const int cw = 12, w = 24;
    Image coarse(cw, 3, 1);
    for (int y = 0; y < 3; ++y)
        for (int i = 0; i < cw; ++i) coarse.At(0, y, i) = float(i);
    Image fine = ref::RhfBicubicUpsample(coarse, w, 6);
    for (int x = 3; x < w - 3; ++x) EXPECT_NEAR(fine.At(0, 2, x), x / 2.0 - 0.25, 1e-5) << x;
    // At the edge the mirror repeats pixel 0: x = 0 reads -0.25, between i = -1 (0) and 0.
    EXPECT_LT(fine.At(0, 2, 0), 0.0f + 1e-6f);
    EXPECT_GT(fine.At(0, 2, 0), -0.25f);
}

// Distances for 1x1 patches built to tie: 2 bins a colour, 8 samples a pixel, pixel
// histograms (8,0), (4,4) or (0,8) per colour. (8,0) against (4,4) gives 16/3 per colour,
// against (0,8) 16: ties are bitwise, the same terms in the same order.
Frame TieFrame(int w, int h, const std::vector<int> &kind) {
    Frame f{Image(w, h, 3), Image(w, h, 7)};
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            int k = kind[size_t(y) * w + x];
            for (int c = 0; c < 3; ++c) {
                f.color.At(c, y, x) = float(y * w + x + 1);
                f.hist.At(2 * c, y, x) = float(8 - 4 * k);
                f.hist.At(2 * c + 1, y, x) = float(4 * k);
            }
            f.hist.At(6, y, x) = 8;
        }
    return f;
}

// k_NN 1 takes two patches, the centre and its nearest, as the tool's selection sort picks
// them. In a row (kinds 1 1 0 2 2) centre 2's first pass finds itself and swaps it with
// candidate 0, which lands behind candidate 1: the tie between 0 and 1 (16/3 each, above
// the threshold 1) goes to 1, so pixel 2 is (3 + 2) / 2. In a 3x3 (centre kind 0, corners
// (0,2) and (2,0) kind 1, the rest kind 2) the tie goes to the column first in the tool's
// column-by-column order, (0,2): pixel (1,1) is (5 + 7) / 2.
TEST_F(RhfToolAlignment, KnnTiesResolveAsTheToolsSelectionSort) {
    struct Case {
        int w, h, x, y;
        std::vector<int> kind;
        float expected;
    };
    for (const Case &c : {Case{5, 1, 2, 0, {1, 1, 0, 2, 2}, 2.5f},
                          Case{3, 3, 1, 1, {2, 2, 1, 2, 0, 2, 1, 2, 2}, 6.f}}) {
        SCOPED_TRACE(fmt::format("{}x{}", c.w, c.h));
        Frame f = TieFrame(c.w, c.h, c.kind);
        ASSERT_EQ(ref::RhfPatchDistance(f.hist, c.x, c.y, 0, c.h - 1, 0),
                  ref::RhfPatchDistance(f.hist, c.x, c.y, c.w - 1 - (c.h == 1 ? 3 : 0), 0, 0));
        RhfParams o;
        o.patchHalf = 0;
        o.searchHalf = 2;
        o.knn = 1;
        o.threshold = 1;
        o.scales = 1;
        o.brightVeto = 0;
        o.brightPool = 0;
        Image cpu = ref::RhfSingleScale(f.color, f.hist, 0, 2, 1.0, 1);
        Image gpu = RhfDenoise(Ctx(), f.color, f.hist, o).image;
        EXPECT_FLOAT_EQ(cpu.At(0, c.y, c.x), c.expected);
        EXPECT_FLOAT_EQ(gpu.At(0, c.y, c.x), c.expected);
        EXPECT_TRUE(ImagesMatch(cpu, gpu, {}, ToleranceFor(f.color, o)));
    }
}

// The coarse histograms are rescaled to keep the count channel's total, not the bins'.
// A frame whose bins hold a varying part of its count (samples outside every bin) and
// whose count is constant: D_1 of a constant is that constant, so the factor is the
// pixel ratio W H / (W_1 H_1), whatever the bins hold. Then GPU against CPU.
TEST_F(RhfToolAlignment, CoarseHistogramsKeepTheCountChannelsTotal) {
    const int w = 27, h = 30, n3 = 3 * kBins;
    Frame f = MakeFrame(w, h, SeedFromName("rhf count rescale"));
    std::mt19937_64 rng(SeedFromName("rhf count rescale drop"));
    std::uniform_real_distribution<float> keep(0.3f, 1.f);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float part = keep(rng);
            for (int i = 0; i < n3; ++i) f.hist.At(i, y, x) *= part;
            f.hist.At(n3, y, x) = 24;
        }
    RhfParams o;
    o.searchHalf = 4;
    o.scales = 2;
    o.keepNegative = true;
    RhfResult result = RhfDenoise(Ctx(), f.color, f.hist, o);
    ASSERT_EQ(result.scalesUsed, 2);
    double expected = double(w * h) / (14 * 15);
    std::string plan;
    for (const std::string &line : result.plan) plan += line + "\n";
    size_t at = plan.find("histograms rescaled by ");
    ASSERT_NE(at, std::string::npos) << plan;
    double factor = std::stod(plan.substr(at + 23));
    // The factor is a float; the taps sum to 1 up to a few round-offs per axis.
    EXPECT_NEAR(factor, expected, 16 * kUnitRoundoff * expected) << plan;
    EXPECT_TRUE(
        ImagesMatch(ref::Rhf(f.color, f.hist, o), result.image, {}, ToleranceFor(f.color, o)));
}

class RhfLimits : public GpuTest {};

// A frame whose selection mask cannot be one binding is refused by the pipeline up front
// (mcd::Method runs it in tiles: tests/methods/tiled_run_test.cpp), naming the window and
// the limit: 640x1024 with search half-window 20 needs 53 words a pixel.
TEST_F(RhfLimits, RefusesAMaskAboveTheBindingLimit) {
    const int w = 640, h = 1024;
    size_t maskBytes = size_t(53) * w * h * 4;
    if (maskBytes <= Ctx().Limits().maxStorageBufferRange)
        GTEST_SKIP() << "this device binds " << Ctx().Limits().maxStorageBufferRange
                     << " bytes: the frame fits, nothing to refuse";
    Image color(w, h, 3, 0.5f), hist(w, h, 7, 1.f);  // 2 bins a channel and the count
    RhfParams o;
    o.searchHalf = 20;
    EXPECT_TRUE(ThrowsError(
        ErrorKind::OutOfMemory, [&] { RhfDenoise(Ctx(), color, hist, o); },
        "search half-window 20"));
}

}  // namespace
}  // namespace mcd::test
