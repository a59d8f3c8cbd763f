// nfor's glint floor on the weights' noise (shaders/nfor/glint_rows.comp, glint.comp) against
// its CPU reference (ref::NforGlintNoise): random and edge inputs, the gate's edge, the floor's
// value.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "cpu_reference/nfor.h"
#include "harness/compare.h"
#include "harness/gpu_fixture.h"
#include "harness/inputs.h"
#include "host/error.h"
#include "host/kernels/nfor_kernels.h"
#include "host/methods/nfor.h"

namespace mcd::test {
namespace {

// The kernels' floored variance and mask.
struct GlintRun {
    Image variance, floored;
};

GlintRun RunGlint(vk::Context &ctx, const Image &color, const Image &albedo, const Image &trust,
                  float gate, int reach, float scale, const Image &variance) {
    const int w = color.width, h = color.height;
    vk::GpuImage c = UploadImage(ctx, color, "color"), a = UploadImage(ctx, albedo, "albedo"),
                 t = UploadImage(ctx, trust, "trust"),
                 v = UploadImage(ctx, variance, "variance");
    vk::GpuImage near(ctx, w, h, 1, "near"), floored(ctx, w, h, 1, "floored");
    vk::Recorder recorder(ctx);
    RecordNforGlintNoise(ctx, recorder, c, a, t, gate, reach, scale, near, v, floored);
    recorder.Submit();
    return {v.Download(), floored.Download()};
}

// The reference's floored variance and mask.
GlintRun Reference(const Image &color, const Image &albedo, const Image &trust, float gate,
                   int reach, float scale, const Image &variance) {
    GlintRun run{variance, Image()};
    run.floored = ref::NforGlintNoise(color, albedo, trust, gate, reach, scale, &run.variance);
    return run;
}

struct GlintCase {
    int w, h, channels;
    InputKind kind;
};

std::string GlintCaseName(const testing::TestParamInfo<GlintCase> &info) {
    return fmt::format("{}x{}x{}_{}", info.param.w, info.param.h, info.param.channels,
                       InputKindName(info.param.kind));
}

std::vector<GlintCase> GlintCases() {
    std::vector<GlintCase> cases;
    for (auto [w, h, ch] : {std::tuple{37, 23, 3}, std::tuple{1, 1, 3}, std::tuple{1, 9, 1},
                            std::tuple{41, 2, 4}, std::tuple{11, 1, 3}})
        for (InputKind kind : {InputKind::Uniform, InputKind::LogNormalFireflies,
                               InputKind::Constant, InputKind::Impulse, InputKind::NonFinite})
            cases.push_back({w, h, ch, kind});
    return cases;
}

class NforGlintKernel : public GpuTestWithParam<GlintCase> {};

// Random and edge colours and variances (fireflies, a constant, an impulse, NaN and Inf) over
// albedos with sparse glints (some NaN, some exactly at the gate) and a trust mostly 0, at
// three reaches and two scales. The kernel sums in float in the reference's order with no
// contraction (precise), so the two agree bit for bit; two runs are bit-identical.
TEST_P(NforGlintKernel, MatchesTheReferenceAndRepeats) {
    const auto [w, h, ch, kind] = GetParam();
    const std::string name = fmt::format("glint{}x{}x{}{}", w, h, ch, InputKindName(kind));
    Image color = MakeVarianceInput(kind, w, h, ch, SeedFromName(name));
    Image variance = MakeVarianceInput(kind, w, h, ch, SeedFromName(name + "variance"));
    for (float &v : variance.data) v *= 0.01f;
    std::mt19937_64 rng(SeedFromName(name + "albedo"));
    std::uniform_real_distribution<float> unit(0.f, 1.f);
    Image albedo(w, h, 3), trust(w, h, 1);
    const float gate = 8, nan = std::numeric_limits<float>::quiet_NaN(),
                inf = std::numeric_limits<float>::infinity();
    for (float &a : albedo.data) {
        const float u = unit(rng);
        a = u < 0.01f    ? 20 * unit(rng) + gate
            : u < 0.02f  ? gate
            : u < 0.03f  ? nan
            : u < 0.035f ? inf
                         : unit(rng);
    }
    for (float &t : trust.data) t = unit(rng) < 0.8f ? 0.f : 1.f;
    int raised = 0;
    for (int reach : {16, 3, 0})
        for (float scale : {0.1f, 2.f}) {
            SCOPED_TRACE(fmt::format("reach {}, scale {}", reach, scale));
            GlintRun want = Reference(color, albedo, trust, gate, reach, scale, variance);
            GlintRun got = RunGlint(Ctx(), color, albedo, trust, gate, reach, scale, variance);
            EXPECT_TRUE(BitIdentical(want.variance, got.variance));
            EXPECT_TRUE(BitIdentical(want.floored, got.floored));
            GlintRun again =
                RunGlint(Ctx(), color, albedo, trust, gate, reach, scale, variance);
            EXPECT_TRUE(BitIdentical(got.variance, again.variance));
            EXPECT_TRUE(BitIdentical(got.floored, again.floored));
            for (float f : got.floored.data) raised += f > 0;
        }
    if (w * h > 100 && kind == InputKind::Uniform) {
        EXPECT_GT(raised, 0);
    }
}

INSTANTIATE_TEST_SUITE_P(Cases, NforGlintKernel, testing::ValuesIn(GlintCases()),
                         GlintCaseName);

class NforGlintRowsKernel : public GpuTestWithParam<GlintCase> {};

// The row pass alone: glints (some NaN, some exactly at the gate) at three reaches, kernel
// and reference alike (comparisons only: exact), two runs bit-identical.
TEST_P(NforGlintRowsKernel, MatchesTheReferenceAndRepeats) {
    const auto [w, h, ch, kind] = GetParam();
    const std::string name = fmt::format("glintRows{}x{}x{}{}", w, h, ch, InputKindName(kind));
    Image albedo = MakeVarianceInput(kind, w, h, ch == 4 ? 1 : 3, SeedFromName(name));
    for (float &a : albedo.data) a *= 4;  // uniform inputs reach past the gate of 3
    for (int reach : {16, 3, 0}) {
        SCOPED_TRACE(fmt::format("reach {}", reach));
        auto run = [&] {
            vk::GpuImage a = UploadImage(Ctx(), albedo, "albedo"), near(Ctx(), w, h, 1, "near");
            vk::Recorder recorder(Ctx());
            RecordNforGlintRows(Ctx(), recorder, a, 3.f, reach, near);
            recorder.Submit();
            return near.Download();
        };
        Image got = run();
        EXPECT_TRUE(BitIdentical(ref::NforGlintRows(albedo, 3.f, reach), got));
        EXPECT_TRUE(BitIdentical(got, run()));
    }
}

INSTANTIATE_TEST_SUITE_P(Cases, NforGlintRowsKernel, testing::ValuesIn(GlintCases()),
                         GlintCaseName);

// One glint at (2, 20) of a 40x40 frame whose albedo is noise everywhere (trust 0) and
// whose variance is tiny: the floor reaches exactly 16 pixels (Chebyshev) and not 17, on the
// row and on the diagonal; an albedo exactly at the gate is no glint; a trusted pixel is
// never raised. Kernel and reference alike.
TEST_F(GpuTest, NforGlintGateEndsAtItsReach) {
    const int w = 40, h = 40, reach = 16;
    const float gate = 8, scale = 0.1f;
    Image color = MakeVarianceInput(InputKind::Uniform, w, h, 3, SeedFromName("glintGate"));
    Image albedo(w, h, 3), trust(w, h, 1), variance(w, h, 3);
    std::fill(albedo.data.begin(), albedo.data.end(), 0.5f);
    std::fill(variance.data.begin(), variance.data.end(), 1e-9f);
    albedo.At(0, 20, 2) = 9;
    albedo.At(2, 5, 35) = gate;  // at the gate: no glint
    trust.At(0, 20, 10) = 1;     // trusted: kept
    for (bool onGpu : {true, false}) {
        SCOPED_TRACE(onGpu ? "kernel" : "reference");
        GlintRun run = onGpu
                           ? RunGlint(Ctx(), color, albedo, trust, gate, reach, scale, variance)
                           : Reference(color, albedo, trust, gate, reach, scale, variance);
        auto raised = [&](int x, int y) { return run.floored.At(0, y, x) > 0; };
        EXPECT_TRUE(raised(2, 20));
        EXPECT_TRUE(raised(18, 20)) << "16 along the row";
        EXPECT_FALSE(raised(19, 20)) << "17 along the row";
        EXPECT_TRUE(raised(18, 36)) << "16 on the diagonal";
        EXPECT_FALSE(raised(18, 37)) << "17 down";
        EXPECT_TRUE(raised(2, 4)) << "16 up";
        EXPECT_FALSE(raised(2, 3)) << "17 up";
        EXPECT_FALSE(raised(35, 5)) << "an albedo at the gate is no glint";
        EXPECT_FALSE(raised(10, 20)) << "trusted";
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const bool inside = std::abs(x - 2) <= reach && std::abs(y - 20) <= reach &&
                                    !(x == 10 && y == 20);
                EXPECT_EQ(raised(x, y), inside) << x << "," << y;
                for (int c = 0; c < 3; ++c)
                    EXPECT_EQ(run.variance.At(c, y, x) > 1e-9f, inside) << x << "," << y;
            }
    }
}

// The floor's value: a 3x3 window of zeros around a centre of 9 has mean 1 and variance
// (8 x 1 + 64) / 9 = 8, so the centre's variance becomes scale x 8 where it was below and
// stays where it was above; a corner's window (4 pixels inside the frame) has mean 9 / 4.
TEST_F(GpuTest, NforGlintFloorIsTheWindowsVariance) {
    const int w = 5, h = 5;
    Image color(w, h, 1), albedo(w, h, 1), trust(w, h, 1), variance(w, h, 1);
    color.At(0, 2, 2) = 9;
    color.At(0, 0, 0) = 9;
    albedo.At(0, 4, 4) = 100;
    variance.At(0, 1, 2) = 5;  // above its floor: kept
    const float scale = 0.5f;
    for (bool onGpu : {true, false}) {
        SCOPED_TRACE(onGpu ? "kernel" : "reference");
        GlintRun run = onGpu ? RunGlint(Ctx(), color, albedo, trust, 8, 16, scale, variance)
                             : Reference(color, albedo, trust, 8, 16, scale, variance);
        EXPECT_FLOAT_EQ(run.variance.At(0, 2, 2), scale * 8.f);
        EXPECT_FLOAT_EQ(run.variance.At(0, 1, 2), 5.f);
        EXPECT_EQ(run.floored.At(0, 1, 2), 0.f);
        const float cornerMean = 9.f / 4,
                    cornerVariance =
                        ((9 - cornerMean) * (9 - cornerMean) + 3 * cornerMean * cornerMean) / 4;
        EXPECT_FLOAT_EQ(run.variance.At(0, 0, 0), scale * cornerVariance);
        EXPECT_EQ(run.variance.At(0, 4, 4), 0.f) << "a window of zeros";
    }
}

// Reach, gate and scale are checked.
TEST_F(GpuTest, NforGlintRejectsBadSettings) {
    Image color(3, 3, 3), albedo(3, 3, 3), trust(3, 3, 1), variance(3, 3, 3);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    EXPECT_THROW(RunGlint(Ctx(), color, albedo, trust, 8, -1, 0.1f, variance), Error);
    EXPECT_THROW(RunGlint(Ctx(), color, albedo, trust, 8, 65, 0.1f, variance), Error);
    EXPECT_THROW(RunGlint(Ctx(), color, albedo, trust, nan, 16, 0.1f, variance), Error);
    EXPECT_THROW(RunGlint(Ctx(), color, albedo, trust, 8, 16, -1.f, variance), Error);
    EXPECT_THROW(RunGlint(Ctx(), color, albedo, trust, 8, 16, nan, variance), Error);
}

// The host's guard on the output (GuardGlintFloor) against ref::GuardGlint, exactly (both
// only compare and copy): thin and one-pixel frames, raised pixels in the corners and one
// inside, NaN and +-Inf in the clamped colour; the count is the pixel-channels changed.
TEST(NforGlintGuard, MatchesTheReference) {
    const float nan = std::numeric_limits<float>::quiet_NaN(),
                inf = std::numeric_limits<float>::infinity();
    for (auto [w, h] : {std::pair{1, 1}, {1, 9}, {9, 1}, {13, 11}}) {
        SCOPED_TRACE(fmt::format("{}x{}", w, h));
        std::mt19937_64 rng(SeedFromName(fmt::format("glint guard {}x{}", w, h)));
        std::uniform_real_distribution<float> unit(0.f, 1.f);
        Image clamped(w, h, 3), output(w, h, 3), raised(w, h, 1);
        for (float &v : clamped.data) {
            const float u = unit(rng);
            v = u < 0.05f ? nan : u < 0.1f ? inf : u < 0.15f ? -inf : unit(rng);
        }
        for (float &v : output.data) v = unit(rng) < 0.05f ? nan : 0.5f * unit(rng);
        // The centre's window all +Inf in channel 0 and all NaN in channel 1: no minimum.
        for (int y = std::max(0, h / 2 - 1); y <= std::min(h - 1, h / 2 + 1); ++y)
            for (int x = std::max(0, w / 2 - 1); x <= std::min(w - 1, w / 2 + 1); ++x) {
                clamped.At(0, y, x) = inf;
                clamped.At(1, y, x) = nan;
            }
        raised.At(0, 0, 0) = 1;
        raised.At(0, h - 1, w - 1) = 1;
        raised.At(0, h / 2, w / 2) = 1;
        Image want = output, got = output;
        ref::GuardGlint(clamped, raised, &want);
        const size_t count = GuardGlintFloor(clamped, raised, &got);
        EXPECT_TRUE(BitIdentical(want, got));
        size_t changed = 0;
        for (size_t i = 0; i < got.data.size(); ++i)
            changed += std::memcmp(&got.data[i], &output.data[i], sizeof(float)) != 0;
        EXPECT_EQ(count, changed);
        if (w * h > 1) {
            EXPECT_GT(count, 0u);
        }
    }
}

}  // namespace
}  // namespace mcd::test
