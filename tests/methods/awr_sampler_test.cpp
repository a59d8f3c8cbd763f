// AWR's adaptive sampler (section 4.1): budget, determinism, adaptation, scale-function
// profiles, and what it is for: lower error after reconstruction than uniform sampling.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "cpu_reference/wavelet_analyze.h"
#include "cpu_reference/wavelet_sqanalyze.h"
#include "harness/compare.h"
#include "harness/errors.h"
#include "harness/gpu_fixture.h"
#include "harness/gpu_wavelet.h"
#include "harness/inputs.h"
#include "host/methods/awr.h"
#include "host/metrics.h"
#include "host/vk/gpu_image.h"
#include "host/wavelet/transform.h"
#include "tools/render/adaptive.h"

namespace mcd::test {
namespace {

class AwrSampler : public GpuTest {};

render::AdaptiveResult Adaptive(vk::Context &ctx, int w, int h, int spp, uint64_t seed) {
    static const render::Scene scene = render::BuildScene("cornell");
    render::AdaptiveOptions o;
    o.width = w, o.height = h, o.averageSpp = spp, o.seed = seed;
    return render::RenderAdaptive(ctx, scene, o);
}

const Image &Layer(const render::AdaptiveResult &r, const char *name) {
    for (const auto &[n, image] : r.layers)
        if (n == name) return image;
    throw Error(name);
}

TEST_F(AwrSampler, SpendsTheBudgetExactlyAndRepeats) {
    render::AdaptiveResult a = Adaptive(Ctx(), 40, 28, 12, 7),
                           b = Adaptive(Ctx(), 40, 28, 12, 7);
    const Image &spp = Layer(a, "spp");
    double total = std::accumulate(spp.data.begin(), spp.data.end(), 0.0);
    EXPECT_EQ(total, 12.0 * 40 * 28);
    EXPECT_EQ(a.samples, uint64_t(12) * 40 * 28);
    EXPECT_GE(*std::min_element(spp.data.begin(), spp.data.end()), 4.f);
    // Adapted: some pixels got many more samples than others.
    EXPECT_GT(*std::max_element(spp.data.begin(), spp.data.end()), 3 * 4.f);
    for (size_t i = 0; i < a.layers.size(); ++i)
        EXPECT_TRUE(BitIdentical(a.layers[i].second, b.layers[i].second)) << a.layers[i].first;
    EXPECT_GT(a.rounds, 1);
}

TEST_F(AwrSampler, ScaleFunctionProfiles) {
    for (WaveletBasis basis : {WaveletBasis::Haar, WaveletBasis::LeGall53, WaveletBasis::Cdf97})
        for (int level = 0; level <= 5; ++level) {
            render::ScaleProfile p = render::ScaleFunctionProfile(basis, level);
            ASSERT_FALSE(p.cdf.empty());
            EXPECT_TRUE(std::is_sorted(p.cdf.begin(), p.cdf.end()));
            EXPECT_EQ(p.cdf.back(), 1.0);
            // Support: (taps - 1)(2^k - 1) + 1 positions; symmetric banks centred on 0.
            int reach =
                basis == WaveletBasis::Cdf97 ? 3 : (basis == WaveletBasis::LeGall53 ? 1 : 0);
            if (basis != WaveletBasis::Haar) {
                EXPECT_EQ(int(p.cdf.size()), 2 * reach * ((1 << level) - 1) + 1);
                EXPECT_EQ(p.origin, -reach * ((1 << level) - 1));
            } else {
                EXPECT_EQ(int(p.cdf.size()), 1 << level);  // a box of 2^k pixels
                EXPECT_EQ(p.origin, 0);
            }
        }
}

// Where the samples go (section 4.1, figure 3): a sharp edge gets them from fine levels, a
// smooth region of high variance from coarse ones. The integrand is known: columns
// x < 12.5 are 1 and the rest of the left half 0.1, noise-free, so only the pixels the
// edge crosses vary; the right half is 0.5 with uniform noise of +-90%, smooth underneath.
TEST_F(AwrSampler, EdgesFromFineLevelsSmoothNoiseFromCoarse) {
    const int w = 64, h = 64;
    render::TraceFunction trace = [](double x, double y, uint64_t key) {
        if (x < 32) return render::Vec3(x < 12.5 ? 1.0 : 0.1);
        double u = double(render::Mix(key ^ 0x9e3779b97f4a7c15ull) >> 11) * 0x1p-53;
        return render::Vec3(0.5 * (1 + 0.9 * (2 * u - 1)));
    };
    render::AdaptiveOptions o;
    o.width = w, o.height = h, o.averageSpp = 32;
    render::AdaptiveResult r = render::SampleAdaptive(Ctx(), trace, o);
    // Mean level that placed the samples landing on the edge column, and in the middle of
    // the noisy half (away from its border with the left half).
    double edge = 0, smooth = 0;
    int edgeN = 0, smoothN = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float level = r.placementLevel.At(0, y, x);
            if (level < 0) continue;
            if (x == 12) edge += level, ++edgeN;
            if (x >= 40 && x < 56) smooth += level, ++smoothN;
        }
    ASSERT_GT(edgeN, h / 2);
    ASSERT_GT(smoothN, 16 * h / 2);
    edge /= edgeN, smooth /= smoothN;
    // Measured: edge 0.11, smooth 3.5 (levels 3 and 4 take 78% of the adaptive samples).
    EXPECT_LT(edge, 1.0);
    EXPECT_GT(smooth, 2.5);
    // The noisy half holds nearly all the variance, and coarse levels serve it.
    EXPECT_GT(r.samplesPerLevel[3] + r.samplesPerLevel[4] + r.samplesPerLevel[5],
              r.samplesPerLevel[0]);
}

// The contrast floor (AwrSamplerParams::contrastFloor): two halves with the same relative
// noise, one at 0.5 and one near black (0.002). Mitchell's contrast (floor 0) is scale-free
// and serves both alike; with the floor, the dark half's noise, small next to 0.1, gets
// few samples beyond the initial 4.
TEST_F(AwrSampler, ContrastFloorSpendsLessOnNearBlack) {
    const int w = 64, h = 32;
    render::TraceFunction trace = [](double x, double y, uint64_t key) {
        double u = double(render::Mix(key ^ 0x9e3779b97f4a7c15ull) >> 11) * 0x1p-53;
        return render::Vec3((x < 32 ? 0.002 : 0.5) * (1 + 0.9 * (2 * u - 1)));
    };
    auto darkShare = [&](float floor) {
        render::AdaptiveOptions o;
        o.width = w, o.height = h, o.averageSpp = 24, o.sampler.contrastFloor = floor;
        render::AdaptiveResult r = render::SampleAdaptive(Ctx(), trace, o);
        const Image &spp = Layer(r, "spp");
        double dark = 0, bright = 0;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) (x < 32 ? dark : bright) += spp.At(0, y, x);
        return dark / (dark + bright);
    };
    double paper = darkShare(0.f), floored = darkShare(0.1f);
    // Measured: 0.48 and 0.12 of the samples on the dark half (the initial 4 spp alone are
    // 4 / 24 / 2 = 0.083).
    EXPECT_GT(paper, 0.4) << paper;
    EXPECT_LT(floored, 0.2) << floored;
    EXPECT_TRUE(ThrowsError(ErrorKind::InvalidArgument, [&] { darkShare(-1.f); }));
    EXPECT_TRUE(ThrowsError(ErrorKind::InvalidArgument, [&] { darkShare(NAN); }));
}

// The scalar reference runs the same loop: the wavelet details and scale variances of
// every round from cpu_reference/ (double precision) instead of the GPU. Float and double
// priorities can order near-ties differently, so the runs may part ways; they must agree
// on where the samples go.
TEST_F(AwrSampler, MatchesTheLoopOnTheCpuReference) {
    const int w = 48, h = 40;
    render::TraceFunction trace = [](double x, double y, uint64_t key) {
        if (x < 24) return render::Vec3(x < 9.5 ? 1.0 : 0.1);
        double u = double(render::Mix(key ^ 0x9e3779b97f4a7c15ull) >> 11) * 0x1p-53;
        return render::Vec3(0.5 * (1 + 0.9 * (2 * u - 1)) * (1 + y / h));
    };
    render::AdaptiveOptions o;
    o.width = w, o.height = h, o.averageSpp = 24;
    render::AdaptiveResult gpu = render::SampleAdaptive(Ctx(), trace, o);
    o.transforms = [](const Image &lum, const Image &var, WaveletBasis basis, int levels,
                      float lowSum, Image *details, std::vector<Image> *scaleVariances) {
        *details = ref::WaveletAnalyze(lum, basis, levels);
        scaleVariances->clear();
        for (int k = 1; k <= levels; ++k)
            scaleVariances->push_back(ref::WaveletSqAnalyze(var, basis, k, lowSum, 0));
    };
    render::AdaptiveResult cpu = render::SampleAdaptive(Ctx(), trace, o);
    const Image &a = Layer(gpu, "spp"), &b = Layer(cpu, "spp");
    int same = 0;
    for (size_t i = 0; i < a.Size(); ++i) same += a.data[i] == b.data[i];
    // Measured: every pixel's count and every level's share identical, 13 rounds each.
    EXPECT_GE(same, int(0.98 * a.Size()));
    ASSERT_EQ(gpu.samplesPerLevel.size(), cpu.samplesPerLevel.size());
    for (size_t k = 0; k < gpu.samplesPerLevel.size(); ++k)
        EXPECT_NEAR(double(gpu.samplesPerLevel[k]), double(cpu.samplesPerLevel[k]),
                    0.05 * gpu.samples)
            << "level " << k;
    // The variation across the rows puts samples at several levels, not one.
    int used = 0;
    for (uint64_t n : gpu.samplesPerLevel) used += n > 0;
    EXPECT_GE(used, 2);
}

// The sampler chains one-level squared analyses image to image; each level's corner must
// hold exactly what the in-place multi-level transform leaves there.
TEST_F(AwrSampler, ChainedScaleVariancesMatchTheInPlaceTransform) {
    const int w = 45, h = 37, levels = MaxWaveletLevels(w, h);
    Image variance = MakeVarianceInput(InputKind::Uniform, w, h, 1, SeedFromName("chain"));
    vk::GpuImage in(Ctx(), w, h, 1, "in");
    std::vector<vk::GpuImage> chained;
    for (int k = 0; k < levels; ++k) chained.emplace_back(Ctx(), w, h, 1, "chained");
    in.Upload(variance);
    WaveletTransform transform(Ctx(), w, h, 1);
    vk::Recorder recorder(Ctx());
    for (int k = 0; k < levels; ++k)
        transform.RecordSqAnalysisLevel(recorder, WaveletBasis::Cdf97, k,
                                        k == 0 ? in : chained[k - 1], chained[k], 1.2f, 0.f);
    recorder.Submit();
    for (int k = 1; k <= levels; ++k) {
        Image full = GpuSqAnalyze(Ctx(), variance, WaveletBasis::Cdf97, k, 1.2f, 0.f);
        Image mine = chained[k - 1].Download();
        for (int y = 0; y < LevelExtent(h, k); ++y)
            for (int x = 0; x < LevelExtent(w, k); ++x)
                ASSERT_EQ(mine.At(0, y, x), full.At(0, y, x))
                    << "level " << k << " at " << x << ", " << y;
    }
}

TEST_F(AwrSampler, RefusesATooSmallBudget) {
    EXPECT_TRUE(ThrowsError(ErrorKind::InvalidArgument, [&] { Adaptive(Ctx(), 8, 8, 3, 1); }));
}

// Equal budget, both reconstructed by awr: adaptive sampling ends closer to the converged
// image. Measured with the CLI at 128x128, 16 spp: relMSE 0.022 against 0.052, PSNR 29.7
// against 28.2 dB, SSIM 0.870 against 0.879.
TEST_F(AwrSampler, BeatsUniformSamplingAfterReconstruction) {
    const int w = 96, h = 96, spp = 16;
    render::Scene scene = render::BuildScene("cornell");
    render::RenderOptions uniform;
    uniform.width = w, uniform.height = h, uniform.spp = spp, uniform.seed = 3;
    render::RenderResult u = render::Render(scene, uniform);
    uniform.spp = 512, uniform.seed = 77;
    render::RenderResult converged = render::Render(scene, uniform);
    auto layer = [](const auto &r, const char *name) -> const Image & {
        for (const auto &[n, image] : r.layers)
            if (n == name) return image;
        throw Error(name);
    };
    const Image &reference = layer(converged, "color");
    auto reconstruct = [&](const auto &r) {
        return AwrReconstruct(
                   Ctx(), layer(r, "color"),
                   AwrVarianceFromRange(layer(r, "min"), layer(r, "max"), layer(r, "spp")), {})
            .image;
    };
    ErrorMetrics uniformError = CompareImages(reconstruct(u), reference);
    ErrorMetrics adaptiveError =
        CompareImages(reconstruct(Adaptive(Ctx(), w, h, spp, 3)), reference);
    EXPECT_LT(adaptiveError.relMse, uniformError.relMse)
        << adaptiveError.relMse << " vs " << uniformError.relMse;
    EXPECT_GT(adaptiveError.psnr, uniformError.psnr)
        << adaptiveError.psnr << " vs " << uniformError.psnr;
}

}  // namespace
}  // namespace mcd::test
