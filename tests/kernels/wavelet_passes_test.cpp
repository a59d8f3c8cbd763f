// One level of the line wavelet kernels called directly, against the reference:
// RecordWaveletSynthesizePass's columns and rows passes (through RecordWaveletLinePass:
// vec4 and scalar rows, interior and edge segments of long axes) against one level of
// ref::WaveletSynthesize, RecordWaveletSqAnalyze against ref::WaveletSqAnalyze, and kernel
// wavelet/synthesize_shrink (RecordWaveletSynthesizeShrink: its fused columns pass, then
// the plain rows pass) against ref::AwrShrink then one level of ref::WaveletSynthesize.
// Each runs on a region at the top left of a larger buffer, which must stay as it was
// outside the region.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "cpu_reference/awr_reconstruct.h"
#include "cpu_reference/wavelet_sqanalyze.h"
#include "cpu_reference/wavelet_synthesize.h"
#include "harness/compare.h"
#include "harness/gpu_fixture.h"
#include "harness/inputs.h"
#include "host/kernels/wavelet_sqanalyze.h"
#include "host/kernels/wavelet_synthesize.h"
#include "host/kernels/wavelet_synthesize_shrink.h"
#include "host/vk/buffer.h"
#include "host/vk/gpu_image.h"
#include "host/vk/recorder.h"
#include "wavelet/tile.h"

namespace mcd::test {
namespace {

constexpr double kUnitRoundoff = 0x1p-24;
constexpr float kUntouched = 7.25f;

const WaveletBasis kBases[] = {WaveletBasis::Haar, WaveletBasis::LeGall53, WaveletBasis::Cdf97};

struct PassCase {
    WaveletBasis basis;
    int w, h;        // the region
    int padX, padY;  // the buffer's extra columns and rows around it
    InputKind kind;

    std::string Name() const {
        return fmt::format("{}_{}x{}_pad{}x{}_{}", WaveletName(basis), w, h, padX, padY,
                           InputKindName(kind));
    }
};

// The region's w x h x 3 values inside a buffer image of (w + padX) x (h + padY) filled with
// kUntouched elsewhere.
Image Embed(const Image &region, int padX, int padY) {
    Image buffer(region.width + padX, region.height + padY, region.channels, kUntouched);
    for (int c = 0; c < region.channels; ++c)
        for (int y = 0; y < region.height; ++y)
            for (int x = 0; x < region.width; ++x) buffer.At(c, y, x) = region.At(c, y, x);
    return buffer;
}

// The buffer outside the region is as it was.
void ExpectOutsideUntouched(const Image &got, const PassCase &c) {
    for (int ch = 0; ch < got.channels; ++ch)
        for (int y = 0; y < got.height; ++y)
            for (int x = 0; x < got.width; ++x)
                if (x >= c.w || y >= c.h) {
                    ASSERT_EQ(got.At(ch, y, x), kUntouched) << "outside at " << x << ", " << y;
                }
}

class WaveletOneLevel : public GpuTestWithParam<PassCase> {};

// The columns pass then the rows pass (each RecordWaveletSynthesizePass: the temporary
// between them holds the kernel's own interleaved, rescaled layout, which has no reference
// of its own) make one level: the synthesis's budget of wavelet_gpu_test.cpp, 96 u per
// level of the magnitude twin.
TEST_P(WaveletOneLevel, SynthesizePassesMatchReference) {
    const PassCase &c = GetParam();
    Image in = MakeInput(c.kind, c.w, c.h, 3, SeedFromName(c.Name()));
    Image expected = ref::WaveletSynthesize(in, c.basis, 1);
    Image magnitude = ref::WaveletSynthesizeMagnitude(in, c.basis, 1);
    Image src = Embed(in, c.padX, c.padY);
    vk::GpuImage srcGpu(Ctx(), src.width, src.height, 3, "src"),
        dstGpu(Ctx(), src.width, src.height, 3, "dst");
    srcGpu.Upload(src);
    const int tmpStride = (c.w + 3) / 4 * 4;
    vk::Buffer tmp(Ctx(), size_t(tmpStride) * c.h * 3 * sizeof(float), "tmp");
    vk::MutableImageView tmpView{&tmp, tmpStride, tmpStride * c.h};
    auto run = [&] {
        dstGpu.Upload(Image(src.width, src.height, 3, kUntouched));
        vk::Recorder recorder(Ctx());
        RecordWaveletSynthesizePass(Ctx(), recorder, c.basis, WAVELET_AXIS_COLUMNS, c.w, c.h, 3,
                                    srcGpu.View(), tmpView, "columns");
        RecordWaveletSynthesizePass(Ctx(), recorder, c.basis, WAVELET_AXIS_ROWS, c.w, c.h, 3,
                                    tmpView, dstGpu.MutableView(), "rows");
        recorder.Submit();
        return dstGpu.Download();
    };
    Image got = run();
    EXPECT_TRUE(ImagesMatch(expected, got.Crop(0, 0, c.w, c.h), magnitude,
                            {96 * kUnitRoundoff, 0, 1e-9}));
    ExpectOutsideUntouched(got, c);
    EXPECT_TRUE(BitIdentical(got, run()));
}

// RecordWaveletSqAnalyze's one level (its rows then columns pass) on the region of a
// padded buffer against ref::WaveletSqAnalyze: squared taps on non-negative values, so
// |expected| is the round-off scale; wavelet_gpu_test.cpp's 24 u per level (9 taps and a
// renormalisation per axis), at the natural sums and at AWR's renormalised ones.
TEST_P(WaveletOneLevel, SqAnalyzeMatchesReference) {
    const PassCase &c = GetParam();
    Image in = MakeVarianceInput(c.kind, c.w, c.h, 3, SeedFromName("sq" + c.Name()));
    Image src = Embed(in, c.padX, c.padY);
    vk::GpuImage srcGpu(Ctx(), src.width, src.height, 3, "variance"),
        dstGpu(Ctx(), src.width, src.height, 3, "coefvar");
    srcGpu.Upload(src);
    const int tmpStride = (c.w + 3) / 4 * 4;
    vk::Buffer tmp(Ctx(), size_t(tmpStride) * c.h * 3 * sizeof(float), "tmp");
    vk::MutableImageView tmpView{&tmp, tmpStride, tmpStride * c.h};
    for (auto [lowSum, highSum] : {std::pair{0.f, 0.f}, std::pair{1.05f, 0.70710678f}}) {
        SCOPED_TRACE(fmt::format("sums {} {}", lowSum, highSum));
        Image expected = ref::WaveletSqAnalyze(in, c.basis, 1, lowSum, highSum);
        auto run = [&] {
            dstGpu.Upload(Image(src.width, src.height, 3, kUntouched));
            vk::Recorder recorder(Ctx());
            RecordWaveletSqAnalyze(Ctx(), recorder, c.basis, c.w, c.h, 3, srcGpu.View(),
                                   tmpView, dstGpu.MutableView(), lowSum, highSum);
            recorder.Submit();
            return dstGpu.Download();
        };
        Image got = run();
        EXPECT_TRUE(
            ImagesMatch(expected, got.Crop(0, 0, c.w, c.h), {}, {24 * kUnitRoundoff, 0, 1e-9}));
        ExpectOutsideUntouched(got, c);
        EXPECT_TRUE(BitIdentical(got, run()));
    }
}

// Buffers whose rows are whole vec4s (the rows pass moves vec4s) and others; axes of 256 and
// more run their interior segments apart from the edges.
std::vector<PassCase> PassCases() {
    std::vector<PassCase> cases;
    for (WaveletBasis basis : kBases) {
        cases.push_back({basis, 2, 2, 0, 0, InputKind::Uniform});
        cases.push_back({basis, 1, 7, 3, 0, InputKind::LogNormalFireflies});
        cases.push_back({basis, 9, 1, 0, 2, InputKind::Uniform});
        cases.push_back({basis, 17, 13, 3, 1, InputKind::Uniform});
        cases.push_back({basis, 17, 13, 3, 1, InputKind::NonFinite});
        cases.push_back({basis, 24, 10, 4, 0, InputKind::Constant});
        cases.push_back({basis, 300, 5, 4, 0, InputKind::Uniform});
        cases.push_back({basis, 5, 261, 0, 3, InputKind::Impulse});
    }
    return cases;
}

INSTANTIATE_TEST_SUITE_P(Cases, WaveletOneLevel, testing::ValuesIn(PassCases()),
                         [](const testing::TestParamInfo<PassCase> &info) {
                             return info.param.Name();
                         });

// ---------------------------------------------------------------- wavelet/synthesize_shrink

class WaveletSynthesizeShrinkKernel : public GpuTestWithParam<PassCase> {};

// The synthesis's 96 u per level of the magnitude twin, taken over the shrinkage's
// magnitude |w| + cs sqrt(var) of every detail coefficient (|w| - cs sqrt(var) cancels:
// sqrt, product and difference err by 4 u of that), and 8 u more for that rounding carried
// through the synthesis.
TEST_P(WaveletSynthesizeShrinkKernel, MatchesReference) {
    const PassCase &c = GetParam();
    const uint64_t seed = SeedFromName(c.Name());
    const float cs = 1.f;
    Image coef = MakeInput(c.kind, c.w, c.h, 3, seed);
    Image variance = MakeVarianceInput(InputKind::Uniform, c.w, c.h, 3, seed + 1);
    for (float &v : variance.data) v *= 0.25f;
    const int lowW = LevelExtent(c.w, 1), lowH = LevelExtent(c.h, 1);
    Image expected =
        ref::WaveletSynthesize(ref::AwrShrink(coef, variance, lowW, lowH, cs), c.basis, 1);
    Image shrinkScale = coef;
    for (int ch = 0; ch < 3; ++ch)
        for (int y = 0; y < c.h; ++y)
            for (int x = 0; x < c.w; ++x) {
                bool low = x < lowW && y < lowH;
                shrinkScale.At(ch, y, x) = std::fabs(coef.At(ch, y, x)) +
                                           (low ? 0.f : cs * std::sqrt(variance.At(ch, y, x)));
            }
    Image magnitude = ref::WaveletSynthesizeMagnitude(shrinkScale, c.basis, 1);
    Image src = Embed(coef, c.padX, c.padY), var = Embed(variance, c.padX, c.padY);
    vk::GpuImage srcGpu(Ctx(), src.width, src.height, 3, "coef"),
        varGpu(Ctx(), src.width, src.height, 3, "variance"),
        dstGpu(Ctx(), src.width, src.height, 3, "dst");
    srcGpu.Upload(src);
    varGpu.Upload(var);
    const int tmpStride = (c.w + 3) / 4 * 4;
    vk::Buffer tmp(Ctx(), size_t(tmpStride) * c.h * 3 * sizeof(float), "tmp");
    vk::MutableImageView tmpView{&tmp, tmpStride, tmpStride * c.h};
    auto run = [&] {
        dstGpu.Upload(Image(src.width, src.height, 3, kUntouched));
        vk::Recorder recorder(Ctx());
        RecordWaveletSynthesizeShrink(Ctx(), recorder, c.basis, c.w, c.h, 3, srcGpu.View(),
                                      varGpu.View(), cs, tmpView, dstGpu.MutableView());
        recorder.Submit();
        return dstGpu.Download();
    };
    Image got = run();
    EXPECT_TRUE(ImagesMatch(expected, got.Crop(0, 0, c.w, c.h), magnitude,
                            {104 * kUnitRoundoff, 0, 1e-9}));
    ExpectOutsideUntouched(got, c);
    EXPECT_TRUE(BitIdentical(got, run()));
    // The coefficients are read, not shrunk in place.
    EXPECT_TRUE(BitIdentical(srcGpu.Download(), src));
}

// GLSL's max of 0 and NaN is undefined, so NaN coefficients are outside the shrinkage's
// contract: the inputs are finite.
std::vector<PassCase> ShrinkCases() {
    std::vector<PassCase> cases;
    for (WaveletBasis basis : kBases) {
        cases.push_back({basis, 2, 2, 0, 0, InputKind::Uniform});
        cases.push_back({basis, 1, 7, 3, 0, InputKind::Uniform});
        cases.push_back({basis, 9, 1, 0, 2, InputKind::LogNormalFireflies});
        cases.push_back({basis, 17, 13, 3, 1, InputKind::Uniform});
        cases.push_back({basis, 24, 10, 4, 0, InputKind::Constant});
        cases.push_back({basis, 33, 260, 0, 2, InputKind::Uniform});
    }
    return cases;
}

INSTANTIATE_TEST_SUITE_P(Cases, WaveletSynthesizeShrinkKernel, testing::ValuesIn(ShrinkCases()),
                         [](const testing::TestParamInfo<PassCase> &info) {
                             return info.param.Name();
                         });

}  // namespace
}  // namespace mcd::test
