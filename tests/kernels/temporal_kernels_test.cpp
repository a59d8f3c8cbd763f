// The temporal kernels (shaders/temporal/{match,fold,finish}.comp) each alone against the
// CPU reference (cpu_reference/temporal.h) on seeded random and edge inputs: odd sizes down
// to 1x1, NaN/Inf in colours, features and motion vectors, positions and vectors that
// point off the frame, all-rejected pixels, every mode and flag; and two runs bit-identical.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "cpu_reference/temporal.h"
#include "harness/compare.h"
#include "harness/gpu_fixture.h"
#include "harness/inputs.h"
#include "host/kernels/temporal_finish.h"
#include "host/kernels/temporal_fold.h"
#include "host/kernels/temporal_match.h"
#include "temporal/temporal.h"

namespace mcd::test {
namespace {

constexpr double kUnitRoundoff = 0x1p-24;
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

// Features in regions (a region's normal, depth, albedo and id, each pixel's own small
// noise), so that a neighbour's pixel in the same region mostly agrees and one in another
// does not; a few background pixels (zero normal), dark albedos under the floor, and with
// NonFinite NaN/Inf in some planes.
Image RegionFeatures(int w, int h, InputKind kind, uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> unit(0.f, 1.f), noise(-1.f, 1.f);
    const float normals[3][3] = {{0, 0, 1}, {0.8f, 0, 0.6f}, {0, -1, 0}};
    Image f(w, h, TEMPORAL_FEATURE_PLANES);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            int r = (x / 5 + y / 4) % 3;
            bool background = unit(rng) < 0.05f;
            for (int c = 0; c < 3; ++c)
                f.At(TEMPORAL_FEATURE_NORMAL + c, y, x) =
                    background ? 0.f : normals[r][c] + 0.05f * noise(rng);
            f.At(TEMPORAL_FEATURE_DEPTH, y, x) = 2.f + float(r) + 0.05f * noise(rng);
            bool dark = unit(rng) < 0.1f;
            for (int c = 0; c < 3; ++c)
                f.At(TEMPORAL_FEATURE_ALBEDO + c, y, x) =
                    dark ? 0.02f * unit(rng) : 0.1f + 0.3f * float(r) + 0.01f * noise(rng);
            f.At(TEMPORAL_FEATURE_ID, y, x) = float(r);
        }
    if (kind == InputKind::NonFinite) {
        const float specials[3] = {kNaN, kInf, -kInf};
        for (size_t i = 0; i < 1 + f.Size() / 50; ++i)
            f.data[rng() % f.Size()] = specials[rng() % 3];
    }
    return f;
}

// Positions near the pixel centres (up to 2.5 pixels off, some off the frame, a few NaN);
// integer offsets for Constant (Blender's vectors of a still camera are whole pixels).
Image RandomPositions(int w, int h, InputKind kind, uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> offset(-2.5f, 2.5f), unit(0.f, 1.f);
    Image p(w, h, 2);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float dx = offset(rng), dy = offset(rng);
            if (kind == InputKind::Constant) dx = std::round(dx), dy = std::round(dy);
            p.At(0, y, x) = float(x) + 0.5f + dx;
            p.At(1, y, x) = float(y) + 0.5f + dy;
            if (unit(rng) < 0.03f) p.At(rng() % 2, y, x) = kNaN;
        }
    return p;
}

// Motion vectors of up to 2 pixels (whole pixels for Constant), NaN/Inf with NonFinite.
Image RandomMotion(int w, int h, InputKind kind, uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> step(-2.f, 2.f);
    Image m(w, h, 4);
    for (float &v : m.data) v = kind == InputKind::Constant ? std::round(step(rng)) : step(rng);
    if (kind == InputKind::NonFinite)
        m.data[rng() % m.Size()] = kInf, m.data[rng() % m.Size()] = kNaN;
    return m;
}

// The chain's previous positions: where the neighbour's vector back from each position
// leads, give or take 1.5 pixels, so that the forward-backward check passes and fails.
Image PreviousPositions(const Image &positions, const Image &motion, int direction,
                        uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> jitter(-1.5f, 1.5f);
    int w = positions.width, h = positions.height;
    Image prev(w, h, 2);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float px = positions.At(0, y, x), py = positions.At(1, y, x);
            int qx = std::isfinite(px) ? std::clamp(int(std::floor(px)), 0, w - 1) : 0;
            int qy = std::isfinite(py) ? std::clamp(int(std::floor(py)), 0, h - 1) : 0;
            float bx = direction > 0 ? motion.At(0, qy, qx) : -motion.At(2, qy, qx);
            float by = direction > 0 ? -motion.At(1, qy, qx) : motion.At(3, qy, qx);
            prev.At(0, y, x) = px + bx + jitter(rng);
            prev.At(1, y, x) = py + by + jitter(rng);
        }
    return prev;
}

// Samples per pixel 1..16, with zeros and NaN (weighed 1).
Image RandomSpp(int w, int h, uint64_t seed) {
    std::mt19937_64 rng(seed);
    Image s(w, h, 1);
    for (float &v : s.data) {
        uint64_t r = rng() % 40;
        v = r == 0 ? 0.f : r == 1 ? kNaN : float(1 + rng() % 16);
    }
    return s;
}

struct MatchConfig {
    bool self, first;
    int direction;
    bool spp, motion;
    int features;
    float motionTol;
};

std::vector<MatchConfig> MatchConfigs() {
    return {
        {false, false, 1, true, true, 15, 1.f},     {false, true, -1, true, true, 15, 1.f},
        {false, false, -1, false, true, 15, 0.f},   {false, false, 1, true, false, 15, 1.f},
        {false, false, 1, false, false, 0, 1.f},    {false, true, 1, true, true, 1 | 8, 0.5f},
        {false, false, -1, true, true, 2 | 4, 2.f}, {true, false, -1, true, true, 15, 1.f},
        {true, false, 1, false, false, 15, 1.f}};
}

std::unique_ptr<vk::GpuImage> Upload(vk::Context &ctx, const Image &image, const char *name) {
    auto g =
        std::make_unique<vk::GpuImage>(ctx, image.width, image.height, image.channels, name);
    g->Upload(image);
    return g;
}

ref::TemporalMatched GpuMatch(vk::Context &ctx, const Image &cur, const Image &features,
                              const Image &color, const Image *spp, const Image *motion,
                              const Image &previous, const Image &position,
                              const MatchConfig &m, const TemporalMatchTest &test) {
    int w = color.width, h = color.height;
    auto gCur = Upload(ctx, cur, "cur"), gFeat = Upload(ctx, features, "features");
    auto gColor = Upload(ctx, color, "color"), gPrev = Upload(ctx, previous, "previous");
    auto gPos = Upload(ctx, position, "position");
    std::unique_ptr<vk::GpuImage> gSpp, gMotion;
    if (spp) gSpp = Upload(ctx, *spp, "spp");
    if (motion) gMotion = Upload(ctx, *motion, "motion");
    vk::GpuImage weight(ctx, w, h, 1, "weight"), next(ctx, w, h, 2, "next");
    vk::Recorder recorder(ctx);
    RecordTemporalMatch(ctx, recorder, *gCur,
                        {gFeat.get(), gColor.get(), gSpp.get(), gMotion.get()}, *gPrev, *gPos,
                        m.self, m.first, m.direction, test, weight, next);
    recorder.Submit();
    return {weight.Download(), next.Download()};
}

// Decisions are comparisons and positions float sums the reference makes in float too:
// both outputs match exactly (NaN where NaN).
class TemporalMatchKernel : public GpuTestWithParam<KernelShape> {};

TEST_P(TemporalMatchKernel, MatchesReferenceAndRepeats) {
    const auto [w, h, channels, kind] = GetParam();
    std::string name = fmt::format("match{}x{}{}", w, h, InputKindName(kind));
    Image cur = RegionFeatures(w, h, kind, SeedFromName(name + "cur"));
    Image features = RegionFeatures(w, h, kind, SeedFromName(name + "nb"));
    Image color = MakeInput(kind, w, h, channels, SeedFromName(name + "color"));
    Image spp = RandomSpp(w, h, SeedFromName(name + "spp"));
    Image motion = RandomMotion(w, h, kind, SeedFromName(name + "motion"));
    Image position = RandomPositions(w, h, kind, SeedFromName(name + "position"));
    int accepted = 0, rejected = 0;
    for (const MatchConfig &m : MatchConfigs()) {
        SCOPED_TRACE(fmt::format(
            "self {} first {} direction {} spp {} motion {} features {} "
            "tol {}",
            m.self, m.first, m.direction, m.spp, m.motion, m.features, m.motionTol));
        Image previous =
            PreviousPositions(position, motion, m.direction, SeedFromName(name + "p"));
        TemporalMatchTest test{m.features, 0.9f, 0.1f, 0.1f, m.motionTol};
        ref::TemporalTest refTest{m.features, double(test.normalCos), double(test.depthRel),
                                  double(test.albedoRel), double(test.motionTol)};
        ref::TemporalMatched expected = ref::TemporalMatch(
            cur, features, color, m.spp ? &spp : nullptr, m.motion ? &motion : nullptr,
            previous, position, m.self, m.first, m.direction, refTest);
        ref::TemporalMatched actual =
            GpuMatch(Ctx(), cur, features, color, m.spp ? &spp : nullptr,
                     m.motion ? &motion : nullptr, previous, position, m, test);
        EXPECT_TRUE(ImagesMatch(expected.weight, actual.weight, {}, {0, 0, 0}));
        EXPECT_TRUE(ImagesMatch(expected.next, actual.next, {}, {0, 0, 0}));
        ref::TemporalMatched again =
            GpuMatch(Ctx(), cur, features, color, m.spp ? &spp : nullptr,
                     m.motion ? &motion : nullptr, previous, position, m, test);
        EXPECT_TRUE(BitIdentical(actual.weight, again.weight));
        EXPECT_TRUE(BitIdentical(actual.next, again.next));
        for (float v : expected.weight.data) (v > 0 ? accepted : rejected) += 1;
    }
    // The cases exercise both outcomes (a 1x1 frame may only ever accept or reject).
    if (w * h > 20) {
        EXPECT_GT(accepted, w * h);
        EXPECT_GT(rejected, w * h);
    }
}

INSTANTIATE_TEST_SUITE_P(Cases, TemporalMatchKernel, testing::ValuesIn(KernelShapes()),
                         KernelShapeName);

// Weights 0 (a third of the pixels) or 1..8, with positions inside the frame where the
// weight is > 0 and anything (NaN, off the frame) where it is 0.
void WeightsAndPositions(int w, int h, uint64_t seed, Image &weight, Image &position) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> unit(0.f, 1.f);
    weight = Image(w, h, 1);
    position = Image(w, h, 2);
    for (size_t i = 0; i < weight.Size(); ++i) {
        bool accepted = unit(rng) < 0.67f;
        weight.data[i] = accepted ? float(1 + rng() % 8) : 0.f;
        position.Plane(0)[i] = accepted ? float(w) * unit(rng) * 0.999f : -3.f;
        position.Plane(1)[i] = accepted ? float(h) * unit(rng) * 0.999f : kNaN;
    }
}

struct FoldConfig {
    TemporalFoldMode mode;
    int power;
    bool first, centres;
};

std::vector<FoldConfig> FoldConfigs() {
    std::vector<FoldConfig> configs;
    for (bool first : {false, true})
        for (bool centres : {false, true}) {
            configs.push_back({TemporalFoldMode::Moments, 1, first, centres});
            for (int power : {0, 1, 2})
                configs.push_back({TemporalFoldMode::Sum, power, first, centres});
            configs.push_back({TemporalFoldMode::Min, 1, first, centres});
            configs.push_back({TemporalFoldMode::Max, 1, first, centres});
            configs.push_back({TemporalFoldMode::Count, 1, first, centres});
        }
    return configs;
}

ref::TemporalFoldMode RefMode(TemporalFoldMode mode) {
    switch (mode) {
        case TemporalFoldMode::Moments:
            return ref::TemporalFoldMode::Moments;
        case TemporalFoldMode::Sum:
            return ref::TemporalFoldMode::Sum;
        case TemporalFoldMode::Min:
            return ref::TemporalFoldMode::Min;
        case TemporalFoldMode::Max:
            return ref::TemporalFoldMode::Max;
        case TemporalFoldMode::Count:
            return ref::TemporalFoldMode::Count;
    }
    return ref::TemporalFoldMode::Moments;
}

Image GpuFold(vk::Context &ctx, const Image &value, const Image &position, const Image &weight,
              const Image &total, const FoldConfig &f, const Image &state) {
    auto gValue = Upload(ctx, value, "value"), gPos = Upload(ctx, position, "position");
    auto gWeight = Upload(ctx, weight, "weight"), gTotal = Upload(ctx, total, "total");
    auto gState = Upload(ctx, state, "state");
    vk::Recorder recorder(ctx);
    RecordTemporalFold(ctx, recorder, *gValue, *gPos, *gWeight, *gTotal,
                       {f.mode, f.power, f.first, f.centres}, *gState);
    recorder.Submit();
    return gState->Download();
}

// The bound per element, from the arithmetic (u the unit roundoff): Moments' mean a few
// operations on values of |A| + |x| (8u of that); its deviations B + w d (x - A') where
// x - A' carries the mean's error: 8u of |B| + w |d| (|d| + |A| + |x|); Sum 4u of |A| +
// f |x|; Min, Max and Count are exact (a float sum of whole numbers, a selection).
Image FoldScale(const Image &value, const Image &position, const Image &weight,
                const Image &total, const FoldConfig &f, const Image &state) {
    int w = weight.width, h = weight.height;
    size_t n = size_t(w) * h;
    int C = f.mode == TemporalFoldMode::Count ? 1 : value.channels;
    Image scale(w, h, state.channels);
    for (int c = 0; c < C; ++c)
        for (size_t i = 0; i < n; ++i) {
            double wt = weight.data[i], x = 0;
            if (wt > 0 && f.mode != TemporalFoldMode::Count) {
                size_t k = f.centres ? i
                                     : size_t(std::floor(position.Plane(1)[i])) * w +
                                           size_t(std::floor(position.Plane(0)[i]));
                x = std::fabs(value.Plane(c)[k]);
            }
            double a = f.first ? 0 : std::fabs(state.Plane(c)[i]);
            if (f.mode == TemporalFoldMode::Moments) {
                double b = f.first ? 0 : std::fabs(state.Plane(C + c)[i]);
                scale.Plane(c)[i] = float(a + x);
                scale.Plane(C + c)[i] = float(b + wt * (a + x) * (2 * (a + x)));
            } else if (f.mode == TemporalFoldMode::Sum) {
                double factor = f.power == 0 ? 1 : f.power == 1 ? wt : wt * wt;
                scale.Plane(c)[i] = float(a + factor * x);
            }
        }
    return scale;
}

class TemporalFoldKernel : public GpuTestWithParam<KernelShape> {};

TEST_P(TemporalFoldKernel, MatchesReferenceAndRepeats) {
    const auto [w, h, channels, kind] = GetParam();
    std::string name = fmt::format("fold{}x{}{}", w, h, InputKindName(kind));
    Image weight, position;
    WeightsAndPositions(w, h, SeedFromName(name + "wp"), weight, position);
    Image value = MakeInput(kind, w, h, channels, SeedFromName(name + "value"));
    // Folded before: weights 0..20 (0 with an empty state) and a count.
    Image total = MakeVarianceInput(InputKind::Uniform, w, h, 2, SeedFromName(name + "total"));
    for (float &v : total.data) v = std::round(20.f * v);
    for (const FoldConfig &f : FoldConfigs()) {
        SCOPED_TRACE(fmt::format("mode {} power {} first {} centres {}", int(f.mode), f.power,
                                 f.first, f.centres));
        int C = f.mode == TemporalFoldMode::Count ? 1 : channels;
        bool two = f.mode == TemporalFoldMode::Moments || f.mode == TemporalFoldMode::Count;
        Image state = MakeInput(kind, w, h, two ? 2 * C : C, SeedFromName(name + "state"));
        if (two)  // B, a sum of squares or a count, is >= 0
            for (size_t i = size_t(C) * w * h; i < state.Size(); ++i)
                if (std::isfinite(state.data[i])) state.data[i] = std::fabs(state.data[i]);
        Image expected = state;
        ref::TemporalFold(value, position, weight, total, RefMode(f.mode), f.power, f.first,
                          f.centres, expected);
        Image actual = GpuFold(Ctx(), value, position, weight, total, f, state);
        Image scale = FoldScale(value, position, weight, total, f, state);
        EXPECT_TRUE(ImagesMatch(expected, actual, scale, {8 * kUnitRoundoff, 0, 1e-10}));
        EXPECT_TRUE(
            BitIdentical(actual, GpuFold(Ctx(), value, position, weight, total, f, state)));
    }
}

INSTANTIATE_TEST_SUITE_P(Cases, TemporalFoldKernel, testing::ValuesIn(KernelShapes()),
                         KernelShapeName);

struct FinishInputs {
    Image moments, counts, pooled, raw, sum0, counts0, sum1, counts1;
};

// Counts: 0 to 5 frames (a fifth of the pixels 0, a fifth 1), weights 1..8 a frame; the
// moments' B >= 0; the halves' weights a part of the whole's, some 0.
FinishInputs RandomFinishInputs(int w, int h, int channels, InputKind kind, uint64_t seed) {
    std::mt19937_64 rng(seed);
    FinishInputs in;
    in.moments = MakeInput(kind, w, h, 2 * channels, seed + 1);
    for (size_t i = size_t(channels) * w * h; i < in.moments.Size(); ++i)
        if (std::isfinite(in.moments.data[i]))
            in.moments.data[i] = std::fabs(in.moments.data[i]);
    in.pooled = MakeVarianceInput(kind, w, h, channels, seed + 2);
    in.raw = MakeInput(kind, w, h, channels, seed + 3);
    in.sum0 = MakeInput(kind, w, h, channels, seed + 4);
    in.sum1 = MakeInput(kind, w, h, channels, seed + 5);
    in.counts = Image(w, h, 2), in.counts0 = Image(w, h, 2), in.counts1 = Image(w, h, 2);
    for (size_t i = 0; i < size_t(w) * h; ++i) {
        int frames = int(rng() % 5);
        double weights = 0, w0 = 0;
        for (int f = 0; f < frames; ++f) {
            double wt = double(1 + rng() % 8);
            weights += wt;
            if (f % 2 == 0) w0 += wt;
        }
        in.counts.Plane(0)[i] = float(weights), in.counts.Plane(1)[i] = float(frames);
        in.counts0.Plane(0)[i] = float(w0), in.counts1.Plane(0)[i] = float(weights - w0);
    }
    return in;
}

Image GpuFinish(vk::Context &ctx, const FinishInputs &in, bool pooled, bool halves,
                int radius) {
    auto m = Upload(ctx, in.moments, "moments"), c = Upload(ctx, in.counts, "counts");
    auto p = Upload(ctx, in.pooled, "pooled"), r = Upload(ctx, in.raw, "raw");
    auto s0 = Upload(ctx, in.sum0, "sum0"), c0 = Upload(ctx, in.counts0, "counts0");
    auto s1 = Upload(ctx, in.sum1, "sum1"), c1 = Upload(ctx, in.counts1, "counts1");
    TemporalFinishInputs inputs{m.get(), c.get(), r.get(), pooled ? p.get() : nullptr};
    if (halves)
        inputs.sum0 = s0.get(), inputs.counts0 = c0.get(), inputs.sum1 = s1.get(),
        inputs.counts1 = c1.get();
    vk::GpuImage out(ctx, in.raw.width, in.raw.height, (halves ? 4 : 2) * in.raw.channels,
                     "out");
    vk::Recorder recorder(ctx);
    RecordTemporalFinish(ctx, recorder, inputs, radius, out);
    recorder.Submit();
    return out.Download();
}

// The mean is a copy; a variance one division of a product (3u) or, filled, a sum over
// up to (2r+1)^2 pixels then two divisions ((2r+1)^2 + 3)u of the result's own size,
// taken from the reference; the halves one division (1u).
class TemporalFinishKernel : public GpuTestWithParam<KernelShape> {};

TEST_P(TemporalFinishKernel, MatchesReferenceAndRepeats) {
    const auto [w, h, channels, kind] = GetParam();
    std::string name = fmt::format("finish{}x{}{}", w, h, InputKindName(kind));
    FinishInputs in = RandomFinishInputs(w, h, channels, kind, SeedFromName(name));
    for (bool pooled : {false, true})
        for (bool halves : {false, true})
            for (int radius : {0, 2}) {
                SCOPED_TRACE(
                    fmt::format("pooled {} halves {} radius {}", pooled, halves, radius));
                Image expected = ref::TemporalFinish(
                    in.moments, in.counts, pooled ? &in.pooled : nullptr, in.raw,
                    halves ? &in.sum0 : nullptr, halves ? &in.counts0 : nullptr,
                    halves ? &in.sum1 : nullptr, halves ? &in.counts1 : nullptr, radius);
                Image actual = GpuFinish(Ctx(), in, pooled, halves, radius);
                double terms = (2 * radius + 1) * (2 * radius + 1) + 3;
                EXPECT_TRUE(
                    ImagesMatch(expected, actual, {}, {terms * kUnitRoundoff, 0, 1e-10}));
                EXPECT_TRUE(BitIdentical(actual, GpuFinish(Ctx(), in, pooled, halves, radius)));
            }
}

INSTANTIATE_TEST_SUITE_P(Cases, TemporalFinishKernel, testing::ValuesIn(KernelShapes()),
                         KernelShapeName);

}  // namespace
}  // namespace mcd::test
