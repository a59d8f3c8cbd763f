// GPU wavelet transform (mcd::WaveletTransform) against the CPU reference on frame-sized
// images: 1920x1080 RGB CDF 9/7 at 5 levels and at the maximum level count, and an odd
// 2049x1031 single-channel LeGall 5/3 (lines longer than 2048, many workgroup segments,
// odd extents at every level), plus a 4K RGB frame whose buffers come close to lavapipe's
// storage-buffer range. Label `slow`: not run in CI.
//
// Tolerances as in tests/wavelet/wavelet_gpu_test.cpp: kUlpsPerLevel units of float32
// round-off per level times the reference's magnitude twin (sum |h| |x| composed over the
// levels); round trips twice that on synthesis(|analysis|(|x|)). The worst error is
// printed as a fraction of the bound.
#include <gtest/gtest.h>

#include <fmt/format.h>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "cpu_reference/wavelet_analyze.h"
#include "cpu_reference/wavelet_synthesize.h"
#include "harness/compare.h"
#include "harness/gpu_fixture.h"
#include "harness/gpu_wavelet.h"
#include "harness/inputs.h"
#include "host/vk/gpu_image.h"
#include "host/wavelet.h"
#include "host/wavelet/transform.h"

namespace mcd::test {
namespace {

constexpr double kUnitRoundoff = 0x1p-24;
constexpr double kUlpsPerLevel = 96;

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point since) {
    return std::chrono::duration<double>(Clock::now() - since).count();
}

struct LargeCase {
    int width, height, channels;
    WaveletBasis basis;
    int levels;  // -1: MaxWaveletLevels
    InputKind kind;

    int Levels() const { return levels < 0 ? MaxWaveletLevels(width, height) : levels; }
    std::string Name() const {
        return fmt::format("{}x{}x{}_{}_L{}_{}", width, height, channels, WaveletName(basis),
                           Levels(), InputKindName(kind));
    }
    Image Input() const {
        return MakeInput(kind, width, height, channels, SeedFromName(Name()));
    }
    Tolerance Tol() const {
        return {kUlpsPerLevel * kUnitRoundoff * std::max(Levels(), 1), 0, 1e-9};
    }
};

class WaveletLarge : public GpuTestWithParam<LargeCase> {};

TEST_P(WaveletLarge, AnalyzeMatchesReference) {
    const LargeCase &p = GetParam();
    Image in = p.Input();
    Clock::time_point t0 = Clock::now();
    Image expected = ref::WaveletAnalyze(in, p.basis, p.Levels());
    Image magnitude = ref::WaveletAnalyzeMagnitude(in, p.basis, p.Levels());
    double refSeconds = Seconds(t0);
    t0 = Clock::now();
    Image actual = GpuAnalyze(Ctx(), in, p.basis, p.Levels());
    double gpuSeconds = Seconds(t0);
    CompareStats stats;
    EXPECT_TRUE(ImagesMatch(expected, actual, magnitude, p.Tol(), &stats)) << p.Name();
    std::fprintf(stderr,
                 "[mcd] %s analyze: worst error %.3f of the tolerance, nmse %.3g (reference "
                 "%.2f s, GPU %.2f s)\n",
                 p.Name().c_str(), stats.maxErrorRatio, stats.nmse, refSeconds, gpuSeconds);
}

TEST_P(WaveletLarge, SynthesizeMatchesReference) {
    const LargeCase &p = GetParam();
    Image coefficients = ref::WaveletAnalyze(p.Input(), p.basis, p.Levels());
    Image expected = ref::WaveletSynthesize(coefficients, p.basis, p.Levels());
    Image magnitude = ref::WaveletSynthesizeMagnitude(coefficients, p.basis, p.Levels());
    Image actual = GpuSynthesize(Ctx(), coefficients, p.basis, p.Levels());
    CompareStats stats;
    EXPECT_TRUE(ImagesMatch(expected, actual, magnitude, p.Tol(), &stats)) << p.Name();
    std::fprintf(stderr, "[mcd] %s synthesize: worst error %.3f of the tolerance\n",
                 p.Name().c_str(), stats.maxErrorRatio);
}

TEST_P(WaveletLarge, RoundTripReturnsInput) {
    const LargeCase &p = GetParam();
    Image in = p.Input();
    Image back =
        GpuSynthesize(Ctx(), GpuAnalyze(Ctx(), in, p.basis, p.Levels()), p.basis, p.Levels());
    ASSERT_TRUE(back.SameShape(in));
    Image magnitude = ref::WaveletSynthesizeMagnitude(
        ref::WaveletAnalyzeMagnitude(in, p.basis, p.Levels()), p.basis, p.Levels());
    Tolerance tol{2 * kUlpsPerLevel * kUnitRoundoff * std::max(p.Levels(), 1), 0, 1e-9};
    CompareStats stats;
    EXPECT_TRUE(ImagesMatch(in, back, magnitude, tol, &stats)) << p.Name();
    std::fprintf(stderr, "[mcd] %s round trip: worst error %.3f of the tolerance\n",
                 p.Name().c_str(), stats.maxErrorRatio);
}

TEST_P(WaveletLarge, RerunIsBitIdentical) {
    const LargeCase &p = GetParam();
    Image in = p.Input();
    Image a = GpuAnalyze(Ctx(), in, p.basis, p.Levels());
    Image b = GpuAnalyze(Ctx(), in, p.basis, p.Levels());
    EXPECT_TRUE(BitIdentical(a, b)) << p.Name();
    Image sa = GpuSynthesize(Ctx(), a, p.basis, p.Levels());
    Image sb = GpuSynthesize(Ctx(), a, p.basis, p.Levels());
    EXPECT_TRUE(BitIdentical(sa, sb)) << p.Name();
}

INSTANTIATE_TEST_SUITE_P(
    Frames, WaveletLarge,
    ::testing::Values(
        LargeCase{1920, 1080, 3, WaveletBasis::Cdf97, 5, InputKind::Uniform},
        LargeCase{1920, 1080, 3, WaveletBasis::Cdf97, -1, InputKind::LogNormalFireflies},
        LargeCase{2049, 1031, 1, WaveletBasis::LeGall53, 5, InputKind::LogNormalFireflies},
        LargeCase{2049, 1031, 1, WaveletBasis::LeGall53, -1, InputKind::Uniform},
        // 4K RGB: 99.5 MB per image, near lavapipe's 128 MiB storage-buffer range.
        LargeCase{3840, 2160, 3, WaveletBasis::Cdf97, 5, InputKind::Uniform}),
    [](const ::testing::TestParamInfo<LargeCase> &info) { return info.param.Name(); });

}  // namespace
}  // namespace mcd::test
