// The operation formulas of `bench kernels` (tools/mcdenoise/kernel_ops.h) against counts
// made by walking each kernel's loops one operation at a time, on dispatches decoded from
// their push constants and grid as the recorder keeps them.
#include <gtest/gtest.h>

#include <cstring>
#include <map>
#include <optional>
#include <string>

#include "awr/shrink.h"
#include "harness/gpu_fixture.h"
#include "host/vk/gpu_image.h"
#include "host/wavelet.h"
#include "host/wavelet/transform.h"
#include "rhf/distance.h"
#include "tools/mcdenoise/kernel_ops.h"
#include "wavelet/swt.h"
#include "wavelet/swt_analyze.h"
#include "wavelet/tile.h"

namespace mcd::tool {
namespace {

template <typename Push>
vk::KeptDispatch Kept(const char *kernel, const Push &push, uint32_t gx, uint32_t gy,
                      uint32_t gz) {
    vk::KeptDispatch d;
    d.timing.kernel = kernel;
    d.timing.groups = {gx, gy, gz};
    d.push.resize(sizeof(Push));
    std::memcpy(d.push.data(), &push, sizeof(Push));
    return d;
}

// rhf/distance.comp's interior path, walked: per centre of the strip and offset, each row
// of the patch, each centre's columns add a sum and a count, then count + 1e-4 and a divide.
TEST(KernelOps, RhfDistanceMatchesItsLoops) {
    for (int patchHalf : {0, 1, 3})
        for (int searchHalf : {1, 6}) {
            const int width = 37, rows = 5, side = 2 * searchHalf + 1;
            shader::RhfDistancePush push{width, 40, patchHalf, 0, 0, 40, 3, rows};
            vk::KeptDispatch d = Kept("rhf_distance", push, (width + 7) / 8, rows, side * side);
            double walked = 0;
            for (int r = 0; r < rows; ++r)
                for (int x = 0; x < width; ++x)
                    for (int o = 0; o < side * side; ++o) {
                        for (int ty = -patchHalf; ty <= patchHalf; ++ty)
                            for (int tx = -patchHalf; tx <= patchHalf; ++tx) walked += 2;
                        walked += 2;
                    }
            std::optional<double> flops = KernelFlops(d);
            ASSERT_TRUE(flops.has_value());
            EXPECT_EQ(*flops, walked)
                << "patch half " << patchHalf << ", search half " << searchHalf;
        }
}

// awr/shrink.comp: sqrt, a multiply, a subtract, a max and the sign's multiply per
// coefficient of every channel.
TEST(KernelOps, AwrShrinkMatchesItsLoops) {
    shader::AwrShrinkPush push{13, 7, 2, 1, 1.5f};
    vk::KeptDispatch d = Kept("awr_shrink", push, 1, 7, 3);
    double walked = 0;
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < 7; ++y)
            for (int x = 0; x < 13; ++x) walked += 5;
    EXPECT_EQ(KernelFlops(d).value_or(-1), walked);
}

// Taps of the filter at an even and an odd position: the analysis's, or the synthesis's.
std::pair<int, int> Taps(WaveletBasis basis, bool analysis) {
    if (basis == WaveletBasis::Cdf97) return analysis ? std::pair{9, 7} : std::pair{7, 9};
    if (basis == WaveletBasis::LeGall53) return analysis ? std::pair{5, 3} : std::pair{3, 5};
    return {1, 1};
}

// Every level's rows and columns passes walked position by position, a multiply and an
// add per tap plus `extra`.
double WalkedWaveletFlops(int width, int height, int channels, int levels, WaveletBasis basis,
                          bool analysis, double extra) {
    auto [evenTaps, oddTaps] = Taps(basis, analysis);
    double flops = 0;
    for (int level = 0; level < levels; ++level) {
        int w = LevelExtent(width, level), h = LevelExtent(height, level);
        for (int c = 0; c < channels; ++c)
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) {
                    flops += 2 * (x % 2 == 0 ? evenTaps : oddTaps) + extra;  // rows pass
                    flops += 2 * (y % 2 == 0 ? evenTaps : oddTaps) + extra;  // columns pass
                }
    }
    return flops;
}

// The transforms' dispatches as the recorder keeps them (split into interior and edge
// parts above WAVELET_SPLIT_LENGTH positions, whole below), their formulas summed per
// kernel, against the walk: each position of each level filtered once per pass.
TEST(KernelOps, WaveletPassesMatchTheirLoops) {
    vk::Context &context = test::TestContext();
    const int width = 300, height = 270, channels = 3, levels = 3;
    vk::GpuImage in(context, width, height, channels, "in"),
        coef(context, width, height, channels, "coef");
    WaveletTransform transform(context, width, height, channels);
    for (WaveletBasis basis :
         {WaveletBasis::Haar, WaveletBasis::LeGall53, WaveletBasis::Cdf97}) {
        vk::Recorder recorder(context);
        transform.RecordAnalysis(recorder, basis, levels, in, coef);
        transform.RecordSqAnalysis(recorder, basis, levels, in, coef, 1.f, 1.f);
        transform.RecordSynthesis(recorder, basis, levels, coef, in);
        vk::KeepDispatches(true);
        recorder.Submit();
        vk::KeepDispatches(false);
        std::map<std::string, double> flops, bytes;
        int split = 0;
        for (const vk::KeptDispatch &d : vk::KeptDispatches()) {
            std::optional<double> f = KernelFlops(d);
            ASSERT_TRUE(f.has_value()) << d.timing.kernel;
            flops[d.timing.kernel] += *f;
            bytes[d.timing.kernel] += KernelTouchedBytes(d).value_or(-1e30);
            split += d.Spec(WAVELET_SPEC_PART, WAVELET_PART_ALL) != WAVELET_PART_ALL;
        }
        EXPECT_GT(split, 0) << "no pass ran in parts: the test covers less than it means to";
        int b = int(basis);
        EXPECT_EQ(flops["wavelet_analyze"],
                  WalkedWaveletFlops(width, height, channels, levels, basis, true, 0))
            << "basis " << b;
        EXPECT_EQ(flops["wavelet_sqanalyze"],
                  WalkedWaveletFlops(width, height, channels, levels, basis, true, 1))
            << "basis " << b;
        EXPECT_EQ(flops["wavelet_synthesize"],
                  WalkedWaveletFlops(width, height, channels, levels, basis, false, 0))
            << "basis " << b;
        // Each pass reads and writes each position of its level's region once.
        double touched = 0;
        for (int level = 0; level < levels; ++level)
            touched +=
                2.0 * LevelExtent(width, level) * LevelExtent(height, level) * channels * 8;
        for (const char *kernel :
             {"wavelet_analyze", "wavelet_sqanalyze", "wavelet_synthesize"})
            EXPECT_EQ(bytes[kernel], touched) << kernel << ", basis " << b;
    }
}

// An SWT pass touches its planes of the level, not every level's planes it binds: the rows
// pass of the analysis reads one and writes two per position of each channel.
TEST(KernelOps, SwtPassTouchesItsPlanes) {
    shader::WaveletSwtAnalyzePush push{};
    push.width = 11, push.height = 5;
    vk::KeptDispatch d = Kept("wavelet_swt_analyze", push, 1, 5, 3);
    d.specialization = {{WAVELET_SWT_SPEC_BASIS, MCD_WAVELET_CDF97},
                        {WAVELET_SWT_SPEC_AXIS, WAVELET_SWT_ROWS}};
    EXPECT_EQ(KernelTouchedBytes(d).value_or(-1), 3.0 * 4 * 11 * 5 * 3);
    d.specialization[1].second = WAVELET_SWT_COLUMNS;
    EXPECT_EQ(KernelTouchedBytes(d).value_or(-1), 6.0 * 4 * 11 * 5 * 3);
    d.timing.kernel = "pivot_fit";
    EXPECT_FALSE(KernelTouchedBytes(d).has_value());
}

// A kernel without a formula says so instead of counting nothing.
TEST(KernelOps, KernelWithoutFormulaHasNone) {
    vk::KeptDispatch d;
    d.timing.kernel = "pivot_fit";
    EXPECT_FALSE(KernelFlops(d).has_value());
    EXPECT_TRUE(KernelFlopsRule("pivot_fit").empty());
    EXPECT_FALSE(KernelFlopsRule("rhf_distance").empty());
}

}  // namespace
}  // namespace mcd::tool
