// GPU wavelet kernels against the CPU reference (cpu_reference/wavelet_*.cpp), in the
// style of ggml's test-backend-ops: every case is named by its parameters and seeded by a
// hash of that name, so a failure replays.
//
// Tolerances: the GPU lifts in float32. Each level applies at most 2 axes x 4 lifting
// steps (CDF 9/7) plus a scaling; each step rounds once or twice, on intermediates at most
// ~4x the output's sum |h| |x| (the first 9/7 predict step has gain 1 + 2|alpha| = 4.2).
// So per level the error is within about 2 x 9 x 4 = 72 units of round-off of the
// magnitude twin (sum |h| |x| composed over levels, from the reference); we allow
// kUlpsPerLevel of them per level. The measured worst ratio is printed by
// WaveletTolerance.Headroom so the bound can be seen to be neither loose nor tight.
#include <gtest/gtest.h>

#include <fmt/format.h>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "cpu_reference/wavelet_analyze.h"
#include "cpu_reference/wavelet_sqanalyze.h"
#include "cpu_reference/wavelet_synthesize.h"
#include "harness/compare.h"
#include "harness/errors.h"
#include "harness/gpu_fixture.h"
#include "harness/gpu_wavelet.h"
#include "harness/inputs.h"
#include "host/error.h"
#include "host/kernels/wavelet_analyze.h"
#include "host/vk/context.h"
#include "host/wavelet/transform.h"

namespace mcd::test {
namespace {

constexpr double kUnitRoundoff = 0x1p-24;
constexpr double kUlpsPerLevel = 96;

// Worst error as a fraction of the allowed bound, per check, printed after the run.
struct Headroom : ::testing::Environment {
    std::map<std::string, double> worst;
    void Note(const std::string &check, const CompareStats &stats) {
        worst[check] = std::max(worst[check], stats.maxErrorRatio);
    }
    void TearDown() override {
        for (auto &[check, ratio] : worst)
            std::fprintf(stderr, "[mcd] %s: worst error %.3f of the tolerance\n", check.c_str(),
                         ratio);
    }
};
Headroom *const headroom =
    static_cast<Headroom *>(::testing::AddGlobalTestEnvironment(new Headroom));

struct WaveletCase {
    int width, height, channels;
    WaveletBasis basis;
    int levels;
    InputKind kind;

    std::string Name() const {
        return fmt::format("{}x{}x{}_{}_L{}_{}", width, height, channels, WaveletName(basis),
                           levels, InputKindName(kind));
    }
    uint64_t Seed() const { return SeedFromName(Name()); }
    Tolerance Tol() const {
        return {kUlpsPerLevel * kUnitRoundoff * std::max(levels, 1), 0, 1e-9};
    }
};

std::vector<WaveletCase> AllCases() {
    const int sizes[][2] = {{1, 1},     {1, 7},    {7, 1},     {2, 2},    {3, 3},  {5, 9},
                            {17, 13},   {31, 33},  {64, 64},   {67, 41},  {97, 3}, {33, 70},
                            {128, 124}, {132, 67}, {256, 256}, {258, 257}};
    std::vector<WaveletCase> cases;
    for (auto [w, h] : sizes)
        for (WaveletBasis basis :
             {WaveletBasis::Haar, WaveletBasis::LeGall53, WaveletBasis::Cdf97}) {
            int maxLevels = MaxWaveletLevels(w, h);
            std::vector<int> levelList;
            for (int l : {1, 2, maxLevels})
                if (l <= maxLevels && (levelList.empty() || levelList.back() != l))
                    levelList.push_back(l);
            if (maxLevels == 0) levelList = {0};
            for (int levels : levelList)
                for (InputKind kind :
                     {InputKind::Uniform, InputKind::LogNormalFireflies, InputKind::Constant,
                      InputKind::Impulse, InputKind::NonFinite})
                    cases.push_back({w, h, 3, basis, levels, kind});
        }
    return cases;
}

// The cases that run a kernel: 1x1 takes no level, its transforms are copies.
std::vector<WaveletCase> KernelCases() {
    std::vector<WaveletCase> cases;
    for (const WaveletCase &c : AllCases())
        if (c.levels > 0) cases.push_back(c);
    return cases;
}

std::string CaseName(const ::testing::TestParamInfo<WaveletCase> &info) {
    return info.param.Name();
}

class WaveletAnalyzeKernel : public GpuTestWithParam<WaveletCase> {};
class WaveletSynthesizeKernel : public GpuTestWithParam<WaveletCase> {};
class WaveletSqanalyzeKernel : public GpuTestWithParam<WaveletCase> {};
class WaveletRoundTrip : public GpuTestWithParam<WaveletCase> {};

TEST_P(WaveletAnalyzeKernel, MatchesReference) {
    const WaveletCase &p = GetParam();
    Image in = MakeInput(p.kind, p.width, p.height, p.channels, p.Seed());
    Image expected = ref::WaveletAnalyze(in, p.basis, p.levels);
    Image magnitude = ref::WaveletAnalyzeMagnitude(in, p.basis, p.levels);
    Image actual = GpuAnalyze(Ctx(), in, p.basis, p.levels);
    CompareStats stats;
    EXPECT_TRUE(ImagesMatch(expected, actual, magnitude, p.Tol(), &stats)) << p.Name();
    headroom->Note("analyze", stats);
}

TEST_P(WaveletSynthesizeKernel, MatchesReference) {
    const WaveletCase &p = GetParam();
    Image in = MakeInput(p.kind, p.width, p.height, p.channels, p.Seed());
    Image coefficients = ref::WaveletAnalyze(in, p.basis, p.levels);
    Image expected = ref::WaveletSynthesize(coefficients, p.basis, p.levels);
    Image magnitude = ref::WaveletSynthesizeMagnitude(coefficients, p.basis, p.levels);
    Image actual = GpuSynthesize(Ctx(), coefficients, p.basis, p.levels);
    CompareStats stats;
    EXPECT_TRUE(ImagesMatch(expected, actual, magnitude, p.Tol(), &stats)) << p.Name();
    headroom->Note("synthesize", stats);
}

TEST_P(WaveletSqanalyzeKernel, MatchesReference) {
    const WaveletCase &p = GetParam();
    Image variance = MakeVarianceInput(p.kind, p.width, p.height, p.channels, p.Seed());
    for (auto [lowSum, highSum] : {std::pair{0.f, 0.f}, std::pair{1.05f, 0.70710678f}}) {
        Image expected = ref::WaveletSqAnalyze(variance, p.basis, p.levels, lowSum, highSum);
        Image actual = GpuSqAnalyze(Ctx(), variance, p.basis, p.levels, lowSum, highSum);
        // All squared taps are positive: |expected| is the round-off scale; 9 taps and a
        // renormalisation per axis and level.
        Tolerance tol{24 * kUnitRoundoff * std::max(p.levels, 1), 0, 1e-9};
        CompareStats stats;
        EXPECT_TRUE(ImagesMatch(expected, actual, Image(), tol, &stats))
            << p.Name() << " lowSum " << lowSum << " highSum " << highSum;
        headroom->Note("sqanalyze", stats);
    }
}

TEST_P(WaveletRoundTrip, ReturnsInput) {
    const WaveletCase &p = GetParam();
    Image in = MakeInput(p.kind, p.width, p.height, p.channels, p.Seed());
    Image coefficients = GpuAnalyze(Ctx(), in, p.basis, p.levels);
    Image back = GpuSynthesize(Ctx(), coefficients, p.basis, p.levels);
    // Non-finite pixels spread over their filters' support on the way: a non-finite input
    // must stay non-finite, and where the output is finite it must be the input.
    for (size_t i = 0; i < in.Size(); ++i) {
        if (!std::isfinite(in.data[i])) {
            ASSERT_FALSE(std::isfinite(back.data[i])) << p.Name() << " element " << i;
            in.data[i] = back.data[i] = 0.f;
        } else if (!std::isfinite(back.data[i])) {
            ASSERT_EQ(p.kind, InputKind::NonFinite) << p.Name() << " element " << i;
            in.data[i] = back.data[i] = 0.f;
        }
    }
    // Round-off of both directions, on the scale of synthesis(|analysis|(|x|)).
    Image magnitude = ref::WaveletSynthesizeMagnitude(
        ref::WaveletAnalyzeMagnitude(in, p.basis, p.levels), p.basis, p.levels);
    Tolerance tol{2 * kUlpsPerLevel * kUnitRoundoff * std::max(p.levels, 1), 0, 1e-9};
    CompareStats stats;
    EXPECT_TRUE(ImagesMatch(in, back, magnitude, tol, &stats)) << p.Name();
    headroom->Note("round trip", stats);
}

TEST_P(WaveletAnalyzeKernel, RerunIsBitIdentical) {
    const WaveletCase &p = GetParam();
    Image in = MakeInput(p.kind, p.width, p.height, p.channels, p.Seed());
    Image a = GpuAnalyze(Ctx(), in, p.basis, p.levels);
    Image b = GpuAnalyze(Ctx(), in, p.basis, p.levels);
    EXPECT_TRUE(BitIdentical(a, b)) << p.Name();
}

TEST_P(WaveletSynthesizeKernel, RerunIsBitIdentical) {
    const WaveletCase &p = GetParam();
    Image coefficients = MakeInput(p.kind, p.width, p.height, p.channels, p.Seed());
    Image sa = GpuSynthesize(Ctx(), coefficients, p.basis, p.levels);
    Image sb = GpuSynthesize(Ctx(), coefficients, p.basis, p.levels);
    EXPECT_TRUE(BitIdentical(sa, sb)) << p.Name();
}

INSTANTIATE_TEST_SUITE_P(Cases, WaveletAnalyzeKernel, ::testing::ValuesIn(KernelCases()),
                         CaseName);
INSTANTIATE_TEST_SUITE_P(Cases, WaveletSynthesizeKernel, ::testing::ValuesIn(KernelCases()),
                         CaseName);
INSTANTIATE_TEST_SUITE_P(Cases, WaveletSqanalyzeKernel, ::testing::ValuesIn(KernelCases()),
                         CaseName);
INSTANTIATE_TEST_SUITE_P(Cases, WaveletRoundTrip, ::testing::ValuesIn(AllCases()), CaseName);

class WaveletProperties : public GpuTest {};

// A constant image has no detail: every detail coefficient is zero up to round-off.
TEST_F(WaveletProperties, ConstantHasZeroDetail) {
    for (WaveletBasis basis : {WaveletBasis::Haar, WaveletBasis::LeGall53, WaveletBasis::Cdf97})
        for (auto [w, h] : {std::pair{37, 23}, std::pair{64, 64}, std::pair{5, 1}}) {
            int levels = MaxWaveletLevels(w, h);
            Image in(w, h, 2, 0.75f);
            Image coef = GpuAnalyze(Ctx(), in, basis, levels);
            double maxDetail = 0;
            for (int c = 0; c < 2; ++c)
                for (int y = 0; y < h; ++y)
                    for (int x = 0; x < w; ++x)
                        if (x > 0 || y > 0)
                            maxDetail =
                                std::max(maxDetail, double(std::fabs(coef.At(c, y, x))));
            // LL = 0.75 * sqrt2^(axes transformed); details are round-off of that.
            double ll = coef.At(0, 0, 0);
            EXPECT_LT(maxDetail, 64 * kUnitRoundoff * levels * ll)
                << WaveletName(basis) << " " << w << "x" << h;
        }
}

// Squared-filter analysis of a constant variance v: every coefficient is v times a product
// of per-axis sums (the squared taps sum to lowSum or highSum), at the borders too.
TEST_F(WaveletProperties, SqAnalyzeConstantMatchesClosedForm) {
    const float v = 0.37f, lowSum = 1.05f, highSum = 0.70710678f;
    for (WaveletBasis basis : {WaveletBasis::Haar, WaveletBasis::LeGall53, WaveletBasis::Cdf97})
        for (auto [w, h] : {std::pair{45, 29}, std::pair{16, 16}}) {
            int levels = 3;
            Image var(w, h, 1, v);
            Image coef = GpuSqAnalyze(Ctx(), var, basis, levels, lowSum, highSum);
            // Expected value per position: walk the levels like the layout does.
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) {
                    double expected = v;
                    int px = x, py = y;
                    for (int level = 0; level < levels; ++level) {
                        int lw = LevelExtent(w, level), lh = LevelExtent(h, level);
                        if (px >= lw || py >= lh) break;
                        int hw = (lw + 1) / 2, hh = (lh + 1) / 2;
                        bool highX = lw > 1 && px >= hw, highY = lh > 1 && py >= hh;
                        if (lw > 1) expected *= highX ? highSum : lowSum;
                        if (lh > 1) expected *= highY ? highSum : lowSum;
                        if (highX || highY) break;
                    }
                    EXPECT_NEAR(coef.At(0, y, x), expected, 1e-5 * expected)
                        << WaveletName(basis) << " " << w << "x" << h << " at " << x << ","
                        << y;
                }
        }
}

// Write-only guard bands: padded strides and planes around every view must come back
// untouched, and NaN in the source's padding must never be read.
TEST_F(WaveletProperties, GuardBandsUntouched) {
    vk::Context &ctx = Ctx();
    const int w = 45, h = 19, channels = 2, pad = 3;
    const int stride = w + pad, plane = stride * (h + pad);
    const float sentinel = 12345.f;
    Image in = MakeInput(InputKind::Uniform, w, h, channels, SeedFromName("guard"));
    std::vector<float> src(size_t(plane) * channels + pad,
                           std::numeric_limits<float>::quiet_NaN());
    for (int c = 0; c < channels; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                src[size_t(c) * plane + y * stride + x] = in.At(c, y, x);
    for (WaveletBasis basis :
         {WaveletBasis::Haar, WaveletBasis::LeGall53, WaveletBasis::Cdf97}) {
        vk::Buffer srcBuffer(ctx, src.size() * 4, "src"),
            coefBuffer(ctx, src.size() * 4, "coef");
        srcBuffer.UploadFloats(src);
        std::vector<float> fill(src.size(), sentinel);
        coefBuffer.UploadFloats(fill);
        vk::Buffer tmpBuffer(ctx, src.size() * 4, "tmp");
        tmpBuffer.UploadFloats(fill);
        vk::Recorder recorder(ctx);
        // Single level straight into the padded coefficient view, through a padded temporary.
        vk::ImageView srcView{&srcBuffer, stride, plane};
        vk::MutableImageView coefView{&coefBuffer, stride, plane},
            tmpView{&tmpBuffer, stride, plane};
        RecordWaveletAnalyze(ctx, recorder, basis, w, h, channels, srcView, tmpView, coefView);
        recorder.Submit();
        std::vector<float> out = coefBuffer.DownloadFloats(src.size());
        std::vector<float> tmpOut = tmpBuffer.DownloadFloats(src.size());
        Image expected = ref::WaveletAnalyze(in, basis, 1);
        Image magnitude = ref::WaveletAnalyzeMagnitude(in, basis, 1);
        Image actual(w, h, channels);
        for (size_t i = 0; i < out.size(); ++i) {
            size_t c = i / plane, r = i % plane;
            int y = int(r / stride), x = int(r % stride);
            bool inside = c < size_t(channels) && y < h && x < w;
            if (inside) {
                actual.At(int(c), y, x) = out[i];
            } else {
                ASSERT_EQ(out[i], sentinel) << WaveletName(basis) << ": guard written at " << i;
                ASSERT_EQ(tmpOut[i], sentinel) << WaveletName(basis) << ": tmp guard at " << i;
            }
        }
        EXPECT_TRUE(
            ImagesMatch(expected, actual, magnitude, {kUlpsPerLevel * kUnitRoundoff, 0, 1e-9}))
            << WaveletName(basis);
    }
}

// In place (input and output the same image) gives what out of place gives, also with 0
// levels, where the transform is a copy (and a copy onto itself would be invalid Vulkan).
TEST_F(WaveletProperties, InPlaceMatchesOutOfPlace) {
    vk::Context &ctx = Ctx();
    Image in = MakeInput(InputKind::Uniform, 45, 29, 2, SeedFromName("inplace"));
    for (int levels : {0, 3}) {
        Image expected = GpuAnalyze(ctx, in, WaveletBasis::Cdf97, levels);
        vk::GpuImage image(ctx, 45, 29, 2, "image");
        image.Upload(in);
        WaveletTransform transform(ctx, 45, 29, 2);
        vk::Recorder recorder(ctx);
        transform.RecordAnalysis(recorder, WaveletBasis::Cdf97, levels, image, image);
        recorder.Submit();
        EXPECT_TRUE(BitIdentical(expected, image.Download())) << levels << " levels";
        transform.RecordSynthesis(recorder, WaveletBasis::Cdf97, levels, image, image);
        recorder.Submit();
        EXPECT_TRUE(BitIdentical(GpuSynthesize(ctx, expected, WaveletBasis::Cdf97, levels),
                                 image.Download()))
            << levels << " levels";
    }
}

// Out-of-range levels and mismatched images are refused with a clear message.
TEST_F(WaveletProperties, BadArgumentsThrow) {
    vk::Context &ctx = Ctx();
    vk::GpuImage a(ctx, 8, 8, 1, "a"), b(ctx, 8, 8, 1, "b"), c(ctx, 4, 8, 1, "c");
    WaveletTransform transform(ctx, 8, 8, 1);
    vk::Recorder recorder(ctx);
    EXPECT_TRUE(ThrowsError(
        ErrorKind::InvalidArgument,
        [&] { transform.RecordAnalysis(recorder, WaveletBasis::Cdf97, 4, a, b); },
        "allows 0..3"));
    EXPECT_TRUE(ThrowsError(ErrorKind::Internal, [&] {
        transform.RecordAnalysis(recorder, WaveletBasis::Cdf97, 1, a, c);
    }));
}

}  // namespace
}  // namespace mcd::test
