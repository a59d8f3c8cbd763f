// The stationary (undecimated) wavelet transform used by method bayes (--bayes-transform
// swt; layout in shaders/wavelet/swt.h): the CPU reference against its definition and the
// foundation's DWT, and the GPU kernels against the reference on random and edge sizes,
// perfect reconstruction, constants, bit-identical reruns and the binding limit.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "bayes/bayes.h"
#include "cpu_reference/bayes_denoise.h"
#include "cpu_reference/wavelet_analyze.h"
#include "cpu_reference/wavelet_swt.h"
#include "harness/bayes_paper.h"
#include "harness/compare.h"
#include "harness/errors.h"
#include "harness/gpu_fixture.h"
#include "harness/inputs.h"
#include "host/kernels/bayes_moments.h"
#include "host/kernels/bayes_swt_moments.h"
#include "host/methods/bayes.h"
#include "host/wavelet/swt.h"
#include "wavelet/swt.h"

namespace mcd::test {
namespace {

constexpr double kUnitRoundoff = 0x1p-24;
const WaveletBasis kBases[] = {WaveletBasis::Haar, WaveletBasis::LeGall53, WaveletBasis::Cdf97};

std::vector<double> RandomLine(int n, uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    std::vector<double> x(n);
    for (double &v : x) v = u(rng);
    return x;
}

// Each case is a test of its own, named by its parameters, so a failing one re-runs alone.
std::string BasisName(const testing::TestParamInfo<WaveletBasis> &info) {
    return WaveletName(info.param);
}

struct SizeCase {
    WaveletBasis basis;
    int w, h, levels;
};

std::string SizeCaseName(const testing::TestParamInfo<SizeCase> &info) {
    const SizeCase &c = info.param;
    return fmt::format("{}_{}x{}_L{}", WaveletName(c.basis), c.w, c.h, c.levels);
}

// ---------------------------------------------------------------- the reference

// Level 0 without decimation holds the DWT: its even low outputs are the DWT's low-pass
// coefficients and its high outputs at 2n (Haar) or 2n + 1 (5/3, 9/7, centred there) the
// DWT's high-pass ones, boundaries included (the same symmetric extensions).
class BayesSwtReferenceLevelZero : public testing::TestWithParam<std::pair<WaveletBasis, int>> {
};

TEST_P(BayesSwtReferenceLevelZero, ContainsTheDwt) {
    const auto [basis, n] = GetParam();
    SCOPED_TRACE(fmt::format("{} n {}", WaveletName(basis), n));
    std::vector<double> x = RandomLine(n, SeedFromName(fmt::format("swt1d{}", n)));
    std::vector<double> low, high;
    ref::SwtAnalyze1D(x, basis, ref::GetFilterBank(basis), 1, true, &low, &high);
    std::vector<double> dwt = ref::Analyze1D(x, basis);
    int nLow = (n + 1) / 2;
    for (int i = 0; i < nLow; ++i) EXPECT_NEAR(low[2 * i], dwt[i], 1e-14) << i;
    int offset = basis == WaveletBasis::Haar ? 0 : 1;
    for (int i = 0; i < n / 2; ++i)
        EXPECT_NEAR(high[2 * i + offset], dwt[nLow + i], 1e-14) << i;
}

std::vector<std::pair<WaveletBasis, int>> LevelZeroCases() {
    std::vector<std::pair<WaveletBasis, int>> cases;
    for (WaveletBasis basis : kBases)
        for (int n : {2, 3, 4, 7, 10, 31}) cases.push_back({basis, n});
    return cases;
}

INSTANTIATE_TEST_SUITE_P(Cases, BayesSwtReferenceLevelZero, testing::ValuesIn(LevelZeroCases()),
                         [](const testing::TestParamInfo<std::pair<WaveletBasis, int>> &info) {
                             return fmt::format("{}_n{}", WaveletName(info.param.first),
                                                info.param.second);
                         });

// Analysis then synthesis is the identity in double, for every level count the image
// allows, on sizes below the filters' reach at the deeper levels.
class BayesSwtReferenceReconstruction : public testing::TestWithParam<SizeCase> {};

TEST_P(BayesSwtReferenceReconstruction, IsPerfect) {
    const auto [basis, w, h, levels] = GetParam();
    SCOPED_TRACE(fmt::format("{} {}x{} levels {}", WaveletName(basis), w, h, levels));
    std::vector<double> x = RandomLine(w * h, SeedFromName(fmt::format("pr{}x{}", w, h)));
    const ref::FilterBank &bank = ref::GetFilterBank(basis);
    auto planes = ref::SwtAnalyzePlane(x, w, h, basis, bank, levels);
    ASSERT_EQ(int(planes.size()), shader::SwtPlaneCount(levels));
    std::vector<double> back = ref::SwtSynthesizePlane(planes, w, h, basis, bank, levels);
    for (size_t i = 0; i < x.size(); ++i) EXPECT_NEAR(back[i], x[i], 1e-12) << i;
}

// Every level count the image allows.
std::vector<SizeCase> ReferenceReconstructionCases() {
    std::vector<SizeCase> cases;
    for (WaveletBasis basis : kBases)
        for (auto [w, h] : {std::pair{1, 1}, std::pair{2, 3}, std::pair{5, 1}, std::pair{7, 6},
                            std::pair{19, 11}, std::pair{40, 9}})
            for (int levels = 0; levels <= MaxWaveletLevels(w, h); ++levels)
                cases.push_back({basis, w, h, levels});
    return cases;
}

INSTANTIATE_TEST_SUITE_P(Cases, BayesSwtReferenceReconstruction,
                         testing::ValuesIn(ReferenceReconstructionCases()), SizeCaseName);

// A constant c: every detail coefficient is 0 (the high-pass taps sum to 0) and the low
// plane is c times the low-pass gain (sum of taps sqrt 2) per transformed axis and level.
class BayesSwtReferenceConstant : public testing::TestWithParam<WaveletBasis> {};

TEST_P(BayesSwtReferenceConstant, HasNoDetail) {
    const WaveletBasis basis = GetParam();
    int w = 13, h = 6, levels = MaxWaveletLevels(w, h);
    std::vector<double> x(w * h, 0.75);
    auto planes = ref::SwtAnalyzePlane(x, w, h, basis, ref::GetFilterBank(basis), levels);
    double gain = 1;
    for (int level = 0; level < levels; ++level) {
        for (int o = 0; o < 3; ++o)
            for (double v : planes[shader::SwtDetailPlane(level, o)]) EXPECT_NEAR(v, 0, 1e-13);
        gain *= (ref::SwtAxisTransformed(w, level) ? std::sqrt(2.0) : 1.0) *
                (ref::SwtAxisTransformed(h, level) ? std::sqrt(2.0) : 1.0);
    }
    for (double v : planes[shader::SwtLowPlane(levels)]) EXPECT_NEAR(v, 0.75 * gain, 1e-12);
}

INSTANTIATE_TEST_SUITE_P(Cases, BayesSwtReferenceConstant, testing::ValuesIn(kBases),
                         BasisName);

// The normalisation the bayes noise model relies on: under white noise every band's
// coefficient variance is the decimated band's (the SWT band is the union of the DWT's
// polyphase bands). Pooled over 8 frames of 192 x 128, the coarsest DWT band (level 2)
// still has 8 x 24 x 16 = 3072 samples: the sampling error of its variance is about
// sqrt(2 / 3072) = 2.6%, the SWT band's (correlated neighbours) of the same order; 10% is
// about 3 sigma of the ratio.
constexpr int kWhiteNoiseLevels = 3;

// Per basis and band, the SWT band's variance over the DWT band's, [level][orientation].
using BandRatios = std::array<std::array<double, 3>, kWhiteNoiseLevels>;

// Every basis's ratios, in kBases' order, measured once: the bases draw their frames from
// one generator, so each basis's noise depends on the bases before it.
const std::vector<BandRatios> &WhiteNoiseBandRatios() {
    static const std::vector<BandRatios> all = [] {
        const int w = 192, h = 128, levels = kWhiteNoiseLevels, frames = 8;
        std::mt19937_64 rng(SeedFromName("swt white noise"));
        std::normal_distribution<double> normal(0, 1);
        std::vector<BandRatios> ratios;
        for (WaveletBasis basis : kBases) {
            double dv[levels][3] = {}, sv[levels][3] = {};
            double dn[levels][3] = {}, sn[levels][3] = {};
            for (int f = 0; f < frames; ++f) {
                Image noise(w, h, 1);
                for (float &v : noise.data) v = float(normal(rng));
                Image swt = ref::WaveletSwtAnalyze(noise, basis, levels);
                Image dwt = ref::WaveletAnalyze(noise, basis, levels);
                for (int level = 0; level < levels; ++level) {
                    int lw = LevelExtent(w, level), lh = LevelExtent(h, level);
                    int lowW = (lw + 1) / 2, lowH = (lh + 1) / 2;
                    int box[3][4] = {
                        {lowW, 0, lw, lowH}, {0, lowH, lowW, lh}, {lowW, lowH, lw, lh}};
                    for (int o = 0; o < 3; ++o) {
                        for (int y = box[o][1]; y < box[o][3]; ++y)
                            for (int x = box[o][0]; x < box[o][2]; ++x, ++dn[level][o])
                                dv[level][o] += double(dwt.At(0, y, x)) * dwt.At(0, y, x);
                        const float *p = swt.Plane(shader::SwtDetailPlane(level, o));
                        for (size_t i = 0; i < swt.PixelCount(); ++i, ++sn[level][o])
                            sv[level][o] += double(p[i]) * p[i];
                    }
                }
            }
            BandRatios r;
            for (int level = 0; level < levels; ++level)
                for (int o = 0; o < 3; ++o)
                    r[level][o] = (sv[level][o] / sn[level][o]) / (dv[level][o] / dn[level][o]);
            ratios.push_back(r);
        }
        return ratios;
    }();
    return all;
}

class BayesSwtReferenceWhiteNoise : public testing::TestWithParam<WaveletBasis> {};

TEST_P(BayesSwtReferenceWhiteNoise, BandVariancesMatchTheDwt) {
    const WaveletBasis basis = GetParam();
    SCOPED_TRACE(WaveletName(basis));
    const BandRatios &ratios =
        WhiteNoiseBandRatios()[std::find(std::begin(kBases), std::end(kBases), basis) -
                               std::begin(kBases)];
    for (int level = 0; level < kWhiteNoiseLevels; ++level)
        for (int o = 0; o < 3; ++o)
            EXPECT_NEAR(ratios[level][o], 1.0, 0.1)
                << "level " << level << " orientation " << o;
}

INSTANTIATE_TEST_SUITE_P(Cases, BayesSwtReferenceWhiteNoise, testing::ValuesIn(kBases),
                         BasisName);

// ---------------------------------------------------------------- GPU against reference

class BayesSwtKernel : public GpuTest {
  protected:
    Image Analyze(const Image &in, WaveletBasis basis, int levels, bool squared = false) {
        SwtTransform transform(Ctx(), in.width, in.height, in.channels, levels);
        vk::GpuImage image(Ctx(), in.width, in.height, in.channels, "swt.in");
        vk::GpuImage coef = transform.MakeCoefficients("swt.coef");
        image.Upload(in);
        vk::Recorder recorder(Ctx());
        transform.RecordAnalysis(recorder, basis, image, coef, squared);
        recorder.Submit();
        return coef.Download();
    }
    Image Synthesize(const Image &coefficients, WaveletBasis basis, int levels, int channels) {
        SwtTransform transform(Ctx(), coefficients.width, coefficients.height, channels,
                               levels);
        vk::GpuImage coef = transform.MakeCoefficients("swt.coef");
        vk::GpuImage out(Ctx(), coefficients.width, coefficients.height, channels, "swt.out");
        coef.Upload(coefficients);
        vk::Recorder recorder(Ctx());
        transform.RecordSynthesis(recorder, basis, coef, out);
        recorder.Submit();
        return out.Download();
    }
};

template <typename Param>
class BayesSwtKernelWithParam : public BayesSwtKernel,
                                public testing::WithParamInterface<Param> {};

// Edge sizes: 1x1 (no level), 2x3, lines, odd sizes, and sizes below the reach of the
// deeper levels (9/7 at level 2 reaches 16 samples each way).
const std::vector<std::pair<int, int>> kSizes = {{1, 1},   {2, 3},  {3, 2},  {1, 9},  {5, 4},
                                                 {17, 13}, {64, 7}, {3, 70}, {33, 33}};

// Every basis and size at the given level counts, those the size allows, each once (the
// lists name the deepest level too, which may repeat another). The kernels' suites ask for
// 1 level at least: at 0 (1x1) the transform is a copy and no kernel runs.
std::vector<SizeCase> KernelCases(std::vector<int> (*levelCounts)(int w, int h)) {
    std::vector<SizeCase> cases;
    for (WaveletBasis basis : kBases)
        for (auto [w, h] : kSizes) {
            std::vector<int> done;
            for (int levels : levelCounts(w, h)) {
                if (levels > MaxWaveletLevels(w, h) ||
                    std::find(done.begin(), done.end(), levels) != done.end())
                    continue;
                done.push_back(levels);
                cases.push_back({basis, w, h, levels});
            }
        }
    return cases;
}

// At most 3 levels, what the squared analysis and the round trip run at.
std::vector<int> UpToThreeLevels(int w, int h) {
    return {std::min(3, MaxWaveletLevels(w, h))};
}

// Error budget per pass: each output is a float dot product of at most 9 taps (the
// analysis) whose taps are themselves float products (a few u each), so its error is at
// most about (9 + 2) u times sum |tap| |x|; an input error propagates through the next
// pass scaled by at most the same |tap| sums. Composed over the 2 passes of L levels, the
// error of a coefficient is at most 11 (2 L) u times the reference's magnitude twin (|taps|
// on |x|, levels composed), plus the reference's own rounding to float (u / 2).
class WaveletSwtAnalyzeKernel : public BayesSwtKernelWithParam<SizeCase> {};

TEST_P(WaveletSwtAnalyzeKernel, MatchesReference) {
    const auto [basis, w, h, levels] = GetParam();
    SCOPED_TRACE(fmt::format("{} {}x{} levels {}", WaveletName(basis), w, h, levels));
    Image in =
        MakeInput(InputKind::Uniform, w, h, 2, SeedFromName(fmt::format("swta{}x{}", w, h)));
    Image expected = ref::WaveletSwtAnalyze(in, basis, levels);
    Image magnitude = ref::WaveletSwtAnalyzeMagnitude(in, basis, levels);
    Image got = Analyze(in, basis, levels);
    double rel = (22.0 * levels + 1) * kUnitRoundoff;
    EXPECT_TRUE(ImagesMatch(expected, got, magnitude, {rel, 1e-30, 1}));
}

// Squared taps on a non-negative variance: all terms are positive, so the value is its own
// magnitude twin. Per pass a dot product of at most 9 products of a squared tap (one more
// rounding for the square than the analysis's taps, within the "+ 2" of its budget) and a
// value: the analysis's 11 u per pass, 22 L u over L levels, plus the reference's rounding.
TEST_P(WaveletSwtAnalyzeKernel, SquaredMatchesReference) {
    const auto [basis, w, h, levels] = GetParam();
    SCOPED_TRACE(fmt::format("{} {}x{} levels {}", WaveletName(basis), w, h, levels));
    Image variance = MakeVarianceInput(InputKind::LogNormalFireflies, w, h, 2,
                                       SeedFromName(fmt::format("swtsq{}x{}", w, h)));
    Image expected = ref::WaveletSwtSqAnalyze(variance, basis, levels);
    Image got = Analyze(variance, basis, levels, true);
    double rel = (22.0 * levels + 1) * kUnitRoundoff;
    EXPECT_TRUE(ImagesMatch(expected, got, {}, {rel, 1e-30, 1}));
}

INSTANTIATE_TEST_SUITE_P(Cases, WaveletSwtAnalyzeKernel,
                         testing::ValuesIn(KernelCases([](int w, int h) {
                             return std::vector<int>{1, 3, std::max(1, MaxWaveletLevels(w, h))};
                         })),
                         SizeCaseName);

// Synthesis of the same float coefficients: each output sums at most 9 + 7 products (the
// 1/2 is exact), so (16 + 2) u per pass, composed over 2 L passes against the synthesis's
// magnitude twin.
class WaveletSwtSynthesizeKernel : public BayesSwtKernelWithParam<SizeCase> {};

TEST_P(WaveletSwtSynthesizeKernel, MatchesReference) {
    const auto [basis, w, h, levels] = GetParam();
    SCOPED_TRACE(fmt::format("{} {}x{} levels {}", WaveletName(basis), w, h, levels));
    Image coef = MakeInput(InputKind::Uniform, w, h, 2 * shader::SwtPlaneCount(levels),
                           SeedFromName(fmt::format("swts{}x{}", w, h)));
    Image expected = ref::WaveletSwtSynthesize(coef, basis, levels);
    Image magnitude = ref::WaveletSwtSynthesizeMagnitude(coef, basis, levels);
    Image got = Synthesize(coef, basis, levels, 2);
    double rel = (36.0 * levels + 1) * kUnitRoundoff;
    EXPECT_TRUE(ImagesMatch(expected, got, magnitude, {rel, 1e-30, 1}));
}

INSTANTIATE_TEST_SUITE_P(Cases, WaveletSwtSynthesizeKernel,
                         testing::ValuesIn(KernelCases([](int w, int h) {
                             return std::vector<int>{1, std::max(1, MaxWaveletLevels(w, h))};
                         })),
                         SizeCaseName);

// GPU analysis then GPU synthesis gives the input back: the analysis error carried
// through the synthesis's |taps| plus the synthesis's own, both bounded by the composed
// magnitude (synthesis magnitude of the analysis magnitude).
class BayesSwtKernelReconstruction : public BayesSwtKernelWithParam<SizeCase> {};

TEST_P(BayesSwtKernelReconstruction, IsPerfect) {
    const auto [basis, w, h, levels] = GetParam();
    SCOPED_TRACE(fmt::format("{} {}x{} levels {}", WaveletName(basis), w, h, levels));
    Image in = MakeInput(InputKind::LogNormalFireflies, w, h, 3,
                         SeedFromName(fmt::format("swtpr{}x{}", w, h)));
    Image back = Synthesize(Analyze(in, basis, levels), basis, levels, 3);
    Image magnitude = ref::WaveletSwtSynthesizeMagnitude(
        ref::WaveletSwtAnalyzeMagnitude(in, basis, levels), basis, levels);
    double rel = (58.0 * levels + 2) * kUnitRoundoff;
    EXPECT_TRUE(ImagesMatch(in, back, magnitude, {rel, 1e-30, 1e-10}));
}

INSTANTIATE_TEST_SUITE_P(Cases, BayesSwtKernelReconstruction,
                         testing::ValuesIn(KernelCases(UpToThreeLevels)), SizeCaseName);

// A constant stays a constant through the round trip, and its detail coefficients are
// round-off (float high-pass taps do not sum to exactly 0): bounded by the same per-pass
// budget against the magnitude.
class BayesSwtKernelConstant : public BayesSwtKernelWithParam<WaveletBasis> {};

TEST_P(BayesSwtKernelConstant, StaysConstant) {
    const WaveletBasis basis = GetParam();
    const int w = 29, h = 18, levels = 3;
    Image in(w, h, 1, 2.5f);
    Image coef = Analyze(in, basis, levels);
    Image magnitude = ref::WaveletSwtAnalyzeMagnitude(in, basis, levels);
    for (int level = 0; level < levels; ++level)
        for (int o = 0; o < 3; ++o) {
            int p = shader::SwtDetailPlane(level, o);
            for (size_t i = 0; i < coef.PixelCount(); ++i)
                EXPECT_LE(std::fabs(coef.Plane(p)[i]),
                          (22.0 * levels) * kUnitRoundoff * magnitude.Plane(p)[i]);
        }
    // Empirical, not derived: the worst measured is 4.8 u (CDF 9/7; Haar and 5/3 give
    // the constant back exactly). The a-priori per-pass budget composed over analysis
    // and synthesis (~5e4 u) is too loose to catch a wrong scale; 200 u still does.
    Image back = Synthesize(coef, basis, levels, 1);
    for (float v : back.data) EXPECT_NEAR(v, 2.5f, 2.5 * 200 * kUnitRoundoff);
}

INSTANTIATE_TEST_SUITE_P(Cases, BayesSwtKernelConstant, testing::ValuesIn(kBases), BasisName);

// The reference's rule for which axes a level transforms, written on its own, agrees with
// the one the kernels' host code uses (shaders/wavelet/swt.h).
TEST(BayesSwtReference, AxisRuleAgreesWithTheKernels) {
    for (int n = 1; n <= 70; ++n)
        for (int level = 0; level < 8; ++level)
            EXPECT_EQ(ref::SwtAxisTransformed(n, level), shader::SwtTransformsAxis(n, level))
                << n << " " << level;
}

TEST_F(BayesSwtKernel, RerunsAreBitIdentical) {
    Image in = MakeInput(InputKind::LogNormalFireflies, 45, 31, 3, SeedFromName("swt rerun"));
    for (WaveletBasis basis : kBases) {
        Image a = Analyze(in, basis, 3), b = Analyze(in, basis, 3);
        EXPECT_TRUE(BitIdentical(a, b));
        EXPECT_TRUE(BitIdentical(Synthesize(a, basis, 3, 3), Synthesize(b, basis, 3, 3)));
    }
}

// Coefficients above one binding are refused up front, naming the sizes: 4096 x 4096 RGB
// at 3 levels is 30 planes, 1920 MiB.
TEST_F(BayesSwtKernel, RefusesCoefficientsAboveOneBinding) {
    if (SwtChannelsPerBinding(Ctx(), 4096, 4096, 3) >= 3)
        GTEST_SKIP() << "this device binds 4096x4096x3's coefficients: nothing to refuse";
    std::string message = ErrorOf([&] { CheckSwtFits(Ctx(), 4096, 4096, 3, 3, "test"); });
    EXPECT_TRUE(Contains(message, "4096x4096x3")) << message;
    EXPECT_TRUE(Contains(message, "30 planes")) << message;
    EXPECT_TRUE(ThrowsError(ErrorKind::OutOfMemory,
                            [&] { CheckSwtFits(Ctx(), 4096, 4096, 3, 3, "test"); }));
    EXPECT_NO_THROW(CheckSwtFits(Ctx(), 64, 64, 3, 3, "test"));
}

// ---------------------------------------------------------------- method bayes over the SWT

class BayesSwtMethod : public GpuTest {};

struct SizeBasisCase {
    int w, h;
    WaveletBasis basis;
};

std::string SizeBasisName(const testing::TestParamInfo<SizeBasisCase> &info) {
    return fmt::format("{}x{}_{}", info.param.w, info.param.h, WaveletName(info.param.basis));
}

Image Log(Image image) {
    for (float &v : image.data) v = std::log(v);
    return image;
}

// Moments of full-size SWT bands, empty bands included (count 0): the sum bound of
// BayesMomentsKernel.MatchReference, (count / 256 + 12) u relative.
struct MomentCase {
    int w, h, levels;
};

// One level and the deepest, each once.
std::vector<MomentCase> MomentCases() {
    std::vector<MomentCase> cases;
    for (auto [w, h] : {std::pair{2, 3}, std::pair{1, 9}, std::pair{37, 23}, std::pair{64, 7}})
        for (int levels : {1, MaxWaveletLevels(w, h)})
            if (cases.empty() || cases.back().w != w || cases.back().h != h ||
                cases.back().levels != levels)
                cases.push_back({w, h, levels});
    return cases;
}

class BayesSwtMomentsKernel : public GpuTestWithParam<MomentCase> {};

TEST_P(BayesSwtMomentsKernel, MatchReference) {
    const auto [w, h, levels] = GetParam();
    SCOPED_TRACE(fmt::format("{}x{} levels {}", w, h, levels));
    const int channels = 2;
    Image coef = MakeInput(InputKind::Uniform, w, h, channels * shader::SwtPlaneCount(levels),
                           SeedFromName(fmt::format("swtmom{}x{}", w, h)));
    int bands = BayesBandCount(channels, levels);
    vk::GpuImage c(Ctx(), w, h, coef.channels, "coef");
    c.Upload(coef);
    vk::Buffer moments(Ctx(), bands * BAYES_MOMENT_STRIDE * sizeof(float), "moments");
    vk::Recorder recorder(Ctx());
    RecordBayesSwtMoments(Ctx(), recorder, c, channels, levels, moments);
    recorder.Submit();
    std::vector<float> got = moments.DownloadFloats(bands * BAYES_MOMENT_STRIDE);
    std::vector<ref::BayesBand> refBands = ref::BayesSwtBands(w, h, channels, levels);
    ASSERT_EQ(int(refBands.size()), bands);
    int empty = 0;
    for (int b = 0; b < bands; ++b) {
        ref::BandMoments m = ref::MeasureBand(coef, refBands[b]);
        empty += m.count == 0;
        double tol = (double(m.count) / 256 + 12) * kUnitRoundoff;
        EXPECT_NEAR(got[b * 4 + 0], m.m2, tol * m.m2) << "band " << b;
        EXPECT_NEAR(got[b * 4 + 1], m.m4, tol * m.m4) << "band " << b;
        EXPECT_EQ(got[b * 4 + 2], float(m.maxAbs)) << "band " << b;
        EXPECT_EQ(got[b * 4 + 3], float(m.count)) << "band " << b;
    }
    // 1x9 and 2x3 at their deepest level leave an axis untransformed.
    if (w <= 2 && levels > 1) {
        EXPECT_GT(empty, 0);
    }
}

INSTANTIATE_TEST_SUITE_P(Cases, BayesSwtMomentsKernel, testing::ValuesIn(MomentCases()),
                         [](const testing::TestParamInfo<MomentCase> &info) {
                             return fmt::format("{}x{}_L{}", info.param.w, info.param.h,
                                                info.param.levels);
                         });

// The whole method with --bayes-transform swt against the reference with swt, on the
// bayes edge sizes. The tolerance is BayesKernelWholeMethod.MatchesReference's (2e-3 in
// log, mean 1e-4): the per-coefficient error is the same table error plus float transform
// round-off, and the SWT synthesis averages two reconstructions, which does not enlarge it.
class BayesSwtMethodWhole : public GpuTestWithParam<SizeBasisCase> {};

TEST_P(BayesSwtMethodWhole, MatchesReference) {
    const auto [w, h, basis] = GetParam();
    SCOPED_TRACE(fmt::format("{}x{} {}", w, h, WaveletName(basis)));
    Image color = NoisyPicture(w, h, SeedFromName(fmt::format("swtwhole{}x{}", w, h)), 0.3);
    BayesParams options = PaperBayesParams();
    options.basis = basis;
    options.transform = BayesTransform::Swt;
    BayesResult gpu = BayesDenoise(Ctx(), color, options);
    BayesParams refParams = options;
    refParams.levels = gpu.levels;
    ref::BayesRefResult cpu = ref::BayesDenoise(color, refParams);
    ASSERT_EQ(gpu.fits.size(), cpu.fits.size());
    for (size_t b = 0; b < cpu.fits.size(); ++b)
        EXPECT_EQ(int(gpu.fits[b].params[4]), cpu.fits[b].fit) << "band " << b;
    EXPECT_TRUE(ImagesMatch(Log(cpu.image), Log(gpu.image), {}, {0, 2e-3, 1e-4}));
    if (gpu.levels > 0) {
        bool said = false;
        for (const std::string &line : gpu.plan) said |= Contains(line, "stationary");
        EXPECT_TRUE(said);
    }
}

std::vector<SizeBasisCase> WholeMethodCases() {
    std::vector<SizeBasisCase> cases;
    for (auto [w, h] : {std::pair{1, 1}, std::pair{2, 1}, std::pair{1, 5}, std::pair{3, 3},
                        std::pair{37, 23}, std::pair{64, 7}, std::pair{3, 70}})
        for (WaveletBasis basis : {WaveletBasis::Haar, WaveletBasis::Cdf97})
            cases.push_back({w, h, basis});
    return cases;
}

INSTANTIATE_TEST_SUITE_P(Cases, BayesSwtMethodWhole, testing::ValuesIn(WholeMethodCases()),
                         SizeBasisName);

// --noise variance through the SWT: the GPU's squared analysis and band means against the
// reference's; the same arithmetic count as BayesVarianceEstimate.MatchesReference (all
// terms positive, a few tens of u), and the band means sum w h terms in double.
class BayesSwtMethodVarianceNoise : public GpuTestWithParam<SizeBasisCase> {};

TEST_P(BayesSwtMethodVarianceNoise, MatchesReference) {
    const auto [w, h, basis] = GetParam();
    SCOPED_TRACE(fmt::format("{}x{} {}", w, h, WaveletName(basis)));
    Image color = NoisyPicture(w, h, SeedFromName(fmt::format("swtvar{}x{}", w, h)), 0.3);
    Image variance = MakeVarianceInput(InputKind::LogNormalFireflies, w, h, 3,
                                       SeedFromName(fmt::format("swtvv{}x{}", w, h)));
    int levels = std::min(3, MaxWaveletLevels(w, h));
    std::vector<float> floors = BayesFloors(color, 1e-3f);
    std::vector<double> refFloors(floors.begin(), floors.end());
    std::vector<float> gpu = BayesVarianceNoise(Ctx(), color, variance, floors, basis, levels,
                                                1.5f, false, nullptr, BayesTransform::Swt);
    std::vector<double> cpu =
        ref::BayesVarianceNoise(color, variance, refFloors, basis, levels, 1.5, false, true);
    ASSERT_EQ(gpu.size(), cpu.size());
    for (size_t b = 0; b < cpu.size(); ++b)
        EXPECT_NEAR(gpu[b], cpu[b], 1e-5 * cpu[b]) << "band " << b;
    // And the whole method with it, against the reference.
    BayesParams options = PaperBayesParams();
    options.basis = basis;
    options.transform = BayesTransform::Swt;
    options.noise = BayesNoise::Variance;
    Image got = BayesDenoise(Ctx(), color, options, {}, &variance).image;
    ref::BayesRefRun run;
    run.variance = &variance;
    Image expected = ref::BayesDenoise(color, options, run).image;
    EXPECT_TRUE(ImagesMatch(Log(expected), Log(got), {}, {0, 2e-3, 1e-4}));
}

std::vector<SizeBasisCase> VarianceNoiseCases() {
    std::vector<SizeBasisCase> cases;
    for (auto [w, h] : {std::pair{2, 3}, std::pair{1, 9}, std::pair{37, 23}})
        for (WaveletBasis basis : kBases) cases.push_back({w, h, basis});
    return cases;
}

INSTANTIATE_TEST_SUITE_P(Cases, BayesSwtMethodVarianceNoise,
                         testing::ValuesIn(VarianceNoiseCases()), SizeBasisName);

// --noise auto over the SWT: the finest HH planes hold every polyphase of the DWT's finest
// HH band, so on log-normal noise of known sigma (Haar, p = 2) it recovers s = sigma
// sqrt 2 as the DWT's estimate does (BayesProperties.NoiseAutoEstimatesTheNoise, 5%).
TEST_F(BayesSwtMethod, NoiseAutoEstimatesTheNoise) {
    const double sigma = 0.3;
    Image noise = LogNormalNoise(96, 96, SeedFromName("swt noise auto"), sigma);
    BayesParams options = PaperBayesParams();
    options.noise = BayesNoise::Mad;
    options.pn = 2;
    options.hpFactor = 1;
    options.transform = BayesTransform::Swt;
    BayesResult r = BayesDenoise(Ctx(), noise, options);
    EXPECT_NEAR(r.sn, sigma * std::sqrt(2.0), 0.05 * sigma * std::sqrt(2.0));
    // Against the reference given the GPU's estimate, on a crop (the reference integrates
    // every coefficient's posterior directly: 27 full-size bands are slow).
    Image crop(29, 19, 3);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < 19; ++y)
            for (int x = 0; x < 29; ++x) crop.At(c, y, x) = noise.At(c, y, x);
    r = BayesDenoise(Ctx(), crop, options);
    ref::BayesRefRun run;
    run.madSn = r.sn;
    Image expected = ref::BayesDenoise(crop, options, run).image;
    EXPECT_TRUE(ImagesMatch(Log(expected), Log(r.image), {}, {0, 2e-3, 1e-4}));
}

// What the SWT is for: shifting the input by one pixel shifts the output (up to the
// borders, where the mirror extension differs, and the fits, which see slightly different
// bands), while the DWT's output changes with the grid. Same noisy frame, fixed noise
// model. The 12-pixel margin is not the 3 levels' full reach (Haar 7+7, CDF 9/7 28+28), so
// border effects stay in the sum; the bound is empirical: the SWT's interior change must
// be under a quarter of the DWT's (measured: 0.11 against 7.0).
TEST_F(BayesSwtMethod, ShiftingTheInputShiftsTheOutput) {
    const int w = 64, h = 48, margin = 12;
    Image big = NoisyPicture(w + 1, h, SeedFromName("swt shift"), 0.3);
    Image a(w, h, 3), b(w, h, 3);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                a.At(c, y, x) = big.At(c, y, x), b.At(c, y, x) = big.At(c, y, x + 1);
    double change[2] = {0, 0};
    for (BayesTransform transform : {BayesTransform::Dwt, BayesTransform::Swt}) {
        BayesParams options = PaperBayesParams();
        options.transform = transform;
        Image outA = Log(BayesDenoise(Ctx(), a, options).image);
        Image outB = Log(BayesDenoise(Ctx(), b, options).image);
        double sum = 0;
        for (int c = 0; c < 3; ++c)
            for (int y = margin; y < h - margin; ++y)
                for (int x = margin; x < w - margin; ++x) {
                    double d = outA.At(c, y, x + 1) - outB.At(c, y, x);
                    sum += d * d;
                }
        change[transform == BayesTransform::Swt] = std::sqrt(sum);
    }
    std::printf("[ shift ] interior change under a 1-pixel shift: dwt %.4g, swt %.4g\n",
                change[0], change[1]);
    EXPECT_LT(change[1], 0.25 * change[0]);
}

TEST_F(BayesSwtMethod, RerunsAreBitIdentical) {
    Image color = NoisyPicture(45, 31, SeedFromName("swt method rerun"), 0.3);
    color.At(0, 3, 3) = 0;
    color.At(1, 4, 4) = std::numeric_limits<float>::quiet_NaN();
    BayesParams options = PaperBayesParams();
    options.basis = WaveletBasis::Cdf97;
    options.noise = BayesNoise::Mad;
    options.transform = BayesTransform::Swt;
    Image first = BayesDenoise(Ctx(), color, options).image;
    Image second = BayesDenoise(Ctx(), color, options).image;
    EXPECT_TRUE(BitIdentical(first, second));
    for (float v : first.data) EXPECT_TRUE(std::isfinite(v));
}

// Channel groups (what a frame above one binding runs in; BayesSwtLarge for a real one):
// bands, fits and every noise model are per channel or pool the same values, so groups of
// 1 and 2 channels must give the image and the fits bit-identical to one group.
// The noise model by number: 0 fixed, 1 mad (--noise auto), 2 variance.
const char *const kNoiseNames[] = {"fixed", "mad", "variance"};

class BayesSwtMethodChannelGroups : public GpuTestWithParam<int> {};

TEST_P(BayesSwtMethodChannelGroups, ChangeNothing) {
    const int noise = GetParam();
    const int w = 37, h = 23;
    Image color = NoisyPicture(w, h, SeedFromName("swt groups"), 0.3);
    Image variance(w, h, 3);
    for (size_t i = 0; i < color.Size(); ++i)
        variance.data[i] = 0.05f * color.data[i] * color.data[i];
    SCOPED_TRACE(noise == 0 ? "fixed" : (noise == 1 ? "mad" : "variance"));
    BayesParams options = PaperBayesParams();
    options.transform = BayesTransform::Swt;
    options.basis = WaveletBasis::Cdf97;
    const BayesNoise noises[] = {BayesNoise::Fixed, BayesNoise::Mad, BayesNoise::Variance};
    options.noise = noises[noise];
    BayesResult all = BayesDenoise(Ctx(), color, options, {}, &variance);
    for (int group : {1, 2}) {
        RunSetup setup;
        setup.swtGroupChannels = group;
        BayesResult grouped = BayesDenoise(Ctx(), color, options, setup, &variance);
        EXPECT_TRUE(BitIdentical(all.image, grouped.image)) << group;
        ASSERT_EQ(all.fits.size(), grouped.fits.size());
        for (size_t b = 0; b < all.fits.size(); ++b)
            EXPECT_EQ(all.fits[b].params, grouped.fits[b].params) << group << " " << b;
        EXPECT_EQ(all.sn, grouped.sn);
    }
}

INSTANTIATE_TEST_SUITE_P(Cases, BayesSwtMethodChannelGroups, testing::Values(0, 1, 2),
                         [](const testing::TestParamInfo<int> &info) {
                             return std::string(kNoiseNames[info.param]);
                         });

// An image whose SWT exceeds one binding even for one channel is refused before any GPU
// work, naming the sizes: 4096 x 4096 x 1 at 3 levels is 10 planes, 640 MiB.
TEST_F(BayesSwtMethod, RefusesAboveOneBinding) {
    if (SwtChannelsPerBinding(Ctx(), 4096, 4096, 3) >= 1)
        GTEST_SKIP() << "this device binds one 4096x4096 channel's coefficients: nothing to "
                        "refuse";
    BayesParams options = PaperBayesParams();
    options.transform = BayesTransform::Swt;
    EXPECT_TRUE(ThrowsError(
        ErrorKind::OutOfMemory,
        [&] { BayesDenoise(Ctx(), Image(4096, 4096, 1, 0.5f), options); }, "4096x4096x1"));
}

}  // namespace
}  // namespace mcd::test
