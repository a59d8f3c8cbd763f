// Method nfor (feature regression): each GPU kernel against the CPU reference
// (cpu_reference/nfor.h) on random and edge inputs, the whole method's stages against the
// reference's, bit-identical reruns, and the properties a first-order regression must have
// (planes and albedo-linear images kept, rank-deficient features, emitters, fireflies).
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "cpu_reference/nfor.h"
#include "cpu_reference/nfor_alpha.h"
#include "cpu_reference/nfor_band.h"
#include "cpu_reference/nfor_coarse.h"
#include "cpu_reference/nfor_kept.h"
#include "cpu_reference/nfor_lights.h"
#include "cpu_reference/nfor_line.h"
#include "cpu_reference/nfor_rare.h"
#include "cpu_reference/nfor_specks.h"
#include "harness/compare.h"
#include "harness/errors.h"
#include "harness/gpu_fixture.h"
#include "harness/inputs.h"
#include "host/api/device.h"
#include "host/api/nfor_reference.h"
#include "host/common/parallel.h"
#include "host/kernels/nfor_kernels.h"
#include "host/methods/nfor.h"
#include "host/methods/nfor_alpha.h"
#include "host/methods/nfor_band.h"
#include "host/methods/nfor_coarse.h"
#include "host/methods/nfor_kept.h"
#include "host/methods/nfor_lights.h"
#include "host/methods/nfor_line.h"
#include "host/methods/nfor_rare.h"
#include "host/methods/nfor_specks.h"
#include "host/metrics.h"
#include "mcdenoise/mcdenoise.h"
#include "nfor/clamp.h"
#include "nfor/distance.h"
#include "nfor/nfor.h"
#include "tools/render/renderer.h"

namespace mcd::test {
namespace {

constexpr double kU = 0x1p-24;  // float unit roundoff

// A kernel case: a frame size and the kind of values.
struct KernelCase {
    int w, h;
    InputKind kind;
};

std::string KernelCaseName(const testing::TestParamInfo<KernelCase> &info) {
    return fmt::format("{}x{}_{}", info.param.w, info.param.h, InputKindName(info.param.kind));
}

std::vector<KernelCase> KernelCases() {
    std::vector<KernelCase> cases;
    for (auto [w, h] : {std::pair{23, 17}, std::pair{1, 1}, std::pair{1, 9}, std::pair{11, 1}})
        for (InputKind kind : {InputKind::Uniform, InputKind::LogNormalFireflies,
                               InputKind::Constant, InputKind::Impulse})
            cases.push_back({w, h, kind});
    return cases;
}

// Non-negative values of the kind (colours, variances).
Image Positive(InputKind kind, int w, int h, int channels, const std::string &name) {
    return MakeVarianceInput(kind, w, h, channels, SeedFromName(name));
}

// An albedo in [0, 1] with a few values under the noise floor and, where `emitters`, a few
// emitters (albedo 3).
Image Albedo(int w, int h, const std::string &name, bool emitters, int channels = 3) {
    std::mt19937_64 rng(SeedFromName(name));
    std::uniform_real_distribution<float> unit(0.f, 1.f);
    Image albedo(w, h, channels);
    for (float &v : albedo.data) v = unit(rng) < 0.1f ? 0.01f : unit(rng);
    if (emitters)
        for (size_t i = 0; i < albedo.PixelCount(); i += 13)
            for (int c = 0; c < channels; ++c) albedo.Plane(c)[i] = 3.f;
    return albedo;
}

// The colour distance's inputs: a colour of `kind`, a variance with every fifth value 0 (the
// normaliser's floor) and an albedo without emitters.
std::tuple<Image, Image, Image> DistanceInputs(const std::string &name, InputKind kind, int w,
                                               int h) {
    Image color = Positive(kind, w, h, 3, name);
    Image variance = Positive(InputKind::Uniform, w, h, 3, name + "variance");
    for (size_t i = 0; i < variance.Size(); ++i) variance.data[i] *= i % 5 == 0 ? 0.f : 0.1f;
    return {std::move(color), std::move(variance), Albedo(w, h, name + "albedo", false)};
}

vk::GpuImage Upload(vk::Context &ctx, const Image &image, const char *name) {
    vk::GpuImage gpu(ctx, image.width, image.height, image.channels, name);
    gpu.Upload(image);
    return gpu;
}

// The largest value of f over the (2r+1)^2 window of (x, y), every channel of c.
double WindowMax(const Image &image, int c, int x, int y, int r,
                 const std::function<double(int, int, int)> &f) {
    double most = 0;
    for (int v = std::max(0, y - r); v <= std::min(image.height - 1, y + r); ++v)
        for (int u = std::max(0, x - r); u <= std::min(image.width - 1, x + r); ++u)
            most = std::max(most, f(c, u, v));
    return most;
}

// The noise kernel on `image` (3 channels) against the reference, divided by `albedo` or
// not, and a second run bit for bit.
//
// Tolerance: each half squared difference of z = value / divisor carries about
// 2u (|z0| + |z1|)^2 of rounding (two divisions, a subtraction, a square), the median selects
// one of them (a tie swapped by rounding picks a value as close), and 4 more roundings scale
// it: 16u of (2 max |z|)^2 x divisor^2 x calibration / median(chi^2_1) over the window.
// The sparse mean of up to 25 half squares, each at most 2 max |z|^2, sums their roundings:
// under 25u x 2 max |z|^2, inside the same bound.
void ExpectNoiseMatches(vk::Context &ctx, const Image &image, const Image &albedo, int radius,
                        bool divided, bool relaxed, bool sparse = false) {
    const int w = image.width, h = image.height;
    const float calibration = 1.479f;
    const Image *divisor = divided ? &albedo : nullptr;
    Image expected = ref::NforNoise(image, divisor, radius, calibration, relaxed, sparse);
    auto run = [&] {
        vk::GpuImage in = Upload(ctx, image, "image"), a = Upload(ctx, albedo, "albedo");
        vk::GpuImage out(ctx, w, h, 3, "variance");
        vk::Recorder recorder(ctx);
        RecordNforNoise(ctx, recorder, in, divided ? &a : nullptr, radius, calibration, out,
                        relaxed, sparse);
        recorder.Submit();
        return out.Download();
    };
    Image actual = run();
    auto divisorAt = [&](int c, int x, int y) {
        double a = divided ? albedo.At(c, y, x) : 1.0;
        return a > NFOR_NOISE_ALBEDO_FLOOR ? a : 1.0;
    };
    Image magnitude(w, h, 3);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                double z = WindowMax(image, c, x, y, radius + 1, [&](int c, int u, int v) {
                    return std::fabs(image.At(c, v, u)) / divisorAt(c, u, v);
                });
                double a = divisorAt(c, x, y);
                magnitude.At(c, y, x) =
                    float(4 * z * z * a * a * calibration / NFOR_CHI2_MEDIAN);
            }
    EXPECT_TRUE(ImagesMatch(expected, actual, magnitude, {16 * kU, 0, 1e-10}))
        << "radius " << radius << " divided " << divided << " relaxed " << relaxed << " sparse "
        << sparse;
    EXPECT_TRUE(BitIdentical(actual, run()));
}

class NforNoiseKernel : public GpuTestWithParam<KernelCase> {};

TEST_P(NforNoiseKernel, MatchesReferenceAndRepeats) {
    const auto [w, h, kind] = GetParam();
    std::string name = fmt::format("noise{}x{}{}", w, h, InputKindName(kind));
    Image image = Positive(kind, w, h, 3, name);
    Image albedo = Albedo(w, h, name + "albedo", false);
    // Radius 1 (the default: the kernel's unrolled path) and 2. Relaxed: most pixels of the
    // random albedo have too few neighbours divided alike.
    for (int radius : {1, 2})
        for (auto [divided, relaxed] : {std::pair{false, false}, {true, false}, {true, true}})
            for (bool sparse : {false, true})
                ExpectNoiseMatches(Ctx(), image, albedo, radius, divided, relaxed, sparse);
}

INSTANTIATE_TEST_SUITE_P(Cases, NforNoiseKernel, testing::ValuesIn(KernelCases()),
                         KernelCaseName);

// Radius 1 takes each direction's median by a sorting network over its 9 pairs (those that
// do not count as +inf): a frame of many pixels, its albedo in patches (most pairs alike
// inside, fewer across their borders) with a random tenth unlike (few alike), so that many
// counts of pairs and orders of the values reach it.
TEST_F(GpuTest, NforNoiseRadiusOneOverManyCountsOfPairs) {
    const int w = 61, h = 47;
    Image image = Positive(InputKind::LogNormalFireflies, w, h, 3, "noiseCounts");
    Image albedo(w, h, 3);
    std::mt19937_64 rng(SeedFromName("noiseCountsAlbedo"));
    std::uniform_real_distribution<float> unit(0.f, 1.f);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                albedo.At(c, y, x) =
                    unit(rng) < 0.1f ? unit(rng) : 0.2f + 0.1f * ((x / 5 + y / 3) % 4);
    for (auto [divided, relaxed] : {std::pair{false, false}, {true, false}, {true, true}})
        ExpectNoiseMatches(Ctx(), image, albedo, 1, divided, relaxed);
    // A frame of few samples: a random 30% of the values hold a sample, the rest are 0, so
    // that many directions' medians are 0 and the sparse mean decides.
    Image few = image;
    for (float &v : few.data)
        if (unit(rng) >= 0.3f) v = 0.f;
    for (int radius : {1, 2})
        for (auto [divided, relaxed] : {std::pair{false, false}, {true, false}, {true, true}})
            ExpectNoiseMatches(Ctx(), few, albedo, radius, divided, relaxed, true);
}

// One lit pixel (value v) on a black 5x5 frame: every direction's median at its centre is
// 0; with sparse each direction's 9 pairs over the 3x3 window hold it twice, so the mean
// is 2 (v^2 / 2) / 9 = v^2 / 9, times the calibration; without, 0. A pixel two above it
// meets it in one vertical pair only: its horizontal pairs are all 0, the smallest
// direction's mean 0 both ways.
TEST_F(GpuTest, NforNoiseSparseTakesTheMeanWhereTheMedianIsZero) {
    const float v = 3.f, calibration = 1.479f;
    Image image(5, 5, 3, 0.f);
    for (int c = 0; c < 3; ++c) image.At(c, 2, 2) = v;
    for (bool sparse : {false, true}) {
        vk::GpuImage in = Upload(Ctx(), image, "image");
        vk::GpuImage out(Ctx(), 5, 5, 3, "variance");
        vk::Recorder recorder(Ctx());
        RecordNforNoise(Ctx(), recorder, in, nullptr, 1, calibration, out, false, sparse);
        recorder.Submit();
        Image variance = out.Download();
        const double expected = sparse ? double(v) * v / 9 * calibration : 0.0;
        EXPECT_NEAR(variance.At(1, 2, 2), expected, 1e-5 * v * v) << "sparse " << sparse;
        EXPECT_EQ(variance.At(1, 0, 2), 0.f) << "sparse " << sparse;
        EXPECT_NEAR(ref::NforNoise(image, nullptr, 1, calibration, false, sparse).At(1, 2, 2),
                    expected, 1e-12);
    }
}

// Clamp: the mask is exact; a clamped value is (median z + t sqrt(v) / a) x a, about 5
// roundings of |C| + t sqrt(v) + a max |z| of the neighbours. Where the value sits on the
// limit either side's choice gives it to that accuracy. With the channels summed a value
// is C x (sum of the clamped values / sum of C): the clamped values' errors summed over the
// channels (C / sum of C is at most 1 for positive colours) and a few roundings of C.
// `channels` colour channels (1 to 4), the albedo's as many or 1 (`albedoChannels`).
void ExpectClampMatches(vk::Context &context, int w, int h, InputKind kind, int rank,
                        float lightEdge, bool sumChannels = false, float line = 0,
                        float loneLight = 0, float lineFloor = 0, int channels = 3,
                        int albedoChannels = 3) {
    std::string name = fmt::format("clamp{}x{}{}", w, h, InputKindName(kind));
    SCOPED_TRACE(fmt::format(
        "rank {} light edge {} sum {} line {} lone light {} floor {} channels {} albedo {}",
        rank, lightEdge, sumChannels, line, loneLight, lineFloor, channels, albedoChannels));
    Image color = Positive(kind, w, h, channels, name);
    Image variance = Positive(InputKind::Uniform, w, h, channels, name + "variance");
    for (float &v : variance.data) v *= 0.01f;
    Image albedo = Albedo(w, h, name + "albedo", true, albedoChannels);
    // The albedo's channel that divides colour channel c.
    auto albedoOf = [&](int c) { return std::min(c, albedoChannels - 1); };
    // With lone lights kept: the last pixel an emitter too (at the frame's edge), and the
    // emitters' colours their albedo's x 0.9, 1.3 and 1.2 in turn: within the ratio (kept
    // whole) and outside it (clamped as without the rule).
    std::vector<std::pair<size_t, bool>> lights;  // pixel, within the ratio
    if (loneLight > 0) {
        for (int c = 0; c < albedoChannels; ++c) albedo.Plane(c)[albedo.PixelCount() - 1] = 3.f;
        const float ratios[3] = {0.9f, 1.3f, 1.2f};
        for (size_t i = 0; i < albedo.PixelCount(); ++i) {
            if (albedo.Plane(0)[i] != 3.f) continue;
            const float ratio = ratios[lights.size() % 3];
            for (int c = 0; c < channels; ++c)
                color.Plane(c)[i] = albedo.Plane(albedoOf(c))[i] * ratio;
            lights.push_back({i, ratio < float(ref::kNforLoneLightRatio)});
        }
    }
    // With the line's floor: bright emitters (albedo 10) in the middle and at the last pixel
    // (the floor's search window cut by the frame's edges).
    if (lineFloor > 0)
        for (size_t i : {albedo.PixelCount() / 2, albedo.PixelCount() - 1})
            for (int c = 0; c < albedoChannels; ++c) albedo.Plane(c)[i] = 10.f;
    const float threshold = 3, relative = 0.5f, emitterAlbedo = 1.5f;
    Image mask = ref::NforMask(&albedo, w, h, emitterAlbedo);
    Image expected = ref::NforClamp(color, variance, &albedo, mask, threshold, relative, rank,
                                    lightEdge, sumChannels, line, loneLight, lineFloor);
    if (loneLight > 0) {
        // The lights within the ratio kept (some the clamp takes without the rule), the others
        // as without it (some clamped).
        Image unruled = ref::NforClamp(color, variance, &albedo, mask, threshold, relative,
                                       rank, lightEdge, sumChannels, line, 0);
        bool keptByRule = false, clamped = false;
        for (auto [i, within] : lights)
            for (int c = 0; c < channels; ++c) {
                const float in = color.Plane(c)[i], out = expected.Plane(c)[i];
                EXPECT_EQ(out, within ? in : unruled.Plane(c)[i]) << "pixel " << i;
                keptByRule = keptByRule || (within && unruled.Plane(c)[i] != in);
                clamped = clamped || (!within && out != in);
            }
        // Both seen (one channel's few lights in a row need not hold one clamped).
        if (w * h > 1) {
            EXPECT_TRUE(keptByRule);
        }
        if (w * h > 1 && channels > 1) {
            EXPECT_TRUE(clamped);
        }
    }
    auto run = [&](Image *gpuMask) {
        vk::GpuImage c = Upload(context, color, "color"),
                     v = Upload(context, variance, "variance");
        vk::GpuImage a = Upload(context, albedo, "albedo");
        vk::GpuImage out(context, w, h, channels, "out"), m(context, w, h, 1, "mask");
        vk::Recorder recorder(context);
        RecordNforClamp(context, recorder, c, v, &a, threshold, relative, emitterAlbedo, rank,
                        lightEdge, sumChannels, line, loneLight, lineFloor, out, m);
        recorder.Submit();
        *gpuMask = m.Download();
        return out.Download();
    };
    Image gpuMask, again;
    Image actual = run(&gpuMask);
    EXPECT_TRUE(BitIdentical(mask, gpuMask));
    Image magnitude(w, h, channels);
    for (int c = 0; c < channels; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                double a = std::max(double(albedo.At(albedoOf(c), y, x)), 1.0);
                double z = WindowMax(color, c, x, y, 1, [&](int c, int u, int v) {
                    double d = albedo.At(albedoOf(c), v, u);
                    return color.At(c, v, u) / (d > NFOR_NOISE_ALBEDO_FLOOR ? d : 1.0);
                });
                magnitude.At(c, y, x) =
                    float(color.At(c, y, x) + threshold * std::sqrt(variance.At(c, y, x)) +
                          (1 + std::max(relative, lightEdge)) * a * z);
            }
    if (sumChannels)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                double sum = 0;
                for (int c = 0; c < channels; ++c) sum += magnitude.At(c, y, x);
                for (int c = 0; c < channels; ++c) magnitude.At(c, y, x) = float(sum);
            }
    EXPECT_TRUE(ImagesMatch(expected, actual, magnitude, {8 * kU, 0, 1e-10}));
    EXPECT_TRUE(BitIdentical(actual, run(&again)));
}

class NforClampKernel : public GpuTestWithParam<KernelCase> {};

// Against the neighbours' median and against their 2nd largest; a light's edge kept, and
// clamped with a relative term of its own; each channel on its own and the channels summed;
// a line's pixels kept (1, and 0.5: more lines); a line's peaks floored (1.5, with the line
// rule and without); lone lights of albedo 2 or more kept
// (ExpectClampMatches sets the emitters' colours to their albedo's x 0.9, 1.3 and 1.2: kept,
// clamped, kept; in the one-row and one-column frames at both ends).
TEST_P(NforClampKernel, MatchesReferenceAndRepeats) {
    const auto [w, h, kind] = GetParam();
    for (bool sum : {false, true}) {
        for (int rank : {0, 2}) ExpectClampMatches(Ctx(), w, h, kind, rank, -1, sum);
        ExpectClampMatches(Ctx(), w, h, kind, 3, 2, sum);
        for (float line : {1.f, 0.5f}) ExpectClampMatches(Ctx(), w, h, kind, 3, -1, sum, line);
        ExpectClampMatches(Ctx(), w, h, kind, 3, -1, sum, 1, 2);
        for (float line : {1.f, 0.f})
            ExpectClampMatches(Ctx(), w, h, kind, 3, -1, sum, line, 0, 1.5f);
        // 1 and 4 colour channels (the kernel's loops run to 4), the albedo's as many or 1.
        for (auto [channels, albedoChannels] : {std::pair{1, 1}, {4, 4}, {4, 1}}) {
            ExpectClampMatches(Ctx(), w, h, kind, 0, -1, sum, 0, 0, 0, channels,
                               albedoChannels);
            ExpectClampMatches(Ctx(), w, h, kind, 3, -1, sum, 1, 2, 0, channels,
                               albedoChannels);
            ExpectClampMatches(Ctx(), w, h, kind, 3, -1, sum, 1, 0, 1.5f, channels,
                               albedoChannels);
        }
    }
}

// The twin's constants are the kernels': a change to one alone fails here.
TEST(NforConstants, TwinAndKernelsAgree) {
    EXPECT_EQ(ref::kNforLoneLightRatio, double(NFOR_LONE_LIGHT_RATIO));
    EXPECT_EQ(ref::kNforLineFloorReach, NFOR_LINE_FLOOR_REACH);
    EXPECT_EQ(ref::kNforLineFloorLight, double(NFOR_LINE_FLOOR_LIGHT));
    EXPECT_EQ(ref::kNforNoiseDivisorRatio, double(NFOR_NOISE_DIVISOR_RATIO));
}

// A light smaller than a pixel seen directly (an emitter alone among its neighbours, its
// colour its albedo's within the ratio in every channel) is no firefly: kept whole by the
// kernel and the reference, where without the rule both clamp it, inside the frame, at its
// corner and at its right edge. A lone emitter whose colour is off its albedo in one channel
// (a light seen through a tinted gloss), one below the albedo bound and two touching emitters
// (not alone; unlike albedos, so each is the other's light edge, clamped with lightEdge
// 0.5) are clamped as before.
TEST_F(GpuTest, NforClampKeepsALoneLightSeenDirectly) {
    const int w = 12, h = 9;
    Image color(w, h, 3), variance(w, h, 3), albedo(w, h, 3);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                albedo.At(c, y, x) = 0.4f;
                color.At(c, y, x) = 0.1f + 0.01f * float((x * 7 + y * 3 + c) % 5);
                variance.At(c, y, x) = 1e-4f;
            }
    auto light = [&](int x, int y, float a, float ratio, float blueRatio) {
        for (int c = 0; c < 3; ++c) {
            albedo.At(c, y, x) = a * (1 - 0.2f * float(c));
            color.At(c, y, x) = albedo.At(c, y, x) * (c == 2 ? blueRatio : ratio);
        }
    };
    light(2, 2, 60, 1.05f, 1.05f);   // kept
    light(0, 0, 30, 0.9f, 0.9f);     // kept at the corner
    light(w - 1, 4, 20, 1.2f, 1.f);  // kept at the right edge
    light(6, 2, 40, 1.05f, 3.f);     // tinted: clamped
    light(2, 6, 4, 1.f, 1.f);        // weak: clamped
    light(7, 6, 60, 1.f, 1.f);       // touching: clamped
    light(8, 6, 20, 1.f, 1.f);
    const float threshold = 4, relative = 0.5f, emitterAlbedo = 1.5f, lightEdge = 0.5f,
                loneLight = 8;
    Image mask = ref::NforMask(&albedo, w, h, emitterAlbedo);
    auto gpu = [&](float lone) {
        vk::GpuImage c = Upload(Ctx(), color, "color"), v = Upload(Ctx(), variance, "variance");
        vk::GpuImage a = Upload(Ctx(), albedo, "albedo");
        vk::GpuImage out(Ctx(), w, h, 3, "out"), m(Ctx(), w, h, 1, "mask");
        vk::Recorder recorder(Ctx());
        RecordNforClamp(Ctx(), recorder, c, v, &a, threshold, relative, emitterAlbedo, 3,
                        lightEdge, true, 1, lone, 0, out, m);
        recorder.Submit();
        return out.Download();
    };
    for (float lone : {loneLight, 0.f}) {
        SCOPED_TRACE(fmt::format("lone light {}", lone));
        Image expected = ref::NforClamp(color, variance, &albedo, mask, threshold, relative, 3,
                                        lightEdge, true, 1, lone);
        Image actual = gpu(lone);
        EXPECT_TRUE(BitIdentical(actual, gpu(lone)));
        for (int c = 0; c < 3; ++c) {
            for (auto [x, y] : {std::pair{2, 2}, {0, 0}, {w - 1, 4}}) {
                const float kept = color.At(c, y, x);
                EXPECT_EQ(expected.At(c, y, x) == kept, lone > 0) << x << "," << y << " " << c;
                EXPECT_EQ(actual.At(c, y, x) == kept, lone > 0) << x << "," << y << " " << c;
            }
            for (auto [x, y] : {std::pair{6, 2}, {2, 6}, {7, 6}, {8, 6}}) {
                EXPECT_LT(expected.At(c, y, x), 0.5f * color.At(c, y, x)) << x << "," << y;
                EXPECT_NEAR(actual.At(c, y, x), expected.At(c, y, x), 1e-5f * color.At(c, y, x))
                    << x << "," << y;
            }
        }
        EXPECT_TRUE(ImagesMatch(expected, actual, color, {8 * kU, 0, 1e-10}));
    }
}

INSTANTIATE_TEST_SUITE_P(Cases, NforClampKernel, testing::ValuesIn(KernelCases()),
                         KernelCaseName);

// Two albedos at the ratio's bound as float rounds it (quantized albedos, e.g. a partly
// covered pixel's, meet it exactly): a neighbour's albedo b = float(a x ratio), rounded up,
// is alike to a in float and not in exact arithmetic. The neighbour's z decides the centre's
// median, so the kernel and the reference must draw the same line: both clamp the centre.
TEST_F(GpuTest, NforClampDividesAlikeAtTheRatioAsTheKernel) {
    const float ratio = float(NFOR_NOISE_DIVISOR_RATIO);
    float a = 0.1f;
    while (!(double(a * ratio) > double(a) * double(ratio))) a = std::nextafter(a, 1.f);
    const float b = a * ratio;
    ASSERT_GT(double(b), double(a) * double(ratio));
    const int w = 3, h = 3;
    Image color(w, h, 3), variance(w, h, 3), albedo(w, h, 3);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                // Unlike the centre (not an emitter): excluded from its median.
                float d = 0.5f, z = 2;
                if (x == 1 && y == 1) d = a, z = 10;
                if (x == 0 && y == 1) d = b, z = 1;
                if (x == 2 && y == 1) d = a, z = 20;
                albedo.At(c, y, x) = d;
                color.At(c, y, x) = z * d;
                variance.At(c, y, x) = 1e-6f;
            }
    const float threshold = 3, relative = 0.5f, emitterAlbedo = 1.5f;
    Image mask = ref::NforMask(&albedo, w, h, emitterAlbedo);
    Image expected =
        ref::NforClamp(color, variance, &albedo, mask, threshold, relative, 0, -1, false, 0);
    vk::GpuImage c = Upload(Ctx(), color, "color"), v = Upload(Ctx(), variance, "variance");
    vk::GpuImage d = Upload(Ctx(), albedo, "albedo");
    vk::GpuImage out(Ctx(), w, h, 3, "out"), m(Ctx(), w, h, 1, "mask");
    vk::Recorder recorder(Ctx());
    RecordNforClamp(Ctx(), recorder, c, v, &d, threshold, relative, emitterAlbedo, 0, -1, false,
                    0, 0, 0, out, m);
    recorder.Submit();
    Image actual = out.Download();
    for (int ch = 0; ch < 3; ++ch) {
        // The median of z 1 and 20 is 1: the centre's z 10 is clamped to about 1.5.
        EXPECT_LT(expected.At(ch, 1, 1), 2 * a) << "channel " << ch;
        EXPECT_NEAR(actual.At(ch, 1, 1), expected.At(ch, 1, 1), 1e-5 * expected.At(ch, 1, 1));
    }
}

// A highlight whose channels cross their limits unevenly (red and green far above their
// neighbours, blue not): clamped each on its own it turns blue; summed, it takes t = 1 -
// (the second smallest share a channel keeps) of itself scaled by one factor, the sum of
// its values clamped one by one over the sum of its values, so blue goes down with red and
// green. One channel alone above its limit (a sample of one colour) is clamped alone, and
// a pixel below its limits keeps its bits either way.
TEST(NforClampChannels, SummedKeepsTheHue) {
    const int w = 9, h = 9;
    Image color(w, h, 3, 0.5f), variance(w, h, 3, 1e-4f), albedo(w, h, 3, 0.5f);
    color.At(0, 4, 4) = color.At(1, 4, 4) = 50;
    color.At(1, 2, 6) = 50;
    Image mask = ref::NforMask(&albedo, w, h, 1.5);
    Image each = ref::NforClamp(color, variance, &albedo, mask, 4, 0.5, 3, -1, false);
    Image sum = ref::NforClamp(color, variance, &albedo, mask, 4, 0.5, 3, -1, true);
    // Each: red and green at the limit (0.5 + 4 x 0.01 + 0.5 x 0.5), blue as it was.
    const double limit = 0.79;
    EXPECT_NEAR(each.At(0, 4, 4), limit, 1e-5);
    EXPECT_NEAR(each.At(1, 4, 4), limit, 1e-5);
    EXPECT_EQ(each.At(2, 4, 4), 0.5f);
    double factor = (2 * limit + 0.5) / 100.5, t = 1 - limit / 50;
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(sum.At(c, 4, 4),
                    (1 - t) * each.At(c, 4, 4) + t * color.At(c, 4, 4) * factor, 1e-5)
            << c;
    EXPECT_EQ(sum.At(0, 4, 4), sum.At(1, 4, 4));
    EXPECT_LT(sum.At(2, 4, 4), 0.05f);
    EXPECT_GT(sum.At(0, 4, 4), 1.f);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c) {
                if (x == 4 && y == 4) continue;
                EXPECT_EQ(sum.At(c, y, x), each.At(c, y, x));
            }
    EXPECT_NEAR(sum.At(1, 2, 6), limit, 1e-5);
    EXPECT_EQ(sum.At(0, 2, 6), 0.5f);
}

// A highlight's streak one pixel wide along row 4 whose pixels the samples hit unevenly
// (8 and 4 in turn, on 0.1), and a lone firefly at (1, 1). Against the 3rd largest
// neighbour every pixel of the streak is clamped; with the line rule a pixel with a
// brighter one on both sides along the row (the 4s, and the 8s at 0.5) keeps its values
// whole, the streak's brightest pixels and the firefly are clamped as before, and so is a
// firefly beside a negative channel.
TEST(NforClampLine, KeepsAStreakNotAFirefly) {
    const int w = 11, h = 9;
    Image color(w, h, 3, 0.1f), variance(w, h, 3, 1e-4f), albedo(w, h, 3, 0.5f);
    for (int x = 0; x < w; ++x)
        for (int c = 0; c < 3; ++c) color.At(c, 4, x) = x % 2 == 0 ? 8.f : 4.f;
    for (int c = 0; c < 3; ++c) color.At(c, 1, 1) = 8;
    // A firefly beside a negative channel (ringing): its positive parts make it bright.
    color.At(0, 7, 8) = 20, color.At(1, 7, 8) = -25;
    Image mask = ref::NforMask(&albedo, w, h, 1.5);
    auto clamp = [&](double line) {
        return ref::NforClamp(color, variance, &albedo, mask, 4, 0.5, 3, -1, true, line);
    };
    Image off = clamp(0), on = clamp(1), wide = clamp(0.5);
    for (int x = 1; x < w - 1; ++x)
        for (int c = 0; c < 3; ++c) {
            EXPECT_LT(off.At(c, 4, x), 1.f) << x;
            EXPECT_EQ(on.At(c, 4, x), x % 2 == 0 ? off.At(c, 4, x) : 4.f) << x;
            EXPECT_EQ(wide.At(c, 4, x), color.At(c, 4, x)) << x;
        }
    for (const Image *image : {&off, &on, &wide}) {
        for (int c = 0; c < 3; ++c) EXPECT_LT(image->At(c, 1, 1), 1.f);
        EXPECT_LT(image->At(0, 7, 8), 1.f);
    }
}

// The clamp kernel with the line floor tests' settings (threshold 4, relative 0.5, emitters
// over 1.5, rank 3, lines 1, floor 1.5) gives the reference's `expected`.
void ExpectLineFloorKernelGives(const Image &color, const Image &variance, const Image &albedo,
                                const Image &expected) {
    vk::Context &ctx = TestContext();
    vk::GpuImage c = Upload(ctx, color, "color"), v = Upload(ctx, variance, "variance");
    vk::GpuImage a = Upload(ctx, albedo, "albedo");
    vk::GpuImage out(ctx, color.width, color.height, 3, "out");
    vk::GpuImage m(ctx, color.width, color.height, 1, "mask");
    vk::Recorder recorder(ctx);
    RecordNforClamp(ctx, recorder, c, v, &a, 4, 0.5f, 1.5f, 3, -1, true, 1, 0, 1.5f, out, m);
    recorder.Submit();
    Image actual = out.Download();
    for (size_t i = 0; i < expected.data.size(); ++i)
        EXPECT_NEAR(actual.data[i], expected.data[i], 1e-5f * (1 + std::fabs(expected.data[i])))
            << i;
}

// Two streaks whose every third pixel is a peak (8, 4, 4 in turn along rows 4 and 13, on
// 0.1, the channels x 1, 0.75, 0.5), as the samples hit glossy lights' ring, and an emitter
// (a light's reflection) at (5, 0), 4 rows above the first: the line rule keeps the 4s and
// clamps the 8s, whose dimmer side's brightest within 2 steps is a 4; the floor 1.5 keeps
// 1.5 x 4 of the first streak's 8s (0.75 of each channel: hue kept) and leaves the second,
// 13 rows from the emitter, as without it. A lone firefly within reach of the emitter and
// one beside a negative channel, whose lines are their ground's, stay below 1. The kernel
// gives the reference's values.
TEST_F(GpuTest, NforClampLineFloorKeepsAStreaksPeaksNearALightNotAFirefly) {
    const int w = 11, h = 17;
    Image color(w, h, 3, 0.1f), variance(w, h, 3, 1e-4f), albedo(w, h, 3, 0.5f);
    for (int y : {4, 13})
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c)
                color.At(c, y, x) = (x % 3 == 0 ? 8.f : 4.f) * (1 - 0.25f * float(c));
    for (int c = 0; c < 3; ++c) albedo.At(c, 0, 5) = 10;
    for (int c = 0; c < 3; ++c) color.At(c, 1, 1) = 8;
    color.At(0, 1, 9) = 20, color.At(1, 1, 9) = -25;
    Image mask = ref::NforMask(&albedo, w, h, 1.5);
    auto clamp = [&](double floor) {
        return ref::NforClamp(color, variance, &albedo, mask, 4, 0.5, 3, -1, true, 1, 0, floor);
    };
    Image off = clamp(0), on = clamp(1.5);
    for (int y : {4, 13})
        for (int x = 1; x < w - 1; ++x)
            for (int c = 0; c < 3; ++c) {
                const float value = color.At(c, y, x);
                if (x % 3 != 0) {
                    EXPECT_EQ(off.At(c, y, x), value) << x << "," << y;
                    EXPECT_EQ(on.At(c, y, x), value) << x << "," << y;
                    continue;
                }
                EXPECT_LT(off.At(c, y, x), 0.25f * value) << x << "," << y;
                if (y == 4)
                    EXPECT_FLOAT_EQ(on.At(c, y, x), 0.75f * value) << x;
                else
                    EXPECT_EQ(on.At(c, y, x), off.At(c, y, x)) << x;
            }
    for (const Image *image : {&off, &on}) {
        for (int c = 0; c < 3; ++c) EXPECT_LT(image->At(c, 1, 1), 1.f);
        EXPECT_LT(image->At(0, 1, 9), 1.f);
    }
    ExpectLineFloorKernelGives(color, variance, albedo, on);
}

// The floor raises a value only where the clamp lowered it, the channels' blend included:
// beside a bright emitter (albedo 10 at (5, 0)) a pixel (8, 8, 0.1) at (5, 3) between two of
// brightness 4.1 on its row has its red and green clamped, and its blue, under its own
// limit, lowered by the blend to far below the floor 1.5 x 4.1 / 16.1 of it: the floor
// gives it back (a floor read from the channel's own clamp alone would leave it). A ground
// pixel beside the emitter, not lowered, keeps its value. A pixel (0.1, 8, 0.1) at (8, 2) on
// the ground has its green alone clamped (no blend): its red stays above its floor
// 1.5 x 0.3 / 8.2 of it, so the emitters' window is first needed at green, which the floor
// raises (a kernel that skipped the window after red would leave it). The kernel gives the
// reference's.
TEST_F(GpuTest, NforClampLineFloorRaisesWhatTheBlendLowered) {
    const int w = 11, h = 9;
    Image color(w, h, 3, 0.1f), variance(w, h, 3, 1e-4f), albedo(w, h, 3, 0.5f);
    for (int c = 0; c < 3; ++c) albedo.At(c, 0, 5) = 10;
    color.At(0, 3, 5) = 8, color.At(1, 3, 5) = 8;
    for (int x : {4, 6}) color.At(0, 3, x) = 2, color.At(1, 3, x) = 2;
    color.At(1, 2, 8) = 8;
    Image mask = ref::NforMask(&albedo, w, h, 1.5);
    auto clamp = [&](double floor) {
        return ref::NforClamp(color, variance, &albedo, mask, 4, 0.5, 3, -1, true, 1, 0, floor);
    };
    Image off = clamp(0), on = clamp(1.5);
    const float share = 1.5f * 4.1f / 16.1f;
    EXPECT_LT(off.At(2, 3, 5), 0.2f * share * 0.1f);
    EXPECT_FLOAT_EQ(on.At(2, 3, 5), share * 0.1f);
    for (int c = 0; c < 2; ++c) {
        EXPECT_LT(off.At(c, 3, 5), share * 8);
        EXPECT_FLOAT_EQ(on.At(c, 3, 5), share * 8) << c;
    }
    for (int c = 0; c < 3; ++c) EXPECT_EQ(on.At(c, 1, 4), color.At(c, 1, 4)) << c;
    const float greenShare = 1.5f * 0.3f / 8.2f;
    EXPECT_LT(off.At(1, 2, 8), 0.5f * greenShare * 8);
    EXPECT_FLOAT_EQ(on.At(1, 2, 8), greenShare * 8);
    for (int c : {0, 2}) EXPECT_EQ(on.At(c, 2, 8), color.At(c, 2, 8)) << c;
    ExpectLineFloorKernelGives(color, variance, albedo, on);
}

// Weights exp(-e): e's terms T = (d^2 - s) / (s + eps) are each at least -1 and are averaged
// over n patch positions with about (n + 5) u of mean |T| of rounding. Since e >= mean |T|
// - 2 / k^2 (only negative terms make |T| and T differ, by at most 2), a weight's absolute
// error is at most (n + 5) u mean|T| exp(2 / k^2 - mean|T|) + 2u <= ((n + 5) e^(2/k^2 - 1)
// + 2) u. A weighted mean over m values then moves by at most 2 m that error (the centre's
// weight 1 bounds the sum of weights from below) plus m u of rounding, of the window's
// largest |value|.
double WeightError(int patchPositions, double bandwidth) {
    return ((patchPositions + 5) * std::exp(2 / (bandwidth * bandwidth) - 1) + 2) * kU;
}

class NforPrefilterKernel : public GpuTestWithParam<KernelCase> {};

TEST_P(NforPrefilterKernel, MatchesReferenceAndRepeats) {
    const auto [w, h, kind] = GetParam();
    std::string name = fmt::format("prefilter{}x{}{}", w, h, InputKindName(kind));
    Image features = MakeInput(kind, w, h, 4, SeedFromName(name));
    Image variance = Positive(InputKind::Uniform, w, h, 4, name + "variance");
    // A third of the pixels sharp (no noise), the rest a little noisy.
    for (size_t i = 0; i < variance.Size(); ++i) variance.data[i] *= i % 3 == 0 ? 0.f : 0.05f;
    const float bandwidth = 1;
    // Radius 1 with 3x3 patches (the default: the kernel's unrolled path), radius 2, and
    // radius 1 with 1x1 and 5x5 patches (the general path: the unrolled one's guard needs
    // both).
    for (auto [radius, patch] : {std::pair{1, 1}, {2, 1}, {1, 0}, {1, 2}}) {
        SCOPED_TRACE(fmt::format("radius {} patch {}", radius, patch));
        Image expected = ref::NforPrefilter(features, variance, radius, patch, bandwidth);
        auto run = [&] {
            vk::GpuImage f = Upload(Ctx(), features, "features");
            vk::GpuImage v = Upload(Ctx(), variance, "variance");
            vk::GpuImage out(Ctx(), w, h, 4, "out");
            vk::Recorder recorder(Ctx());
            RecordNforPrefilter(Ctx(), recorder, f, v, radius, patch, bandwidth, out);
            recorder.Submit();
            return out.Download();
        };
        Image actual = run();
        int m = (2 * radius + 1) * (2 * radius + 1), n = (2 * patch + 1) * (2 * patch + 1);
        double perValue = 2 * m * WeightError(n, bandwidth) + m * kU;
        Image magnitude(w, h, 4);
        for (int c = 0; c < 4; ++c)
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x)
                    magnitude.At(c, y, x) =
                        float(WindowMax(features, c, x, y, radius, [&](int c, int u, int v) {
                            return std::fabs(features.At(c, v, u));
                        }));
        EXPECT_TRUE(ImagesMatch(expected, actual, magnitude, {perValue, 0, 1e-9}));
        EXPECT_TRUE(BitIdentical(actual, run()));
    }
}

INSTANTIATE_TEST_SUITE_P(Cases, NforPrefilterKernel, testing::ValuesIn(KernelCases()),
                         KernelCaseName);

// The illumination kernel's output made on the CPU: per pixel the channels' colour, then
// their variance, each divided by the albedo's channel (min(c, its channels - 1)) and its
// square where that is above the floor, zeros past the channels; then the divisors (1 where
// not divided and past the channels), negated where `trust` is 0.
Image IlluminationOf(const Image &color, const Image &variance, const Image *albedo,
                     const Image *trust = nullptr) {
    Image out(color.width, color.height, kNforIlluminationFloats);
    for (int y = 0; y < color.height; ++y)
        for (int x = 0; x < color.width; ++x) {
            float *values = out.data.data() + (size_t(y) * color.width + x) * 12;
            const float sign = albedo && trust && trust->At(0, y, x) == 0 ? -1.f : 1.f;
            for (int c = 0; c < 4; ++c) values[8 + c] = sign;
            for (int c = 0; c < color.channels; ++c) {
                float value = color.At(c, y, x), noise = variance.At(c, y, x);
                float a = albedo ? albedo->At(std::min(c, albedo->channels - 1), y, x) : 0.f;
                if (albedo && a > float(NFOR_NOISE_ALBEDO_FLOOR)) {
                    value /= a;
                    noise /= a * a;
                    values[8 + c] = sign * a;
                }
                values[c] = value;
                values[4 + c] = noise;
            }
        }
    return out;
}

// A trust plane (nfor/trust.h) of about 40% zeros: pairs with such an end compare colours.
Image RandomTrust(int w, int h, const std::string &name) {
    std::mt19937_64 rng(SeedFromName(name));
    std::uniform_real_distribution<float> unit(0.f, 1.f);
    Image trust(w, h, 1);
    for (float &t : trust.data) t = unit(rng) < 0.4f ? 0.f : 1.f;
    return trust;
}

// Illumination: at most one division per value after a correctly rounded square. Vulkan lets
// a device divide to 2.5 ULP, at most 5 unit roundoffs of the quotient (lavapipe rounds it
// correctly, NVIDIA's H200 does not), so each value is within that of the reference; the
// divisors and signs are copied, exact. With 1, 3 and 4 colour channels, an albedo of as many
// or 1 channel, or none; with and without a trust plane.
constexpr double kDivisionRoundoffs = 5 * kU;

class NforIlluminationKernel : public GpuTestWithParam<KernelCase> {};

TEST_P(NforIlluminationKernel, MatchesTheDefinitionAndRepeats) {
    const auto [w, h, kind] = GetParam();
    const std::string name = fmt::format("illumination{}x{}{}", w, h, InputKindName(kind));
    for (auto [channels, albedoChannels] : {std::pair{3, 3}, {3, 0}, {4, 1}, {1, 1}, {4, 4}}) {
        SCOPED_TRACE(fmt::format("{} channels, albedo {}", channels, albedoChannels));
        Image color = Positive(kind, w, h, channels, name);
        Image variance = Positive(InputKind::Uniform, w, h, channels, name + "variance");
        Image albedo =
            Positive(InputKind::Uniform, w, h, std::max(albedoChannels, 1), name + "albedo");
        // Some albedos under the floor: those channels are not divided.
        for (size_t i = 0; i < albedo.Size(); i += 3) albedo.data[i] *= 0.01f;
        const Image *divisor = albedoChannels > 0 ? &albedo : nullptr;
        const Image trust = RandomTrust(w, h, name + "trust");
        for (bool trusted : {false, true}) {
            auto run = [&] {
                vk::GpuImage c = Upload(Ctx(), color, "color"),
                             v = Upload(Ctx(), variance, "variance"),
                             a = Upload(Ctx(), albedo, "albedo"), t = Upload(Ctx(), trust, "t");
                vk::GpuImage out(Ctx(), w, h, kNforIlluminationFloats, "illumination");
                vk::Recorder recorder(Ctx());
                RecordNforIllumination(Ctx(), recorder, c, v, divisor ? &a : nullptr, out,
                                       trusted ? &t : nullptr);
                recorder.Submit();
                return out.Download();
            };
            Image actual = run();
            EXPECT_TRUE(ImagesMatch(
                IlluminationOf(color, variance, divisor, trusted ? &trust : nullptr), actual,
                {}, {kDivisionRoundoffs, 0, 1e-12}))
                << "trust " << trusted;
            EXPECT_TRUE(BitIdentical(actual, run()));
        }
    }
}

INSTANTIATE_TEST_SUITE_P(Cases, NforIlluminationKernel, testing::ValuesIn(KernelCases()),
                         KernelCaseName);

// The distance kernels' groups (nfor/distance.h): plane 4g + k of pixel p at float
// (g * w * h + p) * 4 + k, and back.
Image GroupsOfPlanes(const Image &planes) {
    Image groups = planes;
    size_t n = planes.PixelCount();
    for (int j = 0; j < planes.channels; ++j)
        for (size_t i = 0; i < n; ++i)
            groups.data[((j / NFOR_TERM_OFFSETS) * n + i) * NFOR_TERM_OFFSETS +
                        j % NFOR_TERM_OFFSETS] = planes.Plane(j)[i];
    return groups;
}

Image PlanesOfGroups(const Image &groups) {
    Image planes = groups;
    size_t n = groups.PixelCount();
    for (int j = 0; j < groups.channels; ++j)
        for (size_t i = 0; i < n; ++i)
            planes.Plane(j)[i] =
                groups.data[((j / NFOR_TERM_OFFSETS) * n + i) * NFOR_TERM_OFFSETS +
                            j % NFOR_TERM_OFFSETS];
    return planes;
}

// Term (divided: also the normaliser 2 min(v_p, v_q)): with the albedo's divisions, cp and cq
// carry a rounding each, which moves d^2 by at most 2u (|cp| + |cq|)^2; the variances'
// divisions, the sums, the square and the division add about 6 roundings more: 12u of ((|cp| +
// |cq|)^2 + alpha s) / den per channel, computed here in double from the inputs. With a trust
// plane a pair with an end not trusted compares the colours, which term makes back from the
// divided values times the divisors (2 roundings more each, within the bound).
class NforTermKernel : public GpuTestWithParam<KernelCase> {};

TEST_P(NforTermKernel, MatchesReferenceAndRepeats) {
    const auto [w, h, kind] = GetParam();
    auto [color, variance, albedo] =
        DistanceInputs(fmt::format("term{}x{}{}", w, h, InputKindName(kind)), kind, w, h);
    const int radius = 3;
    const float alpha = 1;
    const Image trustPlane = RandomTrust(w, h, fmt::format("termTrust{}x{}", w, h));
    for (int mode : {0, 1, 2}) {
        // 0 colour, 1 colour / albedo, 2 colour / albedo where both ends are trusted.
        const bool divided = mode > 0;
        const Image *trust = mode == 2 ? &trustPlane : nullptr;
        Image expected = ref::NforTerms(color, variance, divided ? &albedo : nullptr, radius,
                                        alpha, divided, trust);
        auto run = [&] {
            vk::GpuImage illumination = Upload(
                Ctx(), IlluminationOf(color, variance, divided ? &albedo : nullptr, trust),
                "illumination");
            vk::GpuImage out(Ctx(), w, h, NforOffsetCount(radius), "terms");
            vk::Recorder recorder(Ctx());
            RecordNforTerm(Ctx(), recorder, illumination, 3, radius, alpha, divided, out);
            recorder.Submit();
            return PlanesOfGroups(out.Download());
        };
        Image actual = run();
        Image magnitude(w, h, expected.channels);
        for (int j = 0; j < expected.channels; ++j) {
            int ox, oy;
            ref::NforOffset(radius, j, &ox, &oy);
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) {
                    int qx = x + ox, qy = y + oy;
                    if (qx < 0 || qy < 0 || qx >= w || qy >= h) continue;
                    const bool pair =
                        divided &&
                        (!trust || (trust->At(0, y, x) != 0 && trust->At(0, qy, qx) != 0));
                    double sum = 0;
                    for (int c = 0; c < 3; ++c) {
                        auto scale = [&](int u, int v) {
                            double a = albedo.At(c, v, u);
                            return pair && a > NFOR_NOISE_ALBEDO_FLOOR ? a : 1.0;
                        };
                        double sp = scale(x, y), sq = scale(qx, qy);
                        double cp = color.At(c, y, x) / sp, cq = color.At(c, qy, qx) / sq;
                        double vp = variance.At(c, y, x) / (sp * sp),
                               vq = variance.At(c, qy, qx) / (sq * sq);
                        double s = divided ? 2 * std::min(vp, vq) : vp + vq;
                        double den = s + NFOR_REL_EPS * (cp * cp + cq * cq) + NFOR_TINY;
                        sum +=
                            ((std::fabs(cp) + std::fabs(cq)) * (std::fabs(cp) + std::fabs(cq)) +
                             alpha * s) /
                            den / 3;
                    }
                    magnitude.At(j, y, x) = float(sum);
                }
        }
        EXPECT_TRUE(ImagesMatch(expected, actual, magnitude, {12 * kU, 0, 1e-9}))
            << "mode " << mode;
        EXPECT_TRUE(BitIdentical(actual, run()));
    }
}

INSTANTIATE_TEST_SUITE_P(Cases, NforTermKernel, testing::ValuesIn(KernelCases()),
                         KernelCaseName);

// A pair with an untrusted end whose albedo's square overflows a float (its divided variance
// is 0): term multiplies back to a variance of 0, never 0 x Inf (NaN, which min may turn into
// the cap). The colours are equal once multiplied back, so every term is finite and <= 0.
TEST_F(GpuTest, NforTermMultipliesAHugeAlbedoBackFinitely) {
    const int w = 5, h = 3, radius = 1;
    Image color(w, h, 3), variance(w, h, 3), albedo(w, h, 3), trust(w, h, 1);
    for (float &v : color.data) v = 0.5f;
    for (float &v : variance.data) v = 0.01f;
    for (float &v : albedo.data) v = 0.5f;
    for (float &v : trust.data) v = 1.f;
    for (int c = 0; c < 3; ++c) albedo.At(c, 1, 2) = 1e20f;
    trust.At(0, 1, 2) = 0.f;
    vk::GpuImage illumination =
        Upload(Ctx(), IlluminationOf(color, variance, &albedo, &trust), "illumination");
    vk::GpuImage out(Ctx(), w, h, NforOffsetCount(radius), "terms");
    vk::Recorder recorder(Ctx());
    RecordNforTerm(Ctx(), recorder, illumination, 3, radius, 1.f, false, out);
    recorder.Submit();
    Image terms = out.Download();
    for (float v : terms.data) ASSERT_TRUE(std::isfinite(v) && v <= 0) << v;
}

// Box: a row pass sums at most 2f + 1 values (2f u of the sum of their |values|); a column
// pass sums as many and divides once ((2f + 2) u of the mean |value|): (2f + 2) u of the
// pass applied to |input|, computed here in double. Both passes read the offsets in groups
// (nfor/distance.h); the row pass writes groups, the column pass planes.
void CheckBoxPass(int w, int h, InputKind kind, bool vertical) {
    std::string name = fmt::format("box{}x{}{}", w, h, InputKindName(kind));
    const int radius = 2;
    Image input = MakeInput(kind, w, h, NforOffsetCount(radius), SeedFromName(name));
    Image absolute = input;
    for (float &v : absolute.data) v = std::fabs(v);
    // Patches of every half-size the kernel's blocks hold (up to NFOR_MAX_PATCH), on sizes
    // that are no multiple of the block.
    for (int patch : {2, 0, 1, 3}) {
        SCOPED_TRACE(fmt::format("patch {}", patch));
        Image expected = ref::NforBoxPass(input, radius, patch, vertical);
        Image magnitude = ref::NforBoxPass(absolute, radius, patch, vertical);
        auto run = [&] {
            vk::GpuImage in = Upload(TestContext(), GroupsOfPlanes(input), "terms");
            vk::GpuImage out(TestContext(), w, h, input.channels, "box");
            vk::Recorder recorder(TestContext());
            RecordNforBox(TestContext(), recorder, in, radius, patch, vertical, out);
            recorder.Submit();
            Image result = out.Download();
            return vertical ? result : PlanesOfGroups(result);
        };
        Image actual = run();
        EXPECT_TRUE(ImagesMatch(expected, actual, magnitude, {(2 * patch + 3) * kU, 0, 1e-10}))
            << (vertical ? "columns" : "rows");
        EXPECT_TRUE(BitIdentical(actual, run()));
    }
}

class NforBoxKernel : public GpuTestWithParam<KernelCase> {};

TEST_P(NforBoxKernel, MatchesReferenceAndRepeats) {
    const auto [w, h, kind] = GetParam();
    CheckBoxPass(w, h, kind, false);
}

INSTANTIATE_TEST_SUITE_P(Cases, NforBoxKernel, testing::ValuesIn(KernelCases()),
                         KernelCaseName);

class NforBoxColumnsKernel : public GpuTestWithParam<KernelCase> {};

TEST_P(NforBoxColumnsKernel, MatchesReferenceAndRepeats) {
    const auto [w, h, kind] = GetParam();
    CheckBoxPass(w, h, kind, true);
}

INSTANTIATE_TEST_SUITE_P(Cases, NforBoxColumnsKernel, testing::ValuesIn(KernelCases()),
                         KernelCaseName);

// Distance: a term is about 6 roundings of (d^2 + alpha s) / (s + eps) per channel, with 3
// more where colour and variance are divided by the albedo; the box sums add at most n
// terms (n u of their sum of |terms|): (n + 10) u of the mean |term|, computed here from
// the inputs.
class NforDistanceKernel : public GpuTestWithParam<KernelCase> {};

TEST_P(NforDistanceKernel, MatchesReferenceAndRepeats) {
    const auto [w, h, kind] = GetParam();
    auto [color, variance, albedo] =
        DistanceInputs(fmt::format("distance{}x{}{}", w, h, InputKindName(kind)), kind, w, h);
    const int radius = 3, patch = 2;
    const float alpha = 1;
    const Image trustPlane = RandomTrust(w, h, fmt::format("distanceTrust{}x{}", w, h));
    for (int mode : {0, 1, 2}) {
        // 0 colour, 1 colour / albedo, 2 colour / albedo where both ends are trusted.
        // Divided: also the normaliser 2 min(v_p, v_q).
        const bool divided = mode > 0;
        const Image *trust = mode == 2 ? &trustPlane : nullptr;
        Image expected = ref::NforDistance(color, variance, divided ? &albedo : nullptr, radius,
                                           patch, alpha, divided, trust);
        auto run = [&] {
            vk::GpuImage c = Upload(Ctx(), color, "color"),
                         v = Upload(Ctx(), variance, "variance");
            vk::GpuImage a = Upload(Ctx(), albedo, "albedo"),
                         t = Upload(Ctx(), trustPlane, "t");
            int offsets = NforOffsetCount(radius);
            vk::GpuImage scratch(Ctx(), w, h, offsets, "scratch"),
                out(Ctx(), w, h, offsets, "D"),
                illumination(Ctx(), w, h, kNforIlluminationFloats, "illumination");
            vk::Recorder recorder(Ctx());
            RecordNforDistance(Ctx(), recorder, c, v, divided ? &a : nullptr, radius, patch,
                               alpha, divided, illumination, scratch, out,
                               trust ? &t : nullptr);
            recorder.Submit();
            return out.Download();
        };
        Image actual = run();
        // The compared values and variances.
        Image z = color, vz = variance;
        for (int c = 0; c < 3; ++c)
            for (size_t i = 0; i < z.PixelCount(); ++i) {
                double a = albedo.Plane(c)[i];
                if (!divided || a <= NFOR_NOISE_ALBEDO_FLOOR) continue;
                z.Plane(c)[i] = float(color.Plane(c)[i] / a);
                vz.Plane(c)[i] = float(variance.Plane(c)[i] / (a * a));
            }
        Image magnitude(w, h, expected.channels);
        for (int j = 0; j < expected.channels; ++j) {
            int ox, oy;
            ref::NforOffset(radius, j, &ox, &oy);
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) {
                    double sum = 0;
                    int count = 0;
                    for (int ty = -patch; ty <= patch; ++ty)
                        for (int tx = -patch; tx <= patch; ++tx) {
                            int ux = x + tx, uy = y + ty;
                            if (ux < 0 || uy < 0 || ux >= w || uy >= h || ux + ox < 0 ||
                                uy + oy < 0 || ux + ox >= w || uy + oy >= h)
                                continue;
                            const bool pair = !trust || (trust->At(0, uy, ux) != 0 &&
                                                         trust->At(0, uy + oy, ux + ox) != 0);
                            const Image &zs = pair ? z : color, &vs = pair ? vz : variance;
                            for (int c = 0; c < 3; ++c) {
                                double cp = zs.At(c, uy, ux), cq = zs.At(c, uy + oy, ux + ox);
                                double vp = vs.At(c, uy, ux), vq = vs.At(c, uy + oy, ux + ox);
                                double s = divided ? 2 * std::min(vp, vq) : vp + vq;
                                double den = s + NFOR_REL_EPS * (cp * cp + cq * cq) + NFOR_TINY;
                                sum += std::min(((cp - cq) * (cp - cq) + alpha * s) / den,
                                                NFOR_TERM_MAX) /
                                       3;
                            }
                            ++count;
                        }
                    magnitude.At(j, y, x) = count ? float(sum / count) : 0.f;
                }
        }
        int n = (2 * patch + 1) * (2 * patch + 1);
        EXPECT_TRUE(ImagesMatch(expected, actual, magnitude, {(n + 10) * kU, 0, 1e-10}))
            << "mode " << mode;
        EXPECT_TRUE(BitIdentical(actual, run()));
    }
}

INSTANTIATE_TEST_SUITE_P(Cases, NforDistanceKernel, testing::ValuesIn(KernelCases()),
                         KernelCaseName);

// The inputs of the fit kernels, made by the reference's earlier stages.
struct FitInputs {
    Image input, color, features, mask, distance;
    std::vector<double> weights;
    ref::NforCandidate candidate;
};

// `features` planes: the albedo's three, a uniform plane, a constant plane (a rank-deficient
// column), then two more uniform planes; the albedo's weighted 3, the others 1.
FitInputs MakeFitInputs(int w, int h, InputKind kind, const std::string &name, int radius,
                        int features = 5, int channels = 3) {
    FitInputs f;
    f.input = Positive(kind, w, h, channels, name);
    Image albedo = Albedo(w, h, name + "albedo", true);
    Image other = MakeInput(InputKind::Uniform, w, h, 3, SeedFromName(name + "normal"));
    f.features = Image(w, h, features);
    const float *extra[4] = {other.Plane(0), nullptr, other.Plane(1), other.Plane(2)};
    for (size_t i = 0; i < f.input.PixelCount(); ++i)
        for (int j = 0; j < features; ++j)
            f.features.Plane(j)[i] = j < 3          ? std::min(albedo.Plane(j)[i], 1.f)
                                     : extra[j - 3] ? extra[j - 3][i]
                                                    : 1.f;
    for (int j = 0; j < features; ++j) f.weights.push_back(j < 3 ? 3 : 1);
    Image variance = ref::NforNoise(f.input, &albedo, 2, 1.479);
    f.mask = ref::NforMask(&albedo, w, h, 1.5);
    f.color = ref::NforClamp(f.input, variance, &albedo, f.mask, 4, 0.5, 0);
    f.distance = ref::NforDistance(f.color, variance, &albedo, radius, 2, 1, true);
    f.candidate = {0.7, &f.weights, 0.1, radius, radius};
    return f;
}

// The fit kernels' shapes (features, channels): 5 x 3 fills the coefficients' vec4s
// exactly; 7 x 3 and 4 x 1 pad them.
constexpr std::pair<int, int> kFitShapes[] = {{5, 3}, {7, 3}, {4, 1}};

NforFitSettings SettingsOf(const FitInputs &f) {
    return {f.candidate.radius, f.candidate.gatherRadius, float(f.candidate.bandwidth),
            float(f.candidate.ridge), std::vector<float>(f.weights.begin(), f.weights.end())};
}

// Pack: a copy, bit for bit against NforPackedOf, with 1, 3 and 4 colour channels and
// features filling part of a vec4, all of it, and three.
class NforPackKernel : public GpuTestWithParam<KernelCase> {};

TEST_P(NforPackKernel, MatchesTheLayoutAndRepeats) {
    const auto [w, h, kind] = GetParam();
    const std::string name = fmt::format("pack{}x{}{}", w, h, InputKindName(kind));
    for (auto [channels, features] : {std::pair{3, 7}, {1, 5}, {4, 10}, {3, 3}}) {
        SCOPED_TRACE(fmt::format("{} channels, {} features", channels, features));
        Image color = MakeInput(kind, w, h, channels, SeedFromName(name));
        Image feature = MakeInput(kind, w, h, features, SeedFromName(name + "features"));
        Image mask(w, h, 1, 1.f);
        for (size_t i = 0; i < mask.Size(); i += 4) mask.data[i] = 0.f;
        auto run = [&] {
            vk::GpuImage c = Upload(Ctx(), color, "color"),
                         fe = Upload(Ctx(), feature, "features"),
                         m = Upload(Ctx(), mask, "mask");
            vk::GpuImage out(Ctx(), w, h, NforPackedFloats(features), "packed");
            vk::Recorder recorder(Ctx());
            RecordNforPack(Ctx(), recorder, c, fe, m, out);
            recorder.Submit();
            return out.Download();
        };
        Image actual = run();
        EXPECT_TRUE(BitIdentical(NforPackedOf(color, feature, mask), actual));
        EXPECT_TRUE(BitIdentical(actual, run()));
    }
}

INSTANTIATE_TEST_SUITE_P(Cases, NforPackKernel, testing::ValuesIn(KernelCases()),
                         KernelCaseName);

// Regress: the sums of A = sum w x x^T (+ ridge) carry each weight's error (WeightError
// with the feature term exact to (n + 3) u) and m u of accumulation relative to
// sum w |x_i x_j|; the solution moves by the condition number times that. The condition
// number is at most trace(A) / min(1, lambda sum w) (the centre's weight 1 and x = e_0 there
// bound the smallest eigenvalue), with sum w in [1, m] and trace(A) at most
// sum over the window of |x|^2 + (columns - 1) lambda m: bounds of the window's features.
class NforRegressKernel : public GpuTestWithParam<KernelCase> {};

// Expect regress's coefficients and influence plane for `candidate` within the bound above of
// the reference's.
void ExpectRegressMatches(const FitInputs &f, const ref::NforCandidate &candidate,
                          const Image &beta, const Image &hat) {
    ref::NforFit expected =
        ref::NforRegress(f.color, f.features, f.mask, f.distance, candidate);
    int w = beta.width, h = beta.height, radius = candidate.radius;
    int features = f.features.channels, channels = f.color.channels;
    int window = (2 * radius + 1) * (2 * radius + 1), columns = features + 3;
    double lambda = candidate.ridge;
    Image betaScale(w, h, beta.channels), hatScale(w, h, 1);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            double trace = (columns - 1) * lambda * window, largest = 0;
            for (int v = y - radius; v <= y + radius; ++v)
                for (int u = x - radius; u <= x + radius; ++u) {
                    if (u < 0 || v < 0 || u >= w || v >= h) continue;
                    double norm = 1 + 2.0;  // the constant and |dx|, |dy| <= 1
                    for (int j = 0; j < features; ++j) {
                        double d = f.features.At(j, v, u) - f.features.At(j, y, x);
                        norm += d * d;
                    }
                    trace += norm;
                    for (int c = 0; c < channels; ++c)
                        largest = std::max(largest, double(std::fabs(f.color.At(c, v, u))));
                }
            double condition = trace / std::min(1.0, lambda);
            double error =
                condition * (WeightError(1, candidate.bandwidth) + (window + 8) * kU);
            double betaNorm = 0;
            for (int i = 0; i < beta.channels; ++i)
                betaNorm = std::max(betaNorm, double(std::fabs(expected.beta.At(i, y, x))));
            for (int i = 0; i < beta.channels; ++i)
                betaScale.At(i, y, x) = float(error * (betaNorm + largest));
            hatScale.At(0, y, x) =
                float(error * std::max(1.0, double(expected.hat.At(0, y, x))));
        }
    EXPECT_TRUE(ImagesMatch(expected.beta, beta, betaScale, {1, 0, 1e-8}));
    EXPECT_TRUE(ImagesMatch(expected.hat, hat, hatScale, {1, 0, 1e-8}));
}

void CheckRegress(int w, int h, InputKind kind, int features, int channels, int radius) {
    SCOPED_TRACE(
        fmt::format("{} features, {} channels, radius {}", features, channels, radius));
    FitInputs f =
        MakeFitInputs(w, h, kind, fmt::format("regress{}x{}{}", w, h, InputKindName(kind)),
                      radius, features, channels);
    auto run = [&](Image *hat) {
        vk::GpuImage packed =
            Upload(TestContext(), NforPackedOf(f.color, f.features, f.mask), "packed");
        vk::GpuImage d = Upload(TestContext(), f.distance, "D");
        vk::GpuImage beta(TestContext(), w, h, NforBetaStride(features, channels), "beta"),
            hats(TestContext(), w, h, 2, "hat");
        vk::Recorder recorder(TestContext());
        RecordNforRegress(TestContext(), recorder, packed, features, channels, d, SettingsOf(f),
                          beta, hats, 1);
        recorder.Submit();
        Image all = hats.Download();
        *hat = Image(w, h, 1);
        std::copy(all.Plane(1), all.Plane(1) + hat->Size(), hat->data.begin());
        return NforBetaPlanes(beta.Download(), features, channels);
    };
    Image hat, hatAgain;
    Image beta = run(&hat);
    ExpectRegressMatches(f, f.candidate, beta, hat);
    EXPECT_TRUE(BitIdentical(beta, run(&hatAgain)));
    EXPECT_TRUE(BitIdentical(hat, hatAgain));
}

// Radii 1, 2 and 3: window rows of 3, 5 and 7 steps, which the kernel takes three at a
// time; a row's last chunk holds 3, 2 and 1 of its steps (the others weigh 0). The bound is
// the arithmetic's, so an order of additions other than main's passes here: that the kernel
// keeps the output's bits was checked by comparing whole outputs (docs/performance.md).
TEST_P(NforRegressKernel, MatchesReferenceAndRepeats) {
    const auto [w, h, kind] = GetParam();
    for (int radius : {1, 2, 3})
        for (auto [features, channels] : kFitShapes)
            CheckRegress(w, h, kind, features, channels, radius);
}

// Regress of two candidates in one pass (their bandwidths differ) writes what each writes in
// a pass of its own: the shared reads and column differences, the sums each its own in the
// same order. Bit for bit on a CPU device (lavapipe); elsewhere each variant may contract
// its own multiply-adds, so each candidate within the reference's bound. A second bandwidth
// whose weights cut more of the window than the first's, and one that cuts less; each
// case's two outputs alone differ, so a pair reading the wrong bandwidth fails (not at 1x1,
// whose window is p alone, weight 1 at any bandwidth: there only the writes are checked).
struct RegressOutput {
    Image beta, hat;  // hat: the influence planes from the first candidate's
};

TEST_P(NforRegressKernel, TwoCandidatesInOnePassAsEachAlone) {
    const auto [w, h, kind] = GetParam();
    for (auto [features, channels] : kFitShapes) {
        SCOPED_TRACE(fmt::format("{} features, {} channels", features, channels));
        std::string name = fmt::format("regresspair{}x{}{}", w, h, InputKindName(kind));
        FitInputs f = MakeFitInputs(w, h, kind, name, 2, features, channels);
        // Distances over the weights' range (the made ones are at most 0, or so large that
        // k = 0.25 and 0.7 fit alike), uniform in [-1, 3): at most 0 the bandwidths weigh
        // alike, past 30 k^2 a weight is cut (k = 0.25 past 1.9, not 0.7 or 2).
        Image spread =
            MakeInput(InputKind::Uniform, w, h, f.distance.channels, SeedFromName(name + "D"));
        for (size_t i = 0; i < spread.Size(); ++i) f.distance.data[i] = 1 + 2 * spread.data[i];
        int stride = NforBetaStride(features, channels);
        for (float secondBandwidth : {0.25f, 2.f}) {
            NforFitSettings first = SettingsOf(f), second = first;
            second.bandwidth = secondBandwidth;
            // `settings` alone, or with `second` (its coefficients into *secondBeta).
            auto run = [&](const NforFitSettings &settings, Image *secondBeta) {
                vk::GpuImage packed =
                    Upload(Ctx(), NforPackedOf(f.color, f.features, f.mask), "packed");
                vk::GpuImage d = Upload(Ctx(), f.distance, "D");
                vk::GpuImage beta(Ctx(), w, h, stride, "beta"),
                    other(Ctx(), w, h, stride, "b2"), hats(Ctx(), w, h, 3, "hat");
                vk::Recorder recorder(Ctx());
                RecordNforRegress(Ctx(), recorder, packed, features, channels, d, settings,
                                  beta, hats, 1, secondBeta ? &second : nullptr,
                                  secondBeta ? &other : nullptr);
                recorder.Submit();
                // The coefficients without the padding (zeros, read by nobody).
                if (secondBeta)
                    *secondBeta = NforBetaPlanes(other.Download(), features, channels);
                Image all = hats.Download();
                RegressOutput out{NforBetaPlanes(beta.Download(), features, channels),
                                  Image(w, h, secondBeta ? 2 : 1)};
                std::copy(all.Plane(1), all.Plane(1) + out.hat.Size(), out.hat.data.begin());
                return out;
            };
            SCOPED_TRACE(fmt::format("second bandwidth {}", secondBandwidth));
            RegressOutput firstAlone = run(first, nullptr), secondAlone = run(second, nullptr);
            if (w * h > 1) {
                EXPECT_FALSE(BitIdentical(firstAlone.beta, secondAlone.beta) &&
                             BitIdentical(firstAlone.hat, secondAlone.hat))
                    << "the bandwidths fit alike: the pair check cannot fail";
            }
            Image secondBeta, again;
            RegressOutput paired = run(first, &secondBeta);
            Image firstHat(w, h, 1), secondHat(w, h, 1);
            std::copy(paired.hat.Plane(0), paired.hat.Plane(0) + firstHat.Size(),
                      firstHat.data.begin());
            std::copy(paired.hat.Plane(1), paired.hat.Plane(1) + secondHat.Size(),
                      secondHat.data.begin());
            if (Ctx().Info().type == VK_PHYSICAL_DEVICE_TYPE_CPU) {
                EXPECT_TRUE(BitIdentical(firstAlone.beta, paired.beta));
                EXPECT_TRUE(BitIdentical(firstAlone.hat, firstHat));
                EXPECT_TRUE(BitIdentical(secondAlone.beta, secondBeta));
                EXPECT_TRUE(BitIdentical(secondAlone.hat, secondHat));
            } else {
                ref::NforCandidate secondCandidate = f.candidate;
                secondCandidate.bandwidth = secondBandwidth;
                ExpectRegressMatches(f, f.candidate, paired.beta, firstHat);
                ExpectRegressMatches(f, secondCandidate, secondBeta, secondHat);
            }
            RegressOutput repeat = run(first, &again);
            EXPECT_TRUE(BitIdentical(paired.beta, repeat.beta));
            EXPECT_TRUE(BitIdentical(paired.hat, repeat.hat));
            EXPECT_TRUE(BitIdentical(secondBeta, again));
        }
    }
}

INSTANTIATE_TEST_SUITE_P(Cases, NforRegressKernel, testing::ValuesIn(KernelCases()),
                         KernelCaseName);

// Regress without a ridge on frames of one row (dy is 0 at every q: A's third row is exactly
// zero) and of one pixel (the window is p alone): every Cholesky meets a zero pivot, in the
// kernel as in the reference, and each fit is the pixel's colour as a constant, no slope,
// influence 1. Bit for bit, one candidate and two (the second failing in the same pass).
TEST_F(GpuTest, NforRegressWithoutRidgeFailsToTheColour) {
    for (auto [w, h] : {std::pair{1, 1}, {11, 1}})
        for (auto [features, channels] : kFitShapes) {
            SCOPED_TRACE(
                fmt::format("{}x{}, {} features, {} channels", w, h, features, channels));
            FitInputs f =
                MakeFitInputs(w, h, InputKind::Uniform, fmt::format("regressridge0{}x{}", w, h),
                              2, features, channels);
            f.candidate.ridge = 0;
            ref::NforFit expected =
                ref::NforRegress(f.color, f.features, f.mask, f.distance, f.candidate);
            // The case reaches the failure path: every influence is the constant's.
            for (float value : expected.hat.data) ASSERT_EQ(value, 1.f);
            NforFitSettings first = SettingsOf(f), second = first;
            second.bandwidth = 0.25f;
            int stride = NforBetaStride(features, channels);
            for (bool pair : {false, true}) {
                SCOPED_TRACE(pair ? "two candidates" : "one candidate");
                vk::GpuImage packed =
                    Upload(Ctx(), NforPackedOf(f.color, f.features, f.mask), "packed");
                vk::GpuImage d = Upload(Ctx(), f.distance, "D");
                vk::GpuImage beta(Ctx(), w, h, stride, "beta"),
                    other(Ctx(), w, h, stride, "b2"), hats(Ctx(), w, h, 3, "hat");
                vk::Recorder recorder(Ctx());
                RecordNforRegress(Ctx(), recorder, packed, features, channels, d, first, beta,
                                  hats, 1, pair ? &second : nullptr, pair ? &other : nullptr);
                recorder.Submit();
                Image all = hats.Download();
                for (int k = 0; k < (pair ? 2 : 1); ++k) {
                    Image hat(w, h, 1);
                    std::copy(all.Plane(1 + k), all.Plane(1 + k) + hat.Size(),
                              hat.data.begin());
                    Image fit =
                        NforBetaPlanes((k ? other : beta).Download(), features, channels);
                    EXPECT_TRUE(BitIdentical(expected.beta, fit)) << "candidate " << k;
                    EXPECT_TRUE(BitIdentical(expected.hat, hat)) << "candidate " << k;
                }
            }
        }
}

// Gather on the reference's coefficients: each prediction sums `columns` products (columns
// u of sum |x_i beta_i|), the weighted mean over m windows adds 2 m weight errors and m u,
// of the window's largest prediction magnitude.
class NforGatherKernel : public GpuTestWithParam<KernelCase> {};

void CheckGather(int w, int h, InputKind kind, int features, int channels) {
    SCOPED_TRACE(fmt::format("{} features, {} channels", features, channels));
    const int radius = 2;
    FitInputs f =
        MakeFitInputs(w, h, kind, fmt::format("gather{}x{}{}", w, h, InputKindName(kind)),
                      radius, features, channels);
    ref::NforFit fit = ref::NforRegress(f.color, f.features, f.mask, f.distance, f.candidate);
    Image expected = ref::NforGather(f.input, f.features, f.mask, f.distance, fit, f.candidate);
    auto run = [&] {
        vk::GpuImage in = Upload(TestContext(), f.input, "input"),
                     d = Upload(TestContext(), f.distance, "D");
        vk::GpuImage packed =
            Upload(TestContext(), NforPackedOf(f.color, f.features, f.mask), "packed");
        vk::GpuImage beta =
            Upload(TestContext(), NforBetaPerPixel(fit.beta, features, channels), "beta");
        vk::GpuImage out(TestContext(), w, h, 2 * channels, "out");
        vk::Recorder recorder(TestContext());
        RecordNforGather(TestContext(), recorder, in, packed, features, d, beta, SettingsOf(f),
                         out, channels);
        recorder.Submit();
        Image all = out.Download();
        Image part(w, h, channels);
        std::copy(all.Plane(channels), all.Plane(channels) + part.Size(), part.data.begin());
        return part;
    };
    Image actual = run();
    int window = (2 * radius + 1) * (2 * radius + 1), columns = features + 3;
    Image magnitude(w, h, channels);
    for (int c = 0; c < channels; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                double most = std::fabs(f.input.At(c, y, x));
                for (int v = y - radius; v <= y + radius; ++v)
                    for (int u = x - radius; u <= x + radius; ++u) {
                        if (u < 0 || v < 0 || u >= w || v >= h) continue;
                        std::vector<double> xs(columns);
                        xs[0] = 1;
                        xs[1] = double(x - u) / radius;
                        xs[2] = double(y - v) / radius;
                        for (int j = 0; j < features; ++j)
                            xs[3 + j] = f.features.At(j, y, x) - f.features.At(j, v, u);
                        double sum = 0;
                        for (int i = 0; i < columns; ++i)
                            sum += std::fabs(xs[i] * fit.beta.At(i * channels + c, v, u));
                        most = std::max(most, sum);
                    }
                magnitude.At(c, y, x) = float(most);
            }
    double perValue =
        2 * window * WeightError(1, f.candidate.bandwidth) + (window + columns) * kU;
    EXPECT_TRUE(ImagesMatch(expected, actual, magnitude, {perValue, 0, 1e-9}));
    EXPECT_TRUE(BitIdentical(actual, run()));
}

TEST_P(NforGatherKernel, MatchesReferenceAndRepeats) {
    const auto [w, h, kind] = GetParam();
    for (auto [features, channels] : kFitShapes) CheckGather(w, h, kind, features, channels);
}

INSTANTIATE_TEST_SUITE_P(Cases, NforGatherKernel, testing::ValuesIn(KernelCases()),
                         KernelCaseName);

// Regress and gather refuse feature weights that do not match the packed features: a pack
// of 5 features has the size of one of 7, so only the count can tell them apart.
class NforFitChecks : public GpuTest {};

TEST_F(NforFitChecks, FeatureCountMismatchThrows) {
    const int w = 5, h = 4, radius = 2;
    FitInputs f = MakeFitInputs(w, h, InputKind::Uniform, "fitchecks", radius);
    NforFitSettings settings = SettingsOf(f);
    settings.featureWeights.resize(7, 1.f);
    ASSERT_EQ(NforPackedFloats(5), NforPackedFloats(7));
    vk::GpuImage packed = Upload(Ctx(), NforPackedOf(f.color, f.features, f.mask), "packed");
    vk::GpuImage d = Upload(Ctx(), f.distance, "D"), in = Upload(Ctx(), f.input, "input");
    vk::GpuImage beta(Ctx(), w, h, NforBetaStride(5, 3), "beta"), hat(Ctx(), w, h, 1, "hat"),
        out(Ctx(), w, h, 3, "out");
    vk::Recorder recorder(Ctx());
    EXPECT_THROW(RecordNforRegress(Ctx(), recorder, packed, 5, 3, d, settings, beta, hat, 0),
                 Error);
    EXPECT_THROW(RecordNforGather(Ctx(), recorder, in, packed, 5, d, beta, settings, out, 0),
                 Error);
}

// A second candidate must differ in its bandwidth alone and bring its coefficients.
TEST_F(NforFitChecks, SecondCandidateOfAnotherWindowThrows) {
    const int w = 5, h = 4, radius = 2;
    FitInputs f = MakeFitInputs(w, h, InputKind::Uniform, "fitpair", radius);
    NforFitSettings settings = SettingsOf(f), second = settings;
    second.ridge *= 2;
    vk::GpuImage packed = Upload(Ctx(), NforPackedOf(f.color, f.features, f.mask), "packed");
    vk::GpuImage d = Upload(Ctx(), f.distance, "D");
    vk::GpuImage beta(Ctx(), w, h, NforBetaStride(5, 3), "beta"),
        other(Ctx(), w, h, NforBetaStride(5, 3), "b2"), hat(Ctx(), w, h, 2, "hat");
    vk::Recorder recorder(Ctx());
    EXPECT_THROW(RecordNforRegress(Ctx(), recorder, packed, 5, 3, d, settings, beta, hat, 0,
                                   &second, &other),
                 Error);
    second = settings;
    EXPECT_THROW(RecordNforRegress(Ctx(), recorder, packed, 5, 3, d, settings, beta, hat, 0,
                                   &second, nullptr),
                 Error);
    // Its influence needs a plane after the first's.
    EXPECT_THROW(RecordNforRegress(Ctx(), recorder, packed, 5, 3, d, settings, beta, hat, 1,
                                   &second, &other),
                 Error);
}

// Select on the same candidates: SURE of a pixel is a few roundings of sum |d^2| + v (1 +
// 2 h); its window mean m u more. Where the reference's best and second best means are
// closer than that the choice may go either way; elsewhere it must match, and the output is
// the chosen candidate's value exactly.
void CheckSelect(vk::Context &context, int w, int h, InputKind kind, int radius) {
    std::string name = fmt::format("select{}x{}{}", w, h, InputKindName(kind));
    if (radius != 2) name += fmt::format("r{}", radius);
    Image color = Positive(kind, w, h, 3, name);
    Image variance = Positive(InputKind::Uniform, w, h, 3, name + "variance");
    std::vector<Image> outputs, hats;
    for (int k = 0; k < 3; ++k) {
        Image out = color;
        std::mt19937_64 rng(SeedFromName(name + std::to_string(k)));
        std::normal_distribution<float> normal(0.f, 0.3f * (k + 1));
        for (float &v : out.data) v += normal(rng);
        outputs.push_back(out);
        hats.push_back(Positive(InputKind::Uniform, w, h, 1, name + "hat" + std::to_string(k)));
    }
    Image expectedChoice;
    Image expected = ref::NforSelect(outputs, hats, color, variance, radius, &expectedChoice);
    Image candidates(w, h, 9), hat(w, h, 3);
    for (int k = 0; k < 3; ++k) {
        std::copy(outputs[k].data.begin(), outputs[k].data.end(), candidates.Plane(3 * k));
        std::copy(hats[k].data.begin(), hats[k].data.end(), hat.Plane(k));
    }
    auto run = [&](Image *choice) {
        vk::GpuImage c = Upload(context, color, "color"),
                     v = Upload(context, variance, "variance");
        vk::GpuImage cand = Upload(context, candidates, "candidates"),
                     hh = Upload(context, hat, "hat");
        vk::GpuImage out(context, w, h, 3, "out"), pick(context, w, h, 1, "choice");
        vk::Recorder recorder(context);
        RecordNforSelect(context, recorder, c, v, cand, hh, 3, radius, out, pick);
        recorder.Submit();
        *choice = pick.Download();
        return out.Download();
    };
    Image choice, choiceAgain;
    Image actual = run(&choice);
    int window = (2 * radius + 1) * (2 * radius + 1), ties = 0, mismatches = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            // The reference's window means and their rounding bound.
            std::vector<double> means;
            double bound = 0;
            for (int k = 0; k < 3; ++k) {
                double sum = 0, scale = 0;
                int count = 0;
                for (int v = std::max(0, y - radius); v <= std::min(h - 1, y + radius); ++v)
                    for (int u = std::max(0, x - radius); u <= std::min(w - 1, x + radius);
                         ++u, ++count)
                        for (int c = 0; c < 3; ++c) {
                            double d = double(outputs[k].At(c, v, u)) - color.At(c, v, u);
                            double var = variance.At(c, v, u), hh = hats[k].At(0, v, u);
                            sum += d * d - var + 2 * var * hh;
                            scale += d * d + var * (1 + 2 * hh);
                        }
                means.push_back(sum / count);
                bound = std::max(bound, (window + 12) * kU * scale / count);
            }
            std::vector<double> sorted = means;
            std::sort(sorted.begin(), sorted.end());
            int k = int(choice.At(0, y, x));
            ASSERT_TRUE(k >= 0 && k < 3);
            for (int c = 0; c < 3; ++c) ASSERT_EQ(actual.At(c, y, x), outputs[k].At(c, y, x));
            if (sorted[1] - sorted[0] <= 2 * bound) {
                ++ties;
                EXPECT_LE(means[k] - sorted[0], 2 * bound);
            } else if (k != int(expectedChoice.At(0, y, x)))
                ++mismatches;
        }
    EXPECT_EQ(mismatches, 0);
    EXPECT_LE(ties, w * h / 10 + 1) << "too many near-ties to test the choice";
    EXPECT_TRUE(BitIdentical(actual, run(&choiceAgain)));
    EXPECT_TRUE(BitIdentical(choice, choiceAgain));
}

class NforSelectKernel : public GpuTestWithParam<KernelCase> {};

TEST_P(NforSelectKernel, MatchesReferenceAndRepeats) {
    const auto [w, h, kind] = GetParam();
    CheckSelect(Ctx(), w, h, kind, 2);
}

INSTANTIATE_TEST_SUITE_P(Cases, NforSelectKernel, testing::ValuesIn(KernelCases()),
                         KernelCaseName);

// The kernel shares each pixel's SURE among a workgroup's windows: rows wider than one
// workgroup (64 pixels), ending within one, at the default radius and the largest.
class NforSelectWide : public GpuTest {};

TEST_F(NforSelectWide, MatchesReferenceAcrossWorkgroups) {
    for (int radius : {3, NFOR_SURE_MAX_RADIUS}) {
        SCOPED_TRACE(radius);
        CheckSelect(Ctx(), 150, 13, InputKind::Uniform, radius);
    }
}

// Select by agreement on noisy candidates: a pixel's disagreement d^2 / (m^2 + floor) is a
// few roundings of itself (every term positive), its window mean (window + 12) u more.
// The threshold is the median of candidate 1's window means, so both choices occur; a
// candidate whose mean is within the bound of it may go either way, elsewhere the choice
// must match, and the output is the chosen candidate's value exactly.
class NforAgreementKernel : public GpuTestWithParam<KernelCase> {};

TEST_P(NforAgreementKernel, MatchesReferenceAndRepeats) {
    const auto [w, h, kind] = GetParam();
    std::string name = fmt::format("agree{}x{}{}", w, h, InputKindName(kind));
    Image color = Positive(kind, w, h, 3, name);
    std::vector<Image> outputs, hats;
    Image candidates(w, h, 9), hat(w, h, 3);
    for (int k = 0; k < 3; ++k) {
        Image out = color;
        std::mt19937_64 rng(SeedFromName(name + std::to_string(k)));
        std::normal_distribution<float> normal(0.f, 0.1f * (k + 1));
        for (float &v : out.data) v = std::max(0.f, v * (1 + normal(rng)));
        std::copy(out.data.begin(), out.data.end(), candidates.Plane(3 * k));
        outputs.push_back(out);
        hats.push_back(Image(w, h, 1));
    }
    const int radius = 2, window = (2 * radius + 1) * (2 * radius + 1);
    // The reference's window means of each candidate's disagreement with candidate 0.
    std::vector<Image> means(3, Image(w, h, 1));
    for (int k = 1; k < 3; ++k)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                double sum = 0;
                int count = 0;
                for (int v = std::max(0, y - radius); v <= std::min(h - 1, y + radius); ++v)
                    for (int u = std::max(0, x - radius); u <= std::min(w - 1, x + radius);
                         ++u, ++count) {
                        double d = 0, m = 0;
                        for (int c = 0; c < 3; ++c) {
                            double e = double(outputs[k].At(c, v, u)) - outputs[0].At(c, v, u);
                            d += e * e;
                            m += outputs[0].At(c, v, u);
                        }
                        m /= 3;
                        sum += d / 3 / (m * m + ref::kNforAgreementFloor);
                    }
                means[k].At(0, y, x) = float(sum / count);
            }
    // Halfway between the lower median and the next larger mean (none: above all).
    std::vector<float> sorted = means[1].data;
    std::sort(sorted.begin(), sorted.end());
    const float low = sorted[(sorted.size() - 1) / 2];
    auto next = std::upper_bound(sorted.begin(), sorted.end(), low);
    const bool split = next != sorted.end();
    const float agreement = split ? 0.5f * (low + *next) : 2 * low + 1e-6f;
    Image expectedChoice;
    Image expected =
        ref::NforSelect(outputs, hats, color, color, radius, &expectedChoice, agreement);
    auto run = [&](Image *choice) {
        vk::GpuImage c = Upload(Ctx(), color, "color"), v = Upload(Ctx(), color, "variance");
        vk::GpuImage cand = Upload(Ctx(), candidates, "candidates"),
                     hh = Upload(Ctx(), hat, "hat");
        vk::GpuImage out(Ctx(), w, h, 3, "out"), pick(Ctx(), w, h, 1, "choice");
        vk::Recorder recorder(Ctx());
        RecordNforSelect(Ctx(), recorder, c, v, cand, hh, 3, radius, out, pick, agreement);
        recorder.Submit();
        *choice = pick.Download();
        return out.Download();
    };
    Image choice, choiceAgain;
    Image actual = run(&choice);
    int ties = 0, mismatches = 0;
    std::vector<int> taken(3, 0);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            int k = int(choice.At(0, y, x));
            ASSERT_TRUE(k >= 0 && k < 3);
            ++taken[k];
            for (int c = 0; c < 3; ++c) ASSERT_EQ(actual.At(c, y, x), outputs[k].At(c, y, x));
            bool tie = false;
            for (int j = 1; j < 3; ++j) {
                double mean = means[j].At(0, y, x);
                tie = tie || std::fabs(mean - agreement) <= (window + 12) * kU * mean;
            }
            if (tie)
                ++ties;
            else if (k != int(expectedChoice.At(0, y, x)))
                ++mismatches;
        }
    EXPECT_EQ(mismatches, 0);
    EXPECT_LE(ties, w * h / 10 + 1) << "too many near-ties to test the choice";
    if (split) {
        EXPECT_GT(taken[0], 0) << "the narrow candidate is taken somewhere";
        EXPECT_GT(taken[1] + taken[2], 0) << "a wide candidate is taken somewhere";
    }
    EXPECT_TRUE(BitIdentical(actual, run(&choiceAgain)));
    EXPECT_TRUE(BitIdentical(choice, choiceAgain));
}

INSTANTIATE_TEST_SUITE_P(Cases, NforAgreementKernel, testing::ValuesIn(KernelCases()),
                         KernelCaseName);

// A synthetic plain frame: an albedo texture with an edge, a smooth illumination, normals
// that turn at y = h / 2, a depth ramp, multiplicative noise; and its truth.
struct Frame {
    Image color, albedo, normal, depth, truth;
};

Frame MakeFrame(int w, int h, double noise, const std::string &name) {
    std::mt19937_64 rng(SeedFromName(name));
    std::uniform_real_distribution<double> unit(0, 1);
    std::normal_distribution<double> normal(0, 1);
    Frame f{Image(w, h, 3), Image(w, h, 3), Image(w, h, 3), Image(w, h, 1), Image(w, h, 3)};
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            double light = (0.5 + 0.3 * std::sin(0.2 * x + 0.1 * y)) * (y < h / 2 ? 1.0 : 0.6);
            for (int c = 0; c < 3; ++c) {
                double albedo = (x + y) % 7 < 3 ? 0.2 + 0.1 * c : 0.7 - 0.1 * c;
                f.albedo.At(c, y, x) = float(albedo);
                f.truth.At(c, y, x) = float(albedo * light);
                f.color.At(c, y, x) =
                    float(std::max(0.0, albedo * light * (1 + noise * normal(rng))));
            }
            f.normal.At(0, y, x) = y < h / 2 ? 0.f : 0.8f;
            f.normal.At(1, y, x) = y < h / 2 ? 1.f : 0.6f;
            f.depth.At(0, y, x) = float(2 + 0.01 * x);
        }
    return f;
}

NforInputs InputsOf(const Frame &f) {
    NforInputs in;
    in.color = &f.color;
    in.albedo = &f.albedo;
    in.normal = &f.normal;
    in.depth = &f.depth;
    return in;
}

// The frame over a transparent background: pixels left of a slanted edge covered, right of
// it empty (alpha 0: colour, albedo, normal and depth 0), a band of pixels along it partly
// covered (alpha k / 16, k from 1 to 15, as 16 samples draw it), their colour, features and
// truth premultiplied by alpha. Returns the alpha.
Image Cover(Frame *f, bool whole = false) {
    int w = f->color.width, h = f->color.height;
    Image alpha(w, h, 1);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            // The covered share of the pixel: 1 left of the edge, falling over 3 pixels.
            double edge = 0.5 * w + 0.2 * y, covered = std::clamp((edge - x) / 3, 0.0, 1.0);
            float a = float(std::round(16 * covered) / 16);
            if (whole) a = a >= 0.5f ? 1.f : 0.f;  // covered or empty, none in part
            alpha.At(0, y, x) = a;
            for (Image *layer : {&f->color, &f->albedo, &f->normal, &f->depth, &f->truth})
                for (int c = 0; c < layer->channels; ++c) layer->At(c, y, x) *= a;
        }
    return alpha;
}

// A strong light (3x3, albedo and colour 300 as seen through its coverage) whose right
// column is the last before Cover's edge, and a weak one (3) below it: their neighbours to
// the right are partly covered or empty (alpha 0).
void AddLightsAtTheEdge(Frame *f, const Image *alpha) {
    const int w = f->color.width, h = f->color.height;
    auto put = [&](int x, int y, float value) {
        float a = alpha ? alpha->At(0, y, x) : 1.f;
        for (int c = 0; c < 3; ++c) f->albedo.At(c, y, x) = f->color.At(c, y, x) = value * a;
    };
    for (int y = h / 3; y < h / 3 + 3 && y < h; ++y) {
        const int edge = int(0.5 * w + 0.2 * y);
        for (int x = std::max(0, edge - 3); x < edge && x < w; ++x) put(x, y, 300.f);
    }
    const int y = std::min(h - 1, h / 3 + 5), edge = int(0.5 * w + 0.2 * y);
    put(std::clamp(edge - 1, 0, w - 1), y, 3.f);
}

class NforMethod : public GpuTest {};

// A pilot from outside: the frame's truth with a seeded 5% noise of its own, scaled alike
// where the truth is (premultiplied by Cover's alpha, 0 where a pixel is empty).
Image PilotNearTruth(const Frame &f) {
    std::mt19937_64 rng(SeedFromName("givenPilot"));
    std::normal_distribution<double> normal(0, 1);
    Image pilot = f.truth;
    for (float &v : pilot.data) v = float(v * (1 + 0.05 * normal(rng)));
    return pilot;
}

// A variance layer for MakeFrame's frame: the truth's noise with every seventh value's 100x
// (a firefly among its samples) and every eleventh's 0 (samples that agreed).
Image LayerWithFireflies(const Frame &f) {
    Image variance(f.truth.width, f.truth.height, 3);
    for (size_t i = 0; i < variance.Size(); ++i) {
        double sigma = 0.3 * f.truth.data[i];
        variance.data[i] = float(sigma * sigma * (i % 7 == 3 ? 100 : i % 11 == 5 ? 0 : 1));
    }
    return variance;
}

// The whole method's stages against the reference's, by name: the stages before the
// choices agree to their kernels' round-off; the fits and outputs may differ where a clamp
// or a choice sat on its threshold, which the NMSE bounds allow for a few pixels. With one
// pass and with a second pass over the pilot (two bandwidths each, and one).
// With withVariance the frame carries a variance layer: the truth's noise with every
// seventh pixel's 100x (a firefly among its samples) and every eleventh's 0 (samples that
// agreed).
void ExpectStagesMatch(vk::Context &context, int w, int h, const NforOptions &options,
                       bool withVariance = false, bool covered = false, bool lights = false,
                       bool whole = false,
                       const std::function<void(Frame *, Image *)> &edit = {},
                       std::vector<std::string> *stageNames = nullptr,
                       bool givenPilot = false) {
    Frame f = MakeFrame(w, h, 0.3, fmt::format("stages{}x{}", w, h));
    Image alpha = covered ? Cover(&f, whole) : Image();
    if (lights) AddLightsAtTheEdge(&f, covered ? &alpha : nullptr);
    if (edit) edit(&f, &alpha);
    Image variance = LayerWithFireflies(f);
    Image pilot = givenPilot ? PilotNearTruth(f) : Image();
    NforInputs gpuIn = InputsOf(f);
    if (withVariance) gpuIn.variance = &variance;
    if (covered) gpuIn.alpha = &alpha;
    if (givenPilot) gpuIn.pilot = &pilot;
    NforOptions o = options;
    o.keepStages = true;
    NforResult gpu = NforDenoise(context, gpuIn, o);
    if (stageNames)
        for (const auto &stage : gpu.stages) stageNames->push_back(stage.first);
    std::vector<float> weights;
    std::vector<std::string> names;
    Image features = NforFeatures(InputsOf(f), o, &weights, &names);
    const ref::NforParams p = api::NforReferenceParams(o, weights);
    ref::NforInputs cpuIn{&f.color,
                          &f.albedo,
                          &features,
                          withVariance ? &variance : nullptr,
                          covered ? &alpha : nullptr,
                          givenPilot ? &pilot : nullptr};
    std::vector<std::pair<std::string, Image>> cpu;
    Image expected = ref::Nfor(cpuIn, p, &cpu);
    ASSERT_EQ(gpu.stages.size(), cpu.size());
    for (size_t i = 0; i < cpu.size(); ++i) {
        ASSERT_EQ(gpu.stages[i].first, cpu[i].first);
        ElementDifference d = MeasureDifference(gpu.stages[i].second, cpu[i].second);
        EXPECT_EQ(d.parity, 0u) << cpu[i].first;
        const std::string &name = cpu[i].first;
        double limit = name.find("choice") != std::string::npos ? 1e-2
                       : name.find("beta") != std::string::npos ? 1e-6
                                                                : 1e-8;
        EXPECT_LE(d.nmse, limit) << name << " at " << w << "x" << h;
    }
    ElementDifference d = MeasureDifference(gpu.image, expected);
    EXPECT_LE(d.nmse, 1e-8) << w << "x" << h;
}

// Windows small enough for the stage tests' frames: two bandwidths, the features
// prefiltered, no local mean.
NforOptions SmallWindowOptions() {
    NforOptions o;
    o.radius = 3;
    o.gatherRadius = -1;
    o.patchRadius = 3;
    o.bandwidths = {0.5f, 1.f};
    o.noiseRadius = 2;
    o.prefilterRadius = 3;
    o.meanRadius = 0;
    o.noisyRadius = 0;
    return o;
}

// The one-pass path of the papers: two bandwidths by SURE, the features prefiltered.
TEST_F(NforMethod, StagesMatchTheReference) {
    NforOptions o = SmallWindowOptions();
    o.pilotBandwidths = {};
    for (auto [w, h] : {std::pair{29, 23}, std::pair{1, 1}, std::pair{7, 1}})
        ExpectStagesMatch(Ctx(), w, h, o);
}

// --no-edge-noise on a frame without a variance layer: one estimate of the colour's noise
// for the firefly clamp and the weights alike, made before the clamp reads it (with and
// without alpha, and a frame beside a layer, where the option changes nothing). Buffers are
// handed out filled with NaN, so a stage read before anything wrote it cannot pass.
TEST_F(NforMethod, NoEdgeNoiseStagesMatchTheReference) {
    vk::Context poisoned(vk::ContextOptions{.pipelineThreads = 1, .poisonBuffers = true});
    NforOptions o = SmallWindowOptions();
    o.noEdgeNoise = true;
    for (auto [w, h] : {std::pair{29, 23}, std::pair{1, 1}, std::pair{7, 1}})
        ExpectStagesMatch(poisoned, w, h, o);
    ExpectStagesMatch(poisoned, 29, 23, o, false, true, true);
    ExpectStagesMatch(poisoned, 29, 23, o, true);
}

// Options away from their defaults that reach the twin only through the one mapping: the
// distance's variance cancellation, the ridge, the firefly clamp's threshold and rho, the
// emitters' albedo, the prefilter's bandwidth, SURE's window, and the second pass's alpha
// and wide windows' agreement.
TEST_F(NforMethod, OptionsAwayFromDefaultsMatchTheReference) {
    NforOptions o;
    o.radius = 3;
    o.patchRadius = 2;
    o.noiseRadius = 2;
    o.prefilterRadius = 2;
    o.meanRadius = 0;
    o.alpha = 0.5f;
    o.ridge = 0.01f;
    o.fireflyThreshold = 3;
    o.fireflyRelative = 0.25f;
    o.emitterAlbedo = 2;
    o.prefilterBandwidth = 0.7f;
    o.sureRadius = 2;
    o.pilotAlpha = 0.5f;
    ExpectStagesMatch(Ctx(), 29, 23, o, false, false, true);
    ExpectStagesMatch(Ctx(), 29, 23, o, true);
    o.pilotBandwidths = {1.f};
    o.pilotWideRadius = o.radius + 2;
    o.wideAgreement = 0.5f;
    ExpectStagesMatch(Ctx(), 29, 23, o, true, true, true);
}

// The distance's albedo trust: off (no trust stage), and on over a frame whose left half's
// albedo is noise (random per pixel and channel, which the colour does not follow), where
// the trust stage marks pixels untrusted and the pilot's and the second pass's distances
// take the per-pair rule.
TEST_F(NforMethod, AlbedoTrustStagesMatchTheReference) {
    NforOptions o;
    o.radius = 3;
    o.albedoNoise = 0;
    ExpectStagesMatch(Ctx(), 29, 23, o);
    o.albedoNoise = NforOptions().albedoNoise;
    int untrusted = 0;
    auto noisy = [&untrusted](Frame *f, Image *) {
        std::mt19937_64 rng(SeedFromName("stagesNoisyAlbedo"));
        std::uniform_real_distribution<float> reflectance(0.05f, 0.95f);
        const int w = f->color.width, h = f->color.height;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w / 2; ++x)
                for (int c = 0; c < 3; ++c) f->albedo.At(c, y, x) = reflectance(rng);
        Image trust = ref::NforAlbedoTrust(f->color, f->albedo, NforOptions().albedoNoise);
        untrusted = int(std::count(trust.data.begin(), trust.data.end(), 0.f));
    };
    ExpectStagesMatch(Ctx(), 29, 23, o, false, false, false, false, noisy);
    EXPECT_GT(untrusted, 29 * 23 / 8) << "a good share of the noisy half is untrusted";
    // The bound is finite and >= 0.
    Frame f = MakeFrame(7, 5, 0.3, "trustBound");
    for (float bad : {-1.f, std::numeric_limits<float>::quiet_NaN(),
                      std::numeric_limits<float>::infinity()}) {
        o.albedoNoise = bad;
        EXPECT_THROW(NforDenoise(Ctx(), InputsOf(f), o), Error) << bad;
    }
}

// The glint floor: over a frame whose left half's albedo is noise with one glint (an albedo
// above kNforGlintAlbedo) in it, the floor's stages (the raised pixels, the variance after)
// match the reference and raise some pixels; off (0) or with no glint, no floor stage.
TEST_F(NforMethod, GlintNoiseStagesMatchTheReference) {
    NforOptions o;
    o.radius = 3;
    bool glint = true;
    auto noisy = [&](Frame *f, Image *) {
        std::mt19937_64 rng(SeedFromName("stagesGlint"));
        std::uniform_real_distribution<float> reflectance(0.05f, 0.95f);
        const int w = f->color.width, h = f->color.height;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w / 2; ++x)
                for (int c = 0; c < 3; ++c) f->albedo.At(c, y, x) = reflectance(rng);
        if (glint) f->albedo.At(1, h / 2, w / 4) = 2 * kNforGlintAlbedo;
    };
    auto floored = [](const std::vector<std::string> &names) {
        return std::count(names.begin(), names.end(), "glint") == 1 &&
               std::count(names.begin(), names.end(), "glint.variance") == 1;
    };
    std::vector<std::string> names;
    ExpectStagesMatch(Ctx(), 29, 23, o, false, false, false, false, noisy, &names);
    EXPECT_TRUE(floored(names));
    glint = false;
    names.clear();
    ExpectStagesMatch(Ctx(), 29, 23, o, false, false, false, false, noisy, &names);
    EXPECT_FALSE(floored(names)) << "no glint, no floor";
    glint = true;
    names.clear();
    ExpectStagesMatch(Ctx(), 29, 23, o, true, false, false, false, noisy, &names);
    EXPECT_FALSE(floored(names)) << "a variance layer, no floor";
    o.glintNoise = 0;
    names.clear();
    ExpectStagesMatch(Ctx(), 29, 23, o, false, false, false, false, noisy, &names);
    EXPECT_FALSE(floored(names)) << "off";
    Frame f = MakeFrame(7, 5, 0.3, "glintBound");
    for (float bad : {-1.f, std::numeric_limits<float>::quiet_NaN(),
                      std::numeric_limits<float>::infinity()}) {
        o.glintNoise = bad;
        EXPECT_THROW(NforDenoise(Ctx(), InputsOf(f), o), Error) << bad;
    }
}

// The defaults (second pass, local means), and a second pass of two bandwidths by SURE.
TEST_F(NforMethod, SecondPassStagesMatchTheReference) {
    NforOptions o;
    for (auto [w, h] : {std::pair{29, 23}, std::pair{1, 1}, std::pair{7, 1}})
        ExpectStagesMatch(Ctx(), w, h, o);
    o.radius = 3;
    o.bandwidths = {0.5f};
    o.pilotBandwidths = {0.5f, 1.f};
    o.meanRadius = 0;
    for (auto [w, h] : {std::pair{29, 23}, std::pair{1, 1}, std::pair{7, 1}})
        ExpectStagesMatch(Ctx(), w, h, o);
    o.bandwidths = {0.5f, 1.f};
    o.pilotBandwidths = {1.f};
    ExpectStagesMatch(Ctx(), 17, 13, o);
}

// A frame with a variance layer: the clamp reads the frame's own estimate (by default) or
// the layer, the rest the layer.
TEST_F(NforMethod, VarianceLayerStagesMatchTheReference) {
    NforOptions o;
    o.radius = 3;
    for (bool layer : {false, true}) {
        o.clampLayer = layer;
        for (auto [w, h] : {std::pair{29, 23}, std::pair{1, 1}, std::pair{7, 1}})
            ExpectStagesMatch(Ctx(), w, h, o, true);
    }
    // The estimate's clamp taking off more than none of the light: the layer's after all.
    o.clampLayer = false;
    o.clampLoss = 0;
    ExpectStagesMatch(Ctx(), 29, 23, o, true);
}

// Whether the run's plan says the plain frame's passes run beside the layer.
bool PlansLayerPasses(const NforResult &result) {
    for (const std::string &line : result.plan)
        if (line.find("run as without a layer") != std::string::npos) return true;
    return false;
}

// The names of a run's stages.
std::set<std::string> StageNames(const NforResult &result) {
    std::set<std::string> names;
    for (const auto &stage : result.stages) names.insert(stage.first);
    return names;
}

// Beside a variance layer the passes of a frame without one (specks, the clamp's light, the
// weak emitters' mean, the lights' spread) run, and the weights read the layer capped at
// --layer-noise-cap times the frame's own estimate; both off, as before. The stages agree
// with the reference's; the passes' stages are there only with them; the capped layer is
// nowhere above the layer, and below it at the values whose layer reports a firefly.
TEST_F(NforMethod, VarianceLayerPassesAndCapMatchTheReference) {
    for (bool passes : {true, false})
        for (float cap : {3.f, 0.f}) {
            NforOptions o;
            o.noLayerPasses = !passes;
            o.layerNoiseCap = cap;
            ExpectStagesMatch(Ctx(), 29, 23, o, true, true, true);
            ExpectStagesMatch(Ctx(), 7, 1, o, true);
            // The wide windows' distance reads the capped variance too.
            o.pilotWideRadius = o.radius + 2;
            ExpectStagesMatch(Ctx(), 29, 23, o, true, true, true);
        }
    Frame f = MakeFrame(29, 23, 0.3, "stages29x23");
    AddLightsAtTheEdge(&f, nullptr);
    Image layer = LayerWithFireflies(f);
    NforInputs in = InputsOf(f);
    in.variance = &layer;
    for (bool passes : {true, false}) {
        NforOptions o;
        o.keepStages = true;
        o.noLayerPasses = !passes;
        o.layerNoiseCap = 3;
        NforResult result = NforDenoise(Ctx(), in, o);
        std::set<std::string> names = StageNames(result);
        for (const char *name : {"specks", "unkept", "lights"})
            EXPECT_EQ(names.count(name), passes ? 1u : 0u) << name;
        EXPECT_EQ(PlansLayerPasses(result), passes);
        const Image *variance = nullptr;
        for (const auto &stage : result.stages)
            if (stage.first == "variance") variance = &stage.second;
        ASSERT_NE(variance, nullptr);
        size_t below = 0, fireflies = 0;
        for (size_t i = 0; i < layer.Size(); ++i) {
            EXPECT_LE(variance->data[i], layer.data[i]) << i;
            if (i % 7 != 3 || layer.data[i] <= 0) continue;
            ++fireflies;
            below += variance->data[i] < layer.data[i];
        }
        EXPECT_GT(below, fireflies / 2);
    }
    // Two runs of the defaults beside a layer, bit for bit.
    EXPECT_EQ(NforDenoise(Ctx(), in, NforOptions()).image.data,
              NforDenoise(Ctx(), in, NforOptions()).image.data);
    NforOptions uncapped;
    uncapped.keepStages = true;
    uncapped.layerNoiseCap = 0;
    NforResult result = NforDenoise(Ctx(), in, uncapped);
    for (const auto &stage : result.stages) {
        if (stage.first == "variance") {
            EXPECT_EQ(stage.second.data, layer.data);
        }
    }
    // The cap is finite and >= 0.
    for (float bad : {-1.f, std::numeric_limits<float>::quiet_NaN(),
                      std::numeric_limits<float>::infinity()}) {
        NforOptions o;
        o.layerNoiseCap = bad;
        EXPECT_THROW(NforDenoise(Ctx(), in, o), Error) << bad;
    }
}

// A pilot given from outside takes the first pass's place: the second pass's distances read
// it, on the GPU as in the reference; over partly covered pixels (divided by their alpha),
// beside a variance layer and with the coarse pass (halved like the colour).
TEST_F(NforMethod, GivenPilotStagesMatchTheReference) {
    NforOptions o;
    o.radius = 3;
    for (auto [w, h] : {std::pair{29, 23}, std::pair{1, 1}, std::pair{7, 1}})
        ExpectStagesMatch(Ctx(), w, h, o, false, false, false, false, {}, nullptr, true);
    ExpectStagesMatch(Ctx(), 29, 23, o, false, true, false, false, {}, nullptr, true);
    ExpectStagesMatch(Ctx(), 29, 23, o, true, false, false, false, {}, nullptr, true);
    o.coarse = true;
    ExpectStagesMatch(Ctx(), 29, 23, o, false, false, false, false, {}, nullptr, true);
}

// The given pilot is the pilot stage bit for bit, no first pass runs, the output moves with
// it and a rerun gives the same bits; with no second pass it is not read.
TEST_F(NforMethod, GivenPilotReplacesTheFirstPass) {
    Frame f = MakeFrame(31, 27, 0.3, "given pilot");
    Image pilot = PilotNearTruth(f);
    NforOptions o;
    o.radius = 3;
    o.keepStages = true;
    NforInputs in = InputsOf(f);
    const Image own = NforDenoise(Ctx(), in, o).image;
    in.pilot = &pilot;
    NforResult given = NforDenoise(Ctx(), in, o);
    std::set<std::string> names = StageNames(given);
    ASSERT_TRUE(names.count("pilot"));
    EXPECT_FALSE(names.count("k0.output")) << "the first pass ran";
    for (const auto &[name, image] : given.stages)
        if (name == "pilot") {
            EXPECT_TRUE(BitIdentical(image, pilot));
        }
    EXPECT_FALSE(BitIdentical(given.image, own));
    EXPECT_TRUE(BitIdentical(given.image, NforDenoise(Ctx(), in, o).image));
    o.pilotBandwidths = {};
    o.keepStages = false;
    NforInputs plain = InputsOf(f);
    EXPECT_TRUE(
        BitIdentical(NforDenoise(Ctx(), in, o).image, NforDenoise(Ctx(), plain, o).image));
}

// The front end's --nfor-pilot-layer reads the frame's layer as the pilot: its output is
// NforDenoise's with that pilot bit for bit and moves from the run without the option; a
// missing layer and --demodulate beside the option are refused.
TEST_F(NforMethod, PilotLayerOptionReadsTheLayer) {
    const Frame f = MakeFrame(31, 27, 0.3, "pilot layer");
    const Image pilot = PilotNearTruth(f);
    mcd::Frame frame;
    frame.width = f.color.width, frame.height = f.color.height;
    frame.layers = {{"color", f.color},
                    {"albedo", f.albedo},
                    {"normal", f.normal},
                    {"depth", f.depth},
                    {"p", pilot}};
    Device device = api::BorrowDevice(Ctx());
    Method given("nfor");
    given.Set("nfor-pilot-layer", "p");
    const Image out = given.Run(device, frame).image;
    NforInputs in = InputsOf(f);
    in.pilot = &pilot;
    // The front end's defaults on a frame without a variance layer: the wide second pass.
    NforOptions defaults;
    defaults.pilotWideRadius = 8;
    defaults.wideAgreement = 0.001f;
    EXPECT_TRUE(BitIdentical(out, NforDenoise(Ctx(), in, defaults).image));
    EXPECT_FALSE(BitIdentical(out, Method("nfor").Run(device, frame).image));
    Method missing("nfor");
    missing.Set("nfor-pilot-layer", "nosuch");
    EXPECT_TRUE(ThrowsError(
        ErrorKind::MissingLayer, [&] { missing.Run(device, frame); }, "nosuch"));
    given.Set("demodulate", "albedo");
    EXPECT_TRUE(ThrowsError(
        ErrorKind::InvalidArgument, [&] { given.Run(device, frame); }, "not demodulated"));
}

// A frame whose pixel (cx, cy) holds a bright path: one of its 16 samples 64 times the
// truth, so its mean is 5 times the truth, and the layer reports that sample's variance;
// the layer elsewhere the noise's own. Returns the layer.
Image AddBrightPath(Frame *f, int cx, int cy, double noise) {
    Image layer(f->truth.width, f->truth.height, 3);
    for (size_t i = 0; i < layer.Size(); ++i) {
        double sigma = noise * f->truth.data[i];
        layer.data[i] = float(sigma * sigma);
    }
    for (int c = 0; c < 3; ++c) {
        const double truth = f->truth.At(c, cy, cx), sample = 64 * truth;
        f->color.At(c, cy, cx) = float((15 * truth + sample) / 16);
        layer.At(c, cy, cx) = float((sample - truth) * (sample - truth) / 256);
    }
    return layer;
}

// Beside a variance layer the second pass's distance reads the layer capped at
// --pilot-noise-cap times the frame's own estimate (off by default): a pixel whose layer
// reports a bright path's variance would otherwise weigh with every neighbour in the pilot's
// distance (normalised by the variances' sum, not cancelled) and spread its light around.
// The stages agree with the reference's; the first pass reads the layer as it is.
TEST_F(NforMethod, PilotNoiseCapReadsTheEstimateAtABrightPath) {
    for (float cap : {1.f, 0.f})
        for (float layerCap : {3.f, 0.f}) {
            NforOptions o;
            o.pilotNoiseCap = cap;
            o.layerNoiseCap = layerCap;
            ExpectStagesMatch(Ctx(), 29, 23, o, true, true, true);
            ExpectStagesMatch(Ctx(), 7, 1, o, true);
            // The wide windows' distance reads the capped variance too.
            o.pilotWideRadius = o.radius + 2;
            ExpectStagesMatch(Ctx(), 29, 23, o, true, true, true);
        }
    const double noise = 0.1;
    Frame f = MakeFrame(41, 33, noise, "brightpath41x33");
    const int cx = 20, cy = 8;
    Image layer = AddBrightPath(&f, cx, cy, noise);
    NforInputs in = InputsOf(f);
    in.variance = &layer;
    for (float cap : {0.f, 1.f}) {
        NforOptions o;
        o.keepStages = true;
        o.pilotNoiseCap = cap;
        NforResult result = NforDenoise(Ctx(), in, o);
        const Image *pilotVariance = nullptr;
        for (const auto &stage : result.stages) {
            if (stage.first == "variance") {
                EXPECT_EQ(stage.second.data, layer.data);
            }
            if (stage.first == "pilot.variance") pilotVariance = &stage.second;
        }
        EXPECT_EQ(pilotVariance != nullptr, cap > 0);
        bool planned = false;  // --explain names the cap where it runs
        for (const std::string &line : result.plan)
            planned = planned || line.find("--pilot-noise-cap") != std::string::npos;
        EXPECT_EQ(planned, cap > 0);
        if (!pilotVariance) continue;
        // Nowhere above the layer; at the bright path far below it (its neighbours' noise).
        for (size_t i = 0; i < layer.Size(); ++i)
            EXPECT_LE(pilotVariance->data[i], layer.data[i]) << i;
        for (int c = 0; c < 3; ++c)
            EXPECT_LT(pilotVariance->At(c, cy, cx), 0.01f * layer.At(c, cy, cx)) << c;
    }
    // Off by default; where it runs the second pass reads it (the output moves).
    EXPECT_EQ(NforOptions().pilotNoiseCap, 0.f);
    NforOptions capped;
    capped.pilotNoiseCap = 1;
    EXPECT_NE(NforDenoise(Ctx(), in, capped).image.data,
              NforDenoise(Ctx(), in, NforOptions()).image.data);
    for (float bad : {-1.f, std::numeric_limits<float>::quiet_NaN(),
                      std::numeric_limits<float>::infinity()}) {
        NforOptions o;
        o.pilotNoiseCap = bad;
        EXPECT_THROW(NforDenoise(Ctx(), in, o), Error) << bad;
    }
}

// Beside a variance layer, with the passes on, a clamp that takes off more light than
// --clamp-loss (0 here: any) reads the layer, and the passes of a frame without one stay out:
// no specks, kept pixels' mean or lights' spread. The stages agree with the reference's.
TEST_F(NforMethod, VarianceLayerPassesStayOutWhereTheClampReadsTheLayer) {
    NforOptions o;
    o.clampLoss = 0;
    Frame f = MakeFrame(29, 23, 0.3, "stages29x23");
    AddLightsAtTheEdge(&f, nullptr);
    Image layer = LayerWithFireflies(f);
    NforInputs in = InputsOf(f);
    in.variance = &layer;
    NforOptions kept = o;
    kept.keepStages = true;
    NforResult result = NforDenoise(Ctx(), in, kept);
    EXPECT_TRUE(result.clampOnLayer);
    EXPECT_EQ(result.lights, 0u);
    std::set<std::string> names = StageNames(result);
    for (const char *name : {"specks", "unkept", "lights"}) EXPECT_EQ(names.count(name), 0u);
    EXPECT_EQ(names.count("clamp.variance"), 1u);
    EXPECT_FALSE(PlansLayerPasses(result));
    // Nor where --clamp-layer has the clamp read the layer.
    NforOptions onLayer;
    onLayer.clampLayer = true;
    EXPECT_FALSE(PlansLayerPasses(NforDenoise(Ctx(), in, onLayer)));
    ExpectStagesMatch(Ctx(), 29, 23, o, true, false, true);
}

// Lone lights kept (--firefly-lone-light 2): AddLightsAtTheEdge's weak light (albedo 3, its
// colour its albedo) has no emitter beside it. The stages agree with the reference's, and
// the rule keeps channels that the clamp takes without it. A negative albedo is refused.
TEST_F(NforMethod, LoneLightStagesMatchTheReference) {
    NforOptions o;
    o.fireflyLoneLight = 2;
    ExpectStagesMatch(Ctx(), 29, 23, o, false, false, true);
    Frame f = MakeFrame(29, 23, 0.3, "stages29x23");
    AddLightsAtTheEdge(&f, nullptr);
    const size_t clamped = NforDenoise(Ctx(), InputsOf(f), o).clamped;
    o.fireflyLoneLight = 0;
    EXPECT_LT(clamped, NforDenoise(Ctx(), InputsOf(f), o).clamped);
    o.fireflyLoneLight = -1;
    EXPECT_THROW(NforDenoise(Ctx(), InputsOf(f), o), Error);
}

// The clamp's light changes ExpectStagesMatch's frame: its stage differs from the one
// before it (the fits', before the local means) and from the image at the same point of a
// run without the pass (after the local means: the kept pixels' pass's input).
void ExpectClampLightChanges(vk::Context &context, int w, int h, NforOptions o,
                             bool covered = false, bool lights = false) {
    Frame f = MakeFrame(w, h, 0.3, fmt::format("stages{}x{}", w, h));
    Image alpha = covered ? Cover(&f) : Image();
    if (lights) AddLightsAtTheEdge(&f, covered ? &alpha : nullptr);
    NforInputs in = InputsOf(f);
    if (covered) in.alpha = &alpha;
    o.keepStages = true;
    NforResult on = NforDenoise(context, in, o);
    o.clampLightRadius = 0;
    NforResult off = NforDenoise(context, in, o);
    auto find = [](const NforResult &r, const std::string &name) {
        for (size_t i = 0; i < r.stages.size(); ++i)
            if (r.stages[i].first == name) return i;
        return r.stages.size();
    };
    size_t light = find(on, "clamp.light"), unkept = find(off, "unkept");
    ASSERT_LT(light, on.stages.size()) << "the pass ran";
    ASSERT_GT(light, 0u);
    ASSERT_LT(unkept, off.stages.size());
    EXPECT_EQ(on.stages[light - 1].first, off.stages[unkept - 1].first);
    EXPECT_EQ(on.stages[light - 1].second.data, off.stages[unkept - 1].second.data);
    EXPECT_NE(on.stages[light].second.data, on.stages[light - 1].second.data);
    EXPECT_NE(on.stages[light].second.data, off.stages[unkept].second.data)
        << "the pass gave some light back";
}

// The clamp's light given back (the coarse gate shut, so that it runs on these noisy
// frames): one scale and two, small enough for the frames; beside lights and partly
// covered pixels, whose neighbourhood keeps the clamped colour; off.
TEST_F(NforMethod, ClampLightStagesMatchTheReference) {
    NforOptions o;
    o.radius = 3;
    o.coarseGate = 0;
    o.clampLightRadius = 2;
    for (int fine : {0, 1}) {
        o.clampLightFine = fine;
        for (auto [w, h] : {std::pair{29, 23}, std::pair{1, 1}, std::pair{7, 1}}) {
            SCOPED_TRACE(fmt::format("fine {} {}x{}", fine, w, h));
            ExpectStagesMatch(Ctx(), w, h, o);
        }
        // With the tents of s 2 alone the pass changes nothing on this frame.
        if (fine > 0) ExpectClampLightChanges(Ctx(), 29, 23, o);
    }
    SCOPED_TRACE("partly covered, lights");
    ExpectStagesMatch(Ctx(), 29, 23, o, false, true, true);
    ExpectClampLightChanges(Ctx(), 29, 23, o, true, true);
    o.clampLightReach = 0;
    ExpectStagesMatch(Ctx(), 29, 23, o, false, true, true);
    o.clampLightRadius = 0;
    ExpectStagesMatch(Ctx(), 29, 23, o);
}

// Glints that the clamp takes (one pixel in six of the left third, 8x the surface: a wire
// mesh's) hold light the frame has: with the defaults the output there keeps most of it,
// without the pass (--clamp-light-radius 0) it loses it. A lone firefly beyond the coarse
// tents' reach of the glints is a firefly: the pass leaves the pixels around it as they
// were.
TEST_F(NforMethod, ClampLightGivesBackGlintsNotAFirefly) {
    const int w = 128, h = 64;
    Frame f = MakeFrame(w, h, 0, "clamp light");
    std::mt19937_64 rng(SeedFromName("clamp light glints"));
    std::normal_distribution<double> normal(0, 0.05);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            double gain = 1;
            if (x < 40 && rng() % 6 == 0) gain = 8;  // a glint
            if (x == 112 && y == 32) gain = 40;      // the firefly
            for (int c = 0; c < 3; ++c) {
                f.albedo.At(c, y, x) = 0.5f;
                f.normal.At(c, y, x) = c == 2 ? 1.f : 0.f;
                f.color.At(c, y, x) = float(0.25 * (1 + normal(rng)) * gain);
            }
        }
    NforOptions on, off;
    off.clampLightRadius = 0;
    NforResult a = NforDenoise(Ctx(), InputsOf(f), on),
               b = NforDenoise(Ctx(), InputsOf(f), off);
    EXPECT_FALSE(a.coarseRan);
    auto leftMean = [&](const Image &image) {
        double sum = 0;
        for (int c = 0; c < 3; ++c)
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < 32; ++x) sum += image.At(c, y, x);
        return sum;
    };
    const double input = leftMean(f.color);
    fmt::print("glints' light kept: {:.4f} with the pass, {:.4f} without\n",
               leftMean(a.image) / input, leftMean(b.image) / input);
    EXPECT_LT(leftMean(b.image), 0.9 * input);
    EXPECT_GT(leftMean(a.image), 0.94 * input);
    for (int y = 28; y <= 36; ++y)
        for (int x = 108; x <= 116; ++x)
            if (x != 112 || y != 32) {
                EXPECT_NEAR(a.image.At(1, y, x), b.image.At(1, y, x),
                            0.01 * b.image.At(1, y, x))
                    << x << "," << y;
            }
    NforResult again = NforDenoise(Ctx(), InputsOf(f), on);
    EXPECT_EQ(MeasureDifference(a.image, again.image).parity, 0u);
    EXPECT_EQ(a.image.data, again.image.data);
}

// Partly covered pixels over a transparent background: divided by their alpha before the
// method (the variance layer by its square) and multiplied back after; with the coarse and
// the kept pixels' passes too; and lights at the edge, whose spread reads the alpha (beside
// a background of alpha 0 also with --premultiplied, where nothing is divided).
TEST_F(NforMethod, PartlyCoveredStagesMatchTheReference) {
    NforOptions o;
    o.radius = 3;
    for (bool variance : {false, true})
        for (auto [w, h] : {std::pair{29, 23}, std::pair{1, 1}, std::pair{9, 4}}) {
            SCOPED_TRACE(fmt::format("variance {} {}x{}", variance, w, h));
            ExpectStagesMatch(Ctx(), w, h, o, variance, true);
        }
    ExpectStagesMatch(Ctx(), 29, 23, o, false, true, true);
    // Over a background of alpha 0 without partly covered pixels, as written or not.
    for (bool premultiplied : {false, true}) {
        SCOPED_TRACE(fmt::format("lights beside alpha 0, premultiplied {}", premultiplied));
        NforOptions lit = o;
        lit.premultiplied = premultiplied;
        ExpectStagesMatch(Ctx(), 29, 23, lit, false, true, true, true);
    }
    o.coarse = true;
    o.keptRadius = 2;
    ExpectStagesMatch(Ctx(), 29, 23, o, false, true);
}

// A noisy surface's silhouette over a transparent background: its partly covered pixels,
// divided by their alpha, are fitted with the surface around them and come out with a
// smaller error than denoised as the frame holds them; the covered and the empty pixels
// change little. An alpha of 1 and 0 only, or --premultiplied, gives the bits of a run
// without an alpha (this frame has no light, whose spread reads the alpha); reruns are
// bit-identical.
TEST_F(NforMethod, DenoisesPartlyCoveredPixelsAsTheirSurface) {
    Frame f = MakeFrame(48, 40, 0.3, "silhouette");
    Image alpha = Cover(&f);
    NforInputs in = InputsOf(f);
    in.alpha = &alpha;
    NforOptions straight, premultiplied;
    premultiplied.premultiplied = true;
    NforResult a = NforDenoise(Ctx(), in, straight), b = NforDenoise(Ctx(), in, premultiplied);
    EXPECT_EQ(a.partlyCovered, NforPartlyCovered(alpha));
    EXPECT_GT(a.partlyCovered, 40u);
    EXPECT_EQ(b.partlyCovered, 0u);
    // relMSE over the pixels whose alpha is in (lo, hi].
    auto error = [&](const Image &out, float lo, float hi) {
        double sum = 0;
        size_t count = 0;
        for (size_t i = 0; i < alpha.PixelCount(); ++i) {
            if (!(alpha.data[i] > lo && alpha.data[i] <= hi)) continue;
            for (int c = 0; c < 3; ++c) {
                double t = f.truth.Plane(c)[i], d = out.Plane(c)[i] - t;
                sum += d * d / (t * t + 0.01);
            }
            ++count;
        }
        return sum / double(3 * count);
    };
    const float below = std::nextafter(1.f, 0.f);
    EXPECT_LT(error(a.image, 0, below), 0.5 * error(b.image, 0, below))
        << error(a.image, 0, below) << " against " << error(b.image, 0, below);
    EXPECT_LT(error(a.image, below, 1), 1.05 * error(b.image, below, 1));
    EXPECT_TRUE(BitIdentical(a.image, NforDenoise(Ctx(), in, straight).image));
    NforInputs without = InputsOf(f);
    EXPECT_TRUE(BitIdentical(b.image, NforDenoise(Ctx(), without, straight).image));
    Image whole = alpha;
    for (float &v : whole.data) v = v > 0 ? 1.f : 0.f;
    in.alpha = &whole;
    EXPECT_TRUE(BitIdentical(b.image, NforDenoise(Ctx(), in, straight).image));
}

// The specks' clamp against its reference on values of every kind (fireflies and impulses
// among them), masks with emitters, frames of one pixel, one row and 3x3: the same pixels
// change, to round-off; some do, and the flat ground's bound holds some tighter.
TEST(NforSpecks, MatchesTheReference) {
    size_t changed = 0, flatChanged = 0;
    for (auto [w, h] : {std::pair{31, 17}, std::pair{1, 1}, std::pair{9, 1}, std::pair{3, 3}})
        for (InputKind kind : {InputKind::Uniform, InputKind::LogNormalFireflies,
                               InputKind::Constant, InputKind::Impulse}) {
            std::string name = fmt::format("specks {}x{} {}", w, h, InputKindName(kind));
            uint64_t seed = SeedFromName(name);
            Image input = MakeVarianceInput(kind, w, h, 3, seed);
            Image mask(w, h, 1, 1.f);
            for (size_t i = 5; i < mask.Size(); i += 13) mask.data[i] = 0;
            Image gpuSide = input, cpuSide = input;
            int rank = 1 + int(seed % 4);
            // Every other case with the flat ground's bound on.
            const float flatShare = seed % 2 ? 0.6f : 0.f;
            size_t count =
                NforClampSpecks(mask, {0.3f, 0.02f, rank, flatShare, 0.05f}, &gpuSide);
            ref::NforClampSpecks(mask, rank, 0.3, 0.02, &cpuSide, flatShare, 0.05f);
            if (flatShare > 0) {
                Image loose = input;
                NforClampSpecks(mask, {0.3f, 0.02f, rank, 0.f, 0.05f}, &loose);
                for (size_t i = 0; i < loose.Size(); ++i)
                    flatChanged += loose.data[i] != gpuSide.data[i];
            }
            EXPECT_TRUE(ImagesMatch(cpuSide, gpuSide, {}, {4 * kU, 0, 1e-12})) << name;
            size_t moved = 0;
            for (size_t i = 0; i < input.PixelCount(); ++i)
                moved += input.data[i] != cpuSide.data[i] ||
                         input.Plane(1)[i] != cpuSide.Plane(1)[i] ||
                         input.Plane(2)[i] != cpuSide.Plane(2)[i];
            EXPECT_EQ(count, moved) << name;
            changed += count;
        }
    EXPECT_GT(changed, 0u);
    EXPECT_GT(flatChanged, 0u) << "the flat ground's bound holds some value tighter";
}

// The flat ground's bound: a pixel at 1.15x its 8 flat neighbours (under the bound of 1.2x +
// 0.01, above 1.1x + 0.01) is scaled to 1.1x + 0.01 where the neighbours' median is at
// least 0.8 of the 2nd brightest; the same pixel beside a slope (two neighbours of 0.3,
// the rest 0.1: a highlight's edge) keeps its value; with the share 0 both keep theirs.
TEST(NforSpecks, HoldsASpeckOnAFlatGroundToTheTighterBound) {
    auto frame = [](bool flat) {
        Image image(5, 5, 3, flat ? 0.3f : 0.1f);
        if (!flat)
            for (int c = 0; c < 3; ++c) image.At(c, 1, 1) = image.At(c, 1, 2) = 0.3f;
        for (int c = 0; c < 3; ++c) image.At(c, 2, 2) = 0.345f;
        return image;
    };
    const Image mask(5, 5, 1, 1.f);
    for (bool flat : {true, false}) {
        Image on = frame(flat), off = frame(flat);
        size_t clamped = NforClampSpecks(mask, {0.2f, 0.01f, 2, 0.8f, 0.1f}, &on);
        EXPECT_EQ(NforClampSpecks(mask, {0.2f, 0.01f, 2, 0.f, 0.1f}, &off), 0u);
        EXPECT_EQ(off.At(0, 2, 2), 0.345f);
        if (flat) {
            EXPECT_EQ(clamped, 1u);
            EXPECT_NEAR(on.At(1, 2, 2), 1.1 * 0.3 + 0.01, 1e-6);
        } else {
            EXPECT_EQ(clamped, 0u);
            EXPECT_EQ(on.At(1, 2, 2), 0.345f);
        }
    }
    // The ground is the neighbours' median (their 5th largest): with four of the eight at
    // 0.3 and four at 0.1 the speck is kept, with five at 0.3 it is held.
    const int ring[8][2] = {{1, 1}, {1, 2}, {1, 3}, {2, 3}, {3, 3}, {3, 2}, {3, 1}, {2, 1}};
    for (int bright : {4, 5}) {
        Image image(5, 5, 3, 0.1f);
        for (int k = 0; k < bright; ++k)
            for (int c = 0; c < 3; ++c) image.At(c, ring[k][0], ring[k][1]) = 0.3f;
        for (int c = 0; c < 3; ++c) image.At(c, 2, 2) = 0.345f;
        NforClampSpecks(mask, {0.2f, 0.01f, 2, 0.8f, 0.1f}, &image);
        if (bright == 5)
            EXPECT_NEAR(image.At(1, 2, 2), 1.1 * 0.3 + 0.01, 1e-6);
        else
            EXPECT_EQ(image.At(1, 2, 2), 0.345f);
    }
}

// The rare light's spread against its reference: fireflies cut to a 50th by a clamp,
// `near` flags in stripes, frames of one pixel and one row, the defaults' pairing and one
// other within 16; the same sources, the same output to round-off; some give, and the lone
// ones of the sparse frame do not.
TEST(NforRareLight, MatchesTheReference) {
    size_t given[2] = {0, 0};  // by the defaults' pairing, by one other within 16
    NforRareLightSettings loose;
    loose.pair = 16;
    loose.others = 1;
    for (auto [w, h] : {std::pair{41, 37}, std::pair{1, 1}, std::pair{23, 1}})
        for (int every : {3, 61})
            for (const NforRareLightSettings &s : {NforRareLightSettings{}, loose}) {
                std::string name = fmt::format("rare {}x{} every {} pair {} others {}", w, h,
                                               every, s.pair, s.others);
                uint64_t seed = SeedFromName(name);
                Image color = MakeVarianceInput(InputKind::LogNormalFireflies, w, h, 3, seed);
                Image clamped = color;
                for (size_t i = seed % 5; i < color.PixelCount(); i += every)
                    for (int c = 0; c < 3; ++c) clamped.Plane(c)[i] = color.Plane(c)[i] * 0.02f;
                std::vector<char> near(color.PixelCount());
                for (size_t i = 0; i < near.size(); ++i) near[i] = (i / 7) % 5 == 0;
                Image output = MakeVarianceInput(InputKind::Uniform, w, h, 3, seed + 1);
                Image host = output, cpu = output;
                const size_t count = NforSpreadRareLight(color, clamped, near, s, &host);
                EXPECT_EQ(count,
                          ref::NforSpreadRareLight(color, clamped, near, s.share, s.ratio,
                                                   s.sigma, s.radius, s.pair, s.others, &cpu))
                    << name;
                EXPECT_TRUE(ImagesMatch(cpu, host, {}, {4 * kU, 0, 1e-12})) << name;
                if (count == 0) {
                    EXPECT_EQ(host.data, output.data) << name;
                }
                given[s.others == 1] += count;
            }
    EXPECT_GT(given[0], 0u);
    EXPECT_GT(given[1], 0u);
}

// Two pixels of a dark ground cut by the clamp to a 50th, 5 apart, give share 0.4 of
// their lost light around them as a Gaussian of 2: the frame gains that light (the
// Gaussian's square inside the frame), a pixel between them more than one beyond; a pixel
// cut to a fifth gives nothing (to a 50th with the ratio 60 neither); the same pair flagged
// `near` gives nothing and a flagged receiver gets nothing; one of them alone (no other within
// 16) is a firefly and gives nothing; share 0 leaves the output as it was. A source here
// needs one other within 16.
TEST(NforRareLight, SpreadsCutPixelsLightButNotALoneOnes) {
    const int w = 31, h = 25;
    auto frame = [&](Image *color, Image *clamped, std::vector<std::pair<int, int>> hits,
                     float cut) {
        *color = Image(w, h, 3, 0.02f);
        for (auto [y, x] : hits)
            for (int c = 0; c < 3; ++c) color->At(c, y, x) = 2.f;
        *clamped = *color;
        for (auto [y, x] : hits)
            for (int c = 0; c < 3; ++c) clamped->At(c, y, x) = 2.f * cut;
    };
    Image color, clamped;
    frame(&color, &clamped, {{12, 10}, {12, 15}}, 0.02f);
    std::vector<char> none(size_t(w) * h, 0);
    const Image output(w, h, 3, 0.02f);
    Image spread = output;
    NforRareLightSettings s;
    s.pair = 16;
    s.others = 1;
    ASSERT_EQ(NforSpreadRareLight(color, clamped, none, s, &spread), 2u);
    double gained = 0;
    for (size_t i = 0; i < spread.PixelCount(); ++i) gained += spread.data[i] - output.data[i];
    EXPECT_NEAR(gained, 0.4 * 2 * (2 - 0.04), 1e-4);
    EXPECT_GT(spread.At(0, 12, 12), spread.At(0, 12, 20));
    EXPECT_GT(spread.At(0, 12, 20), output.At(0, 12, 20));
    Image copy = output;
    frame(&color, &clamped, {{12, 10}, {12, 15}}, 0.2f);
    EXPECT_EQ(NforSpreadRareLight(color, clamped, none, s, &copy), 0u);
    EXPECT_EQ(copy.data, output.data);
    frame(&color, &clamped, {{12, 10}, {12, 15}}, 0.02f);
    NforRareLightSettings higher = s;
    higher.ratio = 60;
    EXPECT_EQ(NforSpreadRareLight(color, clamped, none, higher, &copy), 0u);
    EXPECT_EQ(copy.data, output.data);
    frame(&color, &clamped, {{12, 10}, {12, 15}}, 0.02f);
    std::vector<char> nearHits = none, nearReceiver = none;
    nearHits[12 * w + 10] = nearHits[12 * w + 15] = 1;
    EXPECT_EQ(NforSpreadRareLight(color, clamped, nearHits, s, &copy), 0u);
    EXPECT_EQ(copy.data, output.data);
    nearReceiver[12 * w + 12] = 1;
    copy = output;
    EXPECT_EQ(NforSpreadRareLight(color, clamped, nearReceiver, s, &copy), 2u);
    EXPECT_EQ(copy.At(0, 12, 12), output.At(0, 12, 12));
    EXPECT_EQ(copy.At(0, 12, 13), spread.At(0, 12, 13));
    frame(&color, &clamped, {{12, 10}}, 0.02f);
    copy = output;
    EXPECT_EQ(NforSpreadRareLight(color, clamped, none, s, &copy), 0u);
    EXPECT_EQ(copy.data, output.data);
    frame(&color, &clamped, {{12, 10}, {12, 15}}, 0.02f);
    s.share = 0;
    copy = output;
    NforSpreadRareLight(color, clamped, none, s, &copy);
    EXPECT_EQ(copy.data, output.data);
}

// A colour of +Inf over a finite clamped value is no source: its loss would spread Inf over
// the Gaussian's square. Host and CPU twin alike.
TEST(NforRareLight, AnInfiniteColourIsNoSource) {
    const int w = 31, h = 25;
    Image color(w, h, 3, 0.02f), clamped(w, h, 3, 0.02f);
    for (auto [y, x] : {std::pair{12, 10}, {12, 15}})
        for (int c = 0; c < 3; ++c) {
            color.At(c, y, x) = std::numeric_limits<float>::infinity();
            clamped.At(c, y, x) = 0.04f;
        }
    std::vector<char> none(size_t(w) * h, 0);
    const Image output(w, h, 3, 0.02f);
    Image host = output, twin = output;
    NforRareLightSettings s;
    s.pair = 16;  // the pair a source with a finite colour would be
    s.others = 1;
    EXPECT_EQ(NforSpreadRareLight(color, clamped, none, s, &host), 0u);
    EXPECT_EQ(host.data, output.data);
    ref::NforSpreadRareLight(color, clamped, none, s.share, s.ratio, s.sigma, s.radius, s.pair,
                             s.others, &twin);
    EXPECT_EQ(twin.data, output.data);
}

// The defaults' sources: hits within 6 of two others (a reflection's footprint) give; two
// hits 5 apart, and three strewn 10 apart (a caustic's over a floor), are fireflies. Host
// and CPU twin count alike.
TEST(NforRareLight, ThinlyScatteredHitsAreNoSources) {
    const int w = 41, h = 25;
    const Image output(w, h, 3, 0.02f);
    NforRareLightSettings s;
    std::vector<char> none(size_t(w) * h, 0);
    auto sources = [&](std::vector<std::pair<int, int>> hits) {
        Image color(w, h, 3, 0.02f);
        for (auto [y, x] : hits)
            for (int c = 0; c < 3; ++c) color.At(c, y, x) = 2.f;
        Image clamped = color;
        for (auto [y, x] : hits)
            for (int c = 0; c < 3; ++c) clamped.At(c, y, x) = 0.04f;
        Image host = output, twin = output;
        const size_t count = NforSpreadRareLight(color, clamped, none, s, &host);
        EXPECT_EQ(count, ref::NforSpreadRareLight(color, clamped, none, s.share, s.ratio,
                                                  s.sigma, s.radius, s.pair, s.others, &twin));
        EXPECT_EQ(count == 0, host.data == output.data);
        return count;
    };
    EXPECT_EQ(sources({{12, 10}, {12, 15}, {15, 12}}), 3u);
    // The pair's distance counts, one more does not: hits 6 apart, then 7 apart.
    EXPECT_EQ(sources({{12, 10}, {12, 16}, {18, 13}}), 3u);
    EXPECT_EQ(sources({{12, 10}, {12, 17}, {19, 13}}), 0u);
    EXPECT_EQ(sources({{12, 10}, {12, 15}}), 0u);
    EXPECT_EQ(sources({{12, 5}, {12, 15}, {12, 25}}), 0u);
    s.pair = 16;  // the middle one has both within 16
    EXPECT_EQ(sources({{12, 5}, {12, 15}, {12, 25}}), 1u);
}

// The glint bands against their reference: log-normal outputs, an albedo with glints (above
// 8) and emitters (above 1.5) at seeded pixels, frames of one pixel, one row and one column
// (each with a glint), with and without an alpha holding empty pixels and non-finite values
// in the output; the same pixels move, the same output to round-off; some move, and a frame
// without a glint is left as it was.
TEST(NforGlintBands, MatchesTheReference) {
    size_t moved = 0;
    for (auto [w, h] : {std::pair{41, 37}, std::pair{1, 1}, std::pair{23, 1}, std::pair{1, 19}})
        for (int every : {0, 53, 211})
            for (bool withAlpha : {false, true}) {
                std::string name =
                    fmt::format("glint bands {}x{} every {} alpha {}", w, h, every, withAlpha);
                uint64_t seed = SeedFromName(name);
                Image output = MakeVarianceInput(InputKind::LogNormalFireflies, w, h, 3, seed);
                Image albedo = MakeVarianceInput(InputKind::Uniform, w, h, 3, seed + 1);
                for (size_t i = seed % std::min<size_t>(7, albedo.PixelCount());
                     every > 0 && i < albedo.PixelCount(); i += every)
                    for (int c = 0; c < 3; ++c)
                        albedo.Plane(c)[i] = (i / every) % 2 ? 3.f : 20.f;
                Image alpha = MakeVarianceInput(InputKind::Uniform, w, h, 1, seed + 2);
                for (float &a : alpha.data) a = a < 0.1f ? 0.f : 1.f;
                if (withAlpha)
                    for (size_t i = seed % 11; i < output.PixelCount(); i += 97)
                        output.Plane(i % 3)[i] =
                            std::array{std::numeric_limits<float>::infinity(),
                                       -std::numeric_limits<float>::infinity(),
                                       std::numeric_limits<float>::quiet_NaN()}[i % 3];
                const Image *a = withAlpha ? &alpha : nullptr;
                NforGlintBandSettings s;
                Image host = output, cpu = output;
                const size_t count = NforSmoothGlintBands(albedo, a, s, &host);
                EXPECT_EQ(count, ref::NforSmoothGlintBands(
                                     albedo, a, s.radius, s.sigma, s.tensorSigma, s.bound,
                                     s.glintAlbedo, s.reach, s.emitterAlbedo, &cpu))
                    << name;
                EXPECT_TRUE(ImagesMatch(cpu, host, {}, {64 * kU, 0, 1e-9})) << name;
                if (count == 0) {
                    EXPECT_EQ(0, std::memcmp(host.data.data(), output.data.data(),
                                             output.data.size() * sizeof(float)))
                        << name;
                }
                moved += count;
            }
    EXPECT_GT(moved, 0u);
}

// On a broken band near a glint: a non-finite value on the band (+Inf, -Inf or NaN in one
// channel) stays the only one, and an empty pixel (alpha 0) on it keeps its value; host and
// twin alike.
TEST(NforGlintBands, ANonFiniteOrEmptyPixelDoesNotSpread) {
    const int w = 40, h = 36, row = 16;
    Image output(w, h, 3, 0.05f), albedo(w, h, 3, 0.5f), alpha(w, h, 1, 1.f);
    for (int x = 0; x < w; ++x)
        for (int c = 0; c < 3; ++c) output.At(c, row, x) = x % 2 ? 1.f : 0.6f;
    for (int c = 0; c < 3; ++c) albedo.At(c, 2, 20) = 20.f;
    output.At(0, row, 17) = 5.f;
    alpha.At(0, row, 17) = 0.f;
    for (float bad :
         {std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(),
          std::numeric_limits<float>::quiet_NaN()}) {
        Image in = output;
        in.At(1, row, 12) = bad;
        NforGlintBandSettings s;
        Image host = in, twin = in;
        EXPECT_GT(NforSmoothGlintBands(albedo, &alpha, s, &host), 0u);
        ref::NforSmoothGlintBands(albedo, &alpha, s.radius, s.sigma, s.tensorSigma, s.bound,
                                  s.glintAlbedo, s.reach, s.emitterAlbedo, &twin);
        for (const Image *image : {&host, &twin}) {
            size_t nonFinite = 0;
            for (float v : image->data) nonFinite += !std::isfinite(v);
            EXPECT_EQ(nonFinite, 1u) << bad;
            EXPECT_EQ(image->At(0, row, 17), 5.f) << bad;
        }
    }
}

// A highlight's band broken into hits and misses (a row alternating 0.6 and 1, within the
// samples' bound, on a ground of 0.05) within 16 pixels of a glint comes out nearly even
// along the row, its light kept to 2%, the ground two rows off it unchanged to 0.01 and an
// emitter on the band kept; with the glint 17 pixels off the band is left as it was, and
// without a glint, or with the radius 0, the whole output, bit for bit.
TEST(NforGlintBands, SmoothsABrokenBandNearAGlint) {
    const int w = 40, h = 36, row = 16;
    Image output(w, h, 3, 0.05f);
    for (int x = 0; x < w; ++x)
        for (int c = 0; c < 3; ++c) output.At(c, row, x) = x % 2 ? 1.f : 0.6f;
    auto albedoWithGlint = [&](int y, int x) {
        Image albedo(w, h, 3, 0.5f);
        for (int c = 0; c < 3; ++c) albedo.At(c, y, x) = 20.f;
        for (int c = 0; c < 3; ++c) albedo.At(c, row, 30) = 3.f;
        return albedo;
    };
    NforGlintBandSettings s;
    Image smoothed = output;
    ASSERT_GT(NforSmoothGlintBands(albedoWithGlint(2, 20), nullptr, s, &smoothed), 0u);
    double before = 0, after = 0, spread = 0;
    for (int x = 8; x < 28; ++x) {
        before += output.At(1, row, x);
        after += smoothed.At(1, row, x);
        spread = std::max(spread, std::abs(smoothed.At(1, row, x) - 0.8));
        EXPECT_NEAR(smoothed.At(1, row - 2, x), 0.05f, 0.01f) << x;
        EXPECT_NEAR(smoothed.At(1, row + 2, x), 0.05f, 0.01f) << x;
    }
    EXPECT_LT(spread, 0.05);
    EXPECT_NEAR(after, before, 0.02 * before);
    EXPECT_EQ(smoothed.At(1, row, 30), output.At(1, row, 30));
    Image far = output;
    NforSmoothGlintBands(albedoWithGlint(row + 17, 20), nullptr, s, &far);
    for (int x = 0; x < w; ++x) EXPECT_EQ(far.At(1, row, x), output.At(1, row, x)) << x;
    Image none = output;
    EXPECT_EQ(NforSmoothGlintBands(Image(w, h, 3, 0.5f), nullptr, s, &none), 0u);
    EXPECT_EQ(none.data, output.data);
    s.radius = 0;
    Image off = output;
    EXPECT_EQ(NforSmoothGlintBands(albedoWithGlint(2, 20), nullptr, s, &off), 0u);
    EXPECT_EQ(off.data, output.data);
}

// Stamps a 3x3 ground of `ground` (every channel, the same bits) around (x, y), its centre
// `centre`.
void StampGround(Image *image, int x, int y, float ground, float centre) {
    for (int c = 0; c < image->channels; ++c)
        for (int v = y - 1; v <= y + 1; ++v)
            for (int u = x - 1; u <= x + 1; ++u)
                image->At(c, v, u) = u == x && v == y ? centre : ground;
}

// The exact ground's flags against the reference. Designed grounds on a random frame: a
// bright and a dark pixel on a lit ground (flagged); one the clamp changed, one beside an
// emitter, one on a ground of 0, one on a ground of NaN, one equal to its ground and one on
// the border (each left). Then frames of every kind, of one pixel, one row and 3x3 with a
// ground stamped where it fits: the same flags as the reference's.
TEST(NforExactGround, MatchesTheReference) {
    const int w = 15, h = 9;
    Image input = MakeVarianceInput(InputKind::Uniform, w, h, 3, SeedFromName("exact ground"));
    const float nan = std::numeric_limits<float>::quiet_NaN();
    StampGround(&input, 2, 2, 1.425f, 300.f);               // flagged
    StampGround(&input, 6, 2, 1.425f, 0.1f);                // flagged: darker is as unlike
    StampGround(&input, 10, 2, 1.425f, 300.f);              // clamped
    StampGround(&input, 2, 6, 1.425f, 300.f);               // beside an emitter
    StampGround(&input, 6, 6, 0.f, 5.f);                    // unlit ground
    StampGround(&input, 10, 6, nan, 5.f);                   // NaN ground
    StampGround(&input, 13, 4, 0.5f, 0.5f);                 // the centre equals its ground
    for (int c = 0; c < 3; ++c) input.At(c, 4, 14) = 50.f;  // the border: 5 neighbours
    Image clamped = input;
    clamped.At(1, 2, 10) = 2.f;
    Image mask(w, h, 1, 1.f);
    mask.At(0, 7, 3) = 0;
    const std::vector<char> flags = NforExactGround(input, clamped, mask);
    EXPECT_EQ(flags, ref::NforExactGround(input, clamped, mask));
    std::set<std::pair<int, int>> flagged;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            if (flags[size_t(y) * w + x]) flagged.insert({x, y});
    EXPECT_EQ(flagged, (std::set<std::pair<int, int>>{{2, 2}, {6, 2}}));

    size_t count = 0;
    for (auto [fw, fh] : {std::pair{31, 17}, std::pair{1, 1}, std::pair{9, 1}, std::pair{3, 3}})
        for (InputKind kind : {InputKind::Uniform, InputKind::LogNormalFireflies,
                               InputKind::Constant, InputKind::Impulse}) {
            std::string name =
                fmt::format("exact ground {}x{} {}", fw, fh, InputKindName(kind));
            uint64_t seed = SeedFromName(name);
            Image frame = MakeVarianceInput(kind, fw, fh, 3, seed);
            if (fw >= 3 && fh >= 3) StampGround(&frame, 1, 1, 0.75f, float(1 + seed % 100));
            Image frameMask(fw, fh, 1, 1.f);
            const std::vector<char> got = NforExactGround(frame, frame, frameMask);
            EXPECT_EQ(got, ref::NforExactGround(frame, frame, frameMask)) << name;
            {
                ForceParallelParts split(3);  // rows among threads: the same flags
                EXPECT_EQ(NforExactGround(frame, frame, frameMask), got) << name;
            }
            for (char f : got) count += f;
        }
    EXPECT_GT(count, 0u);
}

// A quiet ground for the lone samples' cap: colour about 0.45 (a little noise), its layer
// 0.002 (samples that agree).
void QuietGround(Image *color, Image *variance, const std::string &name) {
    std::mt19937_64 rng(SeedFromName(name));
    std::uniform_real_distribution<double> jitter(-0.05, 0.05);
    for (size_t i = 0; i < color->Size(); ++i) {
        color->data[i] = float(0.45 + jitter(rng));
        variance->data[i] = float(0.002 * (1 + jitter(rng)));
    }
}

// Stamps a lone sample at (x, y): one sample of 64 at value v, so the mean is v / 64 and the
// layer's variance of the mean about its square.
void StampLoneSample(Image *color, Image *variance, int x, int y, float v) {
    for (int c = 0; c < color->channels; ++c) {
        color->At(c, y, x) = v / 64;
        variance->At(c, y, x) = (v / 64) * (v / 64);
    }
}

// The layer as the clamp reads it: capped where NforCapLoneSamples capped, else the layer.
Image CappedLayer(const Image &variance, const Image &color, size_t *count) {
    Image capped;
    const size_t n = NforCapLoneSamples(variance, color, &capped);
    if (count) *count = n;
    return n ? capped : variance;
}

// The lone samples' cap against the reference. Designed: on a quiet ground an isolated lone
// sample (capped, to its neighbours' median), two lone samples 10 apart (a caustic's: both
// kept), one 30 from them (capped), one on an exact ground (also in the frame's corner), one
// on a ground of 0, one whose layer says many samples, one of NaN (all kept). Then frames of
// every kind, of one pixel, one row and 3x3: the same values and count as the reference's,
// under a forced split too.
TEST(NforCapLoneSamples, MatchesTheReference) {
    const int w = 80, h = 40;
    Image color(w, h, 3), variance(w, h, 3);
    QuietGround(&color, &variance, "lone samples");
    const float nan = std::numeric_limits<float>::quiet_NaN();
    StampLoneSample(&color, &variance, 20, 8, 2300.f);  // capped
    StampLoneSample(&color, &variance, 40, 8, 2300.f);  // a pair 10 apart: kept
    StampLoneSample(&color, &variance, 50, 8, 2300.f);
    StampLoneSample(&color, &variance, 50, 38, 2300.f);  // 30 below the pair: capped
    StampGround(&color, 8, 30, 1.425f, 400.f);           // an exact ground: kept
    StampGround(&variance, 8, 30, 0.f, 400.f * 400.f);
    StampGround(&color, 20, 30, 0.f, 30.f);  // a ground of 0: kept
    StampGround(&variance, 20, 30, 0.f, 900.f);
    StampLoneSample(&color, &variance, 70, 20, 2300.f);  // many samples: kept
    for (int c = 0; c < 3; ++c) variance.At(c, 20, 70) = 1.f;
    for (int c = 0; c < 3; ++c) color.At(c, 25, 30) = nan;  // NaN: kept
    // The frame's first pixel on an exact ground of its three neighbours: kept.
    StampLoneSample(&color, &variance, 0, 0, 2300.f);
    for (auto [x, y] : {std::pair{1, 0}, std::pair{0, 1}, std::pair{1, 1}})
        for (int c = 0; c < 3; ++c) color.At(c, y, x) = 1.425f;
    size_t count = 0, refCount = 0;
    const Image capped = CappedLayer(variance, color, &count);
    EXPECT_EQ(capped.data, ref::NforCapLoneSamples(variance, color, kNforLoneHits,
                                                   kNforLoneRatio, kNforLoneReach, &refCount)
                               .data);
    EXPECT_EQ(count, 2u);
    EXPECT_EQ(refCount, count);
    std::set<std::pair<int, int>> changed;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            if (capped.At(1, y, x) != variance.At(1, y, x)) changed.insert({x, y});
    EXPECT_EQ(changed, (std::set<std::pair<int, int>>{{20, 8}, {50, 38}}));
    EXPECT_LT(capped.At(1, 8, 20), 0.0021f);

    size_t total = 0;
    for (auto [fw, fh] : {std::pair{31, 17}, std::pair{1, 1}, std::pair{9, 1}, std::pair{3, 3}})
        for (InputKind kind : {InputKind::Uniform, InputKind::LogNormalFireflies,
                               InputKind::Constant, InputKind::Impulse}) {
            const std::string name =
                fmt::format("lone samples {}x{} {}", fw, fh, InputKindName(kind));
            const uint64_t seed = SeedFromName(name);
            Image frame = MakeVarianceInput(kind, fw, fh, 3, seed);
            Image layer = MakeVarianceInput(InputKind::Uniform, fw, fh, 3, seed + 1);
            for (float &v : layer.data) v *= 0.01f;
            if (fw >= 3 && fh >= 3) StampLoneSample(&frame, &layer, fw / 2, fh / 2, 900.f);
            size_t got = 0, want = 0;
            const Image out = CappedLayer(layer, frame, &got);
            EXPECT_EQ(out.data, ref::NforCapLoneSamples(layer, frame, kNforLoneHits,
                                                        kNforLoneRatio, kNforLoneReach, &want)
                                    .data)
                << name;
            EXPECT_EQ(got, want) << name;
            {
                ForceParallelParts split(3);  // rows among threads: the same values
                EXPECT_EQ(CappedLayer(layer, frame, nullptr).data, out.data) << name;
            }
            total += got;
        }
    EXPECT_GT(total, 0u);
}

// A firefly on a quiet ground beside a variance layer the clamp reads (--clamp-layer): its
// layer reports its own variance, so without the cap the clamp keeps it and the fits spread
// it; with the cap it is clamped and the pixels around it stay near the ground. A pair of
// lone samples 6 apart (a caustic's) keeps its light either way. The stages match the
// reference's with such a firefly in the frame.
TEST_F(NforMethod, ClampsAnIsolatedLoneSampleBesideALayer) {
    const int w = 64, h = 40;
    Frame f = MakeFrame(w, h, 0, "lone sample");
    Image variance(w, h, 3);
    QuietGround(&f.color, &variance, "lone sample ground");
    for (float &a : f.albedo.data) a = 0.5f;
    StampLoneSample(&f.color, &variance, 14, 20, 2300.f);
    StampLoneSample(&f.color, &variance, 44, 17, 2300.f);
    StampLoneSample(&f.color, &variance, 50, 17, 2300.f);
    NforInputs in = InputsOf(f);
    in.variance = &variance;
    NforOptions o;
    o.radius = 3;
    o.clampLayer = true;
    NforOptions off = o;
    off.noLoneSampleCap = true;
    NforResult a = NforDenoise(Ctx(), in, o), b = NforDenoise(Ctx(), in, off);
    EXPECT_EQ(a.loneSamples, 1u);
    double nearA = 0, nearB = 0, pairA = 0, pairB = 0;
    for (int y = 17; y < 24; ++y)
        for (int x = 11; x < 18; ++x) {
            nearA = std::max(nearA, double(a.image.At(1, y, x)));
            nearB = std::max(nearB, double(b.image.At(1, y, x)));
        }
    for (int y = 12; y < 23; ++y)
        for (int x = 39; x < 56; ++x)
            pairA += a.image.At(1, y, x), pairB += b.image.At(1, y, x);
    fmt::print(
        "near the firefly at most {:.3f} / {:.3f} (cap / none); the pair's light {:.1f} / "
        "{:.1f}\n",
        nearA, nearB, pairA, pairB);
    EXPECT_LT(nearA, 1.5);
    EXPECT_GT(nearB, 5.0) << "the frame no longer shows the firefly's spread";
    EXPECT_NEAR(pairA, pairB, 0.01 * pairB);
    EXPECT_GT(pairA, 60.0) << "the pair's light is kept";
    // The stages' layer is 0.3 x the truth's: a truth of 400 / 3 makes a colour of 40 a
    // lone sample there.
    auto stamp = [](Frame *frame, Image *) {
        for (int c = 0; c < 3; ++c) {
            frame->color.At(c, 11, 12) = 40.f;
            frame->truth.At(c, 11, 12) = 400.f / 3;
        }
    };
    ExpectStagesMatch(Ctx(), 29, 23, o, true, false, false, false, stamp);
}

// A light under a pixel seen in a mirror: a pixel of 300 amid neighbours of exactly 1.425
// (every sample there saw the same) keeps its input, and the pixels around it stay near
// their ground; with --no-exact-ground the fits and the local means spread its light into
// a blotch. The stages match the reference's with such a ground in the frame.
TEST_F(NforMethod, KeepsALightUnderAPixelOnAnExactGround) {
    auto stamp = [](Frame *f, Image *) {
        for (int c = 0; c < 3; ++c)
            for (int y = 8; y < 15; ++y)
                for (int x = 8; x < 15; ++x) {
                    f->color.At(c, y, x) = x == 11 && y == 11 ? 300.f : 1.425f;
                    f->albedo.At(c, y, x) = 0.95f;
                }
    };
    NforOptions o;
    o.radius = 3;
    ExpectStagesMatch(Ctx(), 29, 23, o, false, false, false, false, stamp);
    Frame f = MakeFrame(29, 23, 0.3, "exact ground");
    stamp(&f, nullptr);
    NforOptions off = o;
    off.noExactGround = true;
    NforResult a = NforDenoise(Ctx(), InputsOf(f), o), b = NforDenoise(Ctx(), InputsOf(f), off);
    EXPECT_EQ(a.exactGround, 1u);
    EXPECT_EQ(b.exactGround, 0u);
    double nearA = 0, nearB = 0;
    for (int y = 9; y < 14; ++y)
        for (int x = 9; x < 14; ++x)
            if (x != 11 || y != 11) {
                nearA = std::max(nearA, double(a.image.At(1, y, x)));
                nearB = std::max(nearB, double(b.image.At(1, y, x)));
            }
    fmt::print("centre {:.1f} / {:.1f}, its neighbours at most {:.3f} / {:.3f}\n",
               a.image.At(1, 11, 11), b.image.At(1, 11, 11), nearA, nearB);
    EXPECT_NEAR(a.image.At(1, 11, 11), 300.f, 3.f);
    EXPECT_LT(nearA, 1.2 * 1.425);
    EXPECT_GT(nearB, 2 * 1.425) << "the frame no longer shows the blotch";
}

// A speck the firefly clamp leaves (a pixel at 1.7x its flat neighbours, under the clamp's
// limit) and the fits keep (its normal unlike its neighbours') comes out near its neighbours:
// scaled down to the bound, its light given to the pixels around it by the local means, the
// frame's sum kept; with
// --speck-relative -1 it stays. A line a pixel wide (two bright neighbours each) is kept.
TEST_F(NforMethod, ClampsASpeckTheFitsLeaveAndKeepsItsLight) {
    int w = 32, h = 32;
    Frame f = MakeFrame(w, h, 0, "speck");
    std::mt19937_64 rng(SeedFromName("speck noise"));
    std::normal_distribution<double> normal(0, 0.05);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                f.albedo.At(c, y, x) = 0.5f;
                f.truth.At(c, y, x) = 0.25f;
                f.color.At(c, y, x) = float(0.25 * (1 + normal(rng)));
                // A wire a sample hit: its normal unlike the ground's, so the fits weigh
                // only itself (and a line's pixels one another).
                if ((x == 16 && y == 16) || (x == 6 && y >= 4 && y < 28)) {
                    f.color.At(c, y, x) = 0.425f;
                    f.normal.At(c, y, x) = c == 2 ? 1.f : 0.f;
                }
            }
    NforOptions on, off;
    off.speckRelative = -1;
    NforResult a = NforDenoise(Ctx(), InputsOf(f), on),
               b = NforDenoise(Ctx(), InputsOf(f), off);
    EXPECT_EQ(b.specks, 0u);
    EXPECT_GE(a.specks, 1u);
    EXPECT_GT(b.image.At(1, 16, 16), 0.38f);
    EXPECT_LT(a.image.At(1, 16, 16), 0.36f);
    double sumA = 0, sumB = 0;
    for (size_t i = 0; i < a.image.Size(); ++i)
        sumA += a.image.data[i], sumB += b.image.data[i];
    EXPECT_NEAR(sumA / sumB, 1.0, 1e-3);
    for (int y = 8; y < 24; ++y) EXPECT_GT(a.image.At(1, y, 6), 0.38f) << y;
}

// The division by alpha (and by its square) and the multiplication back against their
// references: alphas under the floor, at it, between, 1, above 1 and negative, on values of
// every kind; only the partly covered pixels change.
TEST(NforAlpha, MatchesTheReference) {
    const float special[] = {0.f, 5e-4f, 1e-3f, 1.f / 16, 0.5f, 15.f / 16, 1.f, 1.5f, -0.25f};
    for (auto [w, h] : {std::pair{31, 17}, std::pair{1, 1}, std::pair{2, 5}})
        for (InputKind kind :
             {InputKind::Uniform, InputKind::LogNormalFireflies, InputKind::Constant}) {
            std::string name = fmt::format("alpha {}x{} {}", w, h, InputKindName(kind));
            uint64_t seed = SeedFromName(name);
            Image image = MakeInput(kind, w, h, 3, seed);
            Image alpha = MakeVarianceInput(InputKind::Uniform, w, h, 1, seed + 1);
            for (size_t i = 0; i < alpha.Size() && i < std::size(special); ++i)
                alpha.data[i] = special[i];
            size_t partly = 0;
            for (float a : alpha.data) partly += ref::NforPartlyCovered(a);
            EXPECT_EQ(NforPartlyCovered(alpha), partly) << name;
            const Tolerance tolerance{4 * kU, 0, 1e-12};
            for (int power : {1, 2}) {
                Image divided = NforDivideByAlpha(image, alpha, power);
                EXPECT_TRUE(
                    ImagesMatch(ref::NforStraight(image, alpha, power), divided, {}, tolerance))
                    << name << " power " << power;
                for (size_t i = 0; i < image.Size(); ++i) {
                    if (!ref::NforPartlyCovered(alpha.data[i % alpha.PixelCount()])) {
                        ASSERT_EQ(std::memcmp(&image.data[i], &divided.data[i], 4), 0) << name;
                    }
                }
            }
            Image multiplied = image;
            NforMultiplyByAlpha(alpha, &multiplied);
            EXPECT_TRUE(
                ImagesMatch(ref::NforPremultiply(image, alpha), multiplied, {}, tolerance))
                << name;
        }
}

// A frame whose light is in rare bright samples (one pixel in 8 saw a caustic through 4 of
// its 16 paths, the rest none of it): the estimate's clamp would take a third of the light
// off, so beside the variance layer the clamp reads the layer and the brightness stays.
TEST_F(NforMethod, KeepsTheLightOfRareBrightSamples) {
    Frame f = MakeFrame(32, 32, 0.05, "rare bright");
    std::mt19937_64 rng(SeedFromName("rare bright hits"));
    Image variance(32, 32, 3);
    double input = 0;
    for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 32; ++x) {
            bool hit = rng() % 8 == 0;
            for (int c = 0; c < 3; ++c) {
                float t = f.truth.At(c, y, x);
                // Per sample 0 or 10 t (a caustic 10x the surface): mean 2.5 t or 0.
                f.color.At(c, y, x) = hit ? 2.5f * t : 0.f;
                variance.At(c, y, x) =
                    hit ? float(std::pow(10 * t, 2) * 0.25 * 0.75 / 16) : 0.f;
                input += f.color.At(c, y, x);
            }
        }
    NforInputs in = InputsOf(f);
    in.variance = &variance;
    auto brightness = [&](const Image &image) {
        double sum = 0;
        for (float v : image.data) sum += v;
        return sum / input;
    };
    NforOptions defaults;
    defaults.keepStages = true;
    NforResult r = NforDenoise(Ctx(), in, defaults);
    EXPECT_TRUE(r.clampOnLayer);
    // The passes of a frame without a layer stay out: the clamp read the layer.
    std::set<std::string> names = StageNames(r);
    for (const char *name : {"specks", "unkept", "lights"}) EXPECT_EQ(names.count(name), 0u);
    EXPECT_GT(r.clampLoss, 0.03);
    EXPECT_NEAR(brightness(r.image), 1, 0.03);
    NforOptions never;
    never.clampLoss = 1;
    never.noLayerPasses = true;  // the clamp's light restored would give it back
    NforResult estimate = NforDenoise(Ctx(), in, never);
    EXPECT_FALSE(estimate.clampOnLayer);
    EXPECT_LT(brightness(estimate.image), 0.97);
}

// The fraction of the light the estimate's clamp takes off, measured for a tiled frame in
// strips of rows (NforFrameClampLoss), is the one a run on the whole frame measures, bit
// for bit: strips of one row, of a few and the whole frame, at two noise radii (halos), with
// the sparse mean (the default: the left half's rare hits among zeros read as noise, so the
// clamp takes less) and without.
TEST_F(NforMethod, FrameClampLossInStripsIsTheRunsOwn) {
    const int w = 37, h = 29;
    Frame f = MakeFrame(w, h, 0.1, "strips");
    AddLightsAtTheEdge(&f, nullptr);  // bright emitters: the line's floor reaches further
    std::mt19937_64 rng(SeedFromName("strips hits"));
    Image variance(w, h, 3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            bool hit = x < w / 2 && rng() % 6 == 0;
            for (int c = 0; c < 3; ++c) {
                float t = f.truth.At(c, y, x);
                if (x < w / 2) f.color.At(c, y, x) = hit ? 4 * t : 0.f;
                variance.At(c, y, x) = float(std::pow(0.1 * t, 2) * (hit ? 100 : 1));
            }
        }
    NforInputs in = InputsOf(f);
    in.variance = &variance;
    for (int noiseRadius : {1, 2}) {
        double losses[2] = {};
        for (bool sparse : {true, false}) {
            NforOptions o;
            o.radius = 3;
            o.noiseRadius = noiseRadius;
            o.noSparseNoise = !sparse;
            double own = NforDenoise(Ctx(), in, o).clampLoss;
            losses[sparse] = own;
            EXPECT_GT(own, 0.005) << "the clamp takes some of the light";
            for (int strip : {w, 3 * w + 5, w * h}) {
                NforInputs measured = in;
                NforFrameClampLoss(Ctx(), &measured, o, strip);
                EXPECT_EQ(measured.clampLoss, own)
                    << "noise radius " << noiseRadius << ", strips of " << strip
                    << " pixels, sparse " << sparse;
            }
        }
        EXPECT_LT(losses[true], losses[false]) << "noise radius " << noiseRadius;
    }
}

// A second pass over two window sizes (each of two bandwidths over both: four candidates by
// SURE), with a light's edges clamped.
TEST_F(NforMethod, WideSecondPassStagesMatchTheReference) {
    NforOptions o;
    o.radius = 3;
    o.pilotWideRadius = 5;
    o.pilotBandwidths = {0.5f, 1.f};
    o.fireflyLightEdge = 0.5f;
    for (auto [w, h] : {std::pair{29, 23}, std::pair{1, 1}, std::pair{7, 1}})
        ExpectStagesMatch(Ctx(), w, h, o);
    Frame f = MakeFrame(21, 19, 0.4, "wide rerun");
    EXPECT_TRUE(BitIdentical(NforDenoise(Ctx(), InputsOf(f), o).image,
                             NforDenoise(Ctx(), InputsOf(f), o).image));
    o.pilotWideRadius = 3;
    EXPECT_THROW(NforDenoise(Ctx(), InputsOf(f), o), Error);
}

// The second pass's distance normalised apart from the first's: by 2 min(v_p, v_q) in the
// first and v_p + v_q in the second, and the other way round; the second pass's distance
// follows its own setting (it differs from the one the first pass's would give).
TEST_F(NforMethod, PilotDistanceVarianceStagesMatchTheReference) {
    NforOptions o;
    o.radius = 3;
    o.minVariance = true;
    o.pilotMinVariance = 0;
    for (auto [w, h] : {std::pair{29, 23}, std::pair{1, 1}, std::pair{9, 4}})
        ExpectStagesMatch(Ctx(), w, h, o);
    o.minVariance = false;
    o.pilotMinVariance = 1;
    ExpectStagesMatch(Ctx(), 29, 23, o);
    Frame f = MakeFrame(29, 23, 0.4, "pilot distance");
    auto pilotDistance = [&](int pilotMin) {
        NforOptions run = o;
        run.pilotMinVariance = pilotMin;
        run.keepStages = true;
        NforResult result = NforDenoise(Ctx(), InputsOf(f), run);
        for (auto &[name, image] : result.stages)
            if (name == "pilot.distance") return image;
        ADD_FAILURE() << "no pilot.distance stage";
        return Image();
    };
    Image same = pilotDistance(-1), sum = pilotDistance(0), min = pilotDistance(1);
    EXPECT_TRUE(BitIdentical(same, sum));
    EXPECT_FALSE(BitIdentical(min, sum));
}

// The coarse pass: the whole method again at half the resolution (odd sizes and 1x1
// included), its stage and the corrected output against the reference's.
TEST_F(NforMethod, CoarsePassStagesMatchTheReference) {
    NforOptions o;
    o.radius = 3;
    o.coarse = true;
    for (auto [w, h] : {std::pair{29, 23}, std::pair{1, 1}, std::pair{7, 1}})
        ExpectStagesMatch(Ctx(), w, h, o);
    Frame f = MakeFrame(21, 19, 0.4, "coarse rerun");
    EXPECT_TRUE(BitIdentical(NforDenoise(Ctx(), InputsOf(f), o).image,
                             NforDenoise(Ctx(), InputsOf(f), o).image));
}

// The halving and the correction against their references on random inputs, odd sizes,
// one pixel and constants.
TEST(NforCoarse, MatchesTheReference) {
    for (auto [w, h] : {std::pair{31, 17}, std::pair{1, 1}, std::pair{2, 5}, std::pair{16, 16}})
        for (InputKind kind :
             {InputKind::Uniform, InputKind::LogNormalFireflies, InputKind::Constant}) {
            std::string name = fmt::format("coarse {}x{} {}", w, h, InputKindName(kind));
            uint64_t seed = SeedFromName(name);
            Image input = MakeInput(kind, w, h, 3, seed),
                  output = MakeInput(kind, w, h, 3, seed + 1);
            Image albedo = MakeVarianceInput(InputKind::Uniform, w, h, 3, seed + 2);
            for (float &a : albedo.data) a *= 2;  // some emitters
            Image coarse = MakeInput(kind, (w + 1) / 2, (h + 1) / 2, 3, seed + 3);
            for (size_t i = 0; i < coarse.Size(); ++i) coarse.data[i] *= 1.05f;
            EXPECT_LE(MeasureDifference(NforHalf(input), ref::NforHalf(input)).nmse, 1e-12)
                << name;
            EXPECT_LE(MeasureDifference(NforHalf(input, true), ref::NforHalf(input, true)).nmse,
                      1e-12)
                << name;
            Image gpuSide = output, cpuSide = output;
            NforAddCoarse(input, coarse, &albedo, 1.5f, 0.1f, 0.3f, &gpuSide);
            ref::NforAddCoarse(input, coarse, &albedo, 1.5, 0.1, 0.3, &cpuSide);
            EXPECT_LE(MeasureDifference(gpuSide, cpuSide).nmse, 1e-10) << name;
        }
}

// A coarse output a little above the fine one on a flat, noisy area lifts it there; one far
// off (an edge the half resolution blurs) and an emitter leave it.
TEST(NforCoarse, TakesSmallLowFrequencyDifferencesOnly) {
    int w = 16, h = 16;
    Image input(w, h, 3), output(w, h, 3, 1.f), coarse(w / 2, h / 2, 3, 1.02f);
    for (size_t i = 0; i < input.Size(); ++i) input.data[i] = i % 2 ? 1.3f : 0.7f;
    // The residual is 0.3 in every channel: t = min(0.1 x 3, 0.3 sqrt(3 x 0.09)), the
    // difference 0.02 in each of 3 channels, taken times 1 - |d|^2 / t^2.
    double t = std::min(0.3, 0.3 * std::sqrt(0.27)), lifted = 1 + 0.02 * (1 - 0.0012 / (t * t));
    Image moved = output;
    NforAddCoarse(input, coarse, nullptr, 1.5f, 0.1f, 0.3f, &moved);
    EXPECT_NEAR(moved.At(0, 8, 8), lifted, 1e-5);
    Image far(w / 2, h / 2, 3, 2.f), kept = output;
    NforAddCoarse(input, far, nullptr, 1.5f, 0.1f, 0.3f, &kept);
    EXPECT_EQ(kept.At(0, 8, 8), 1.f);
    Image albedo(w, h, 3, 0.5f);
    albedo.At(1, 8, 8) = 3.f;
    Image lit = output;
    NforAddCoarse(input, coarse, &albedo, 1.5f, 0.1f, 0.3f, &lit);
    EXPECT_EQ(lit.At(0, 8, 8), 1.f);
    EXPECT_NEAR(lit.At(0, 8, 7), lifted, 1e-5);
}

// The frame's noise that gates the coarse pass against its reference: random colours and
// variances, odd sizes and one pixel, a NaN and an infinite variance (sorted last); two
// pixels (the lower median) by hand.
TEST(NforCoarse, RelativeNoiseMatchesTheReference) {
    for (auto [w, h] : {std::pair{31, 17}, std::pair{1, 1}, std::pair{2, 5}, std::pair{16, 16}})
        for (InputKind kind :
             {InputKind::Uniform, InputKind::LogNormalFireflies, InputKind::Constant}) {
            std::string name =
                fmt::format("relative noise {}x{} {}", w, h, InputKindName(kind));
            uint64_t seed = SeedFromName(name);
            Image color = MakeInput(kind, w, h, 3, seed);
            Image variance = MakeVarianceInput(InputKind::Uniform, w, h, 3, seed + 1);
            if (w * h > 4) {
                variance.data[1] = std::numeric_limits<float>::quiet_NaN();
                variance.data[2] = std::numeric_limits<float>::infinity();
            }
            double host = NforRelativeNoise(color, variance);
            double cpu = ref::NforRelativeNoise(color, variance);
            EXPECT_NEAR(host, cpu, 1e-6 * std::abs(cpu)) << name;
            EXPECT_EQ(host, NforRelativeNoise(color, variance)) << name;
        }
    Image color(2, 1, 1), variance(2, 1, 1);
    variance.data = {0.003f, 0.001f};
    EXPECT_NEAR(NforRelativeNoise(color, variance), 0.1, 1e-6);
    EXPECT_NEAR(ref::NforRelativeNoise(color, variance), 0.1, 1e-6);
}

// A frame of few samples: MakeFrame's truth sampled 4 times a pixel, each sample the
// truth / 0.15 with probability 0.15 and else 0 (a dim interior's light, which few paths
// find), so that most pixels and most pairs of neighbours are exactly 0. The colour's
// noise estimate read as a median is then 0 over much of the frame: the firefly clamp takes
// each lit pixel to its neighbours' median and the fits weigh each pixel alone, leaving
// black holes. With the sparse mean (the default) under 5% of the pixels come out below a
// quarter of the truth (a hole) and relMSE is under half; with --no-sparse-noise over 20%.
TEST_F(NforMethod, FewSamplesLeaveNoBlackHoles) {
    const int w = 40, h = 32;
    Frame f = MakeFrame(w, h, 0, "few samples");
    std::mt19937_64 rng(SeedFromName("few samples hits"));
    std::uniform_real_distribution<double> unit(0, 1);
    const double p = 0.15;
    size_t zeros = 0;
    for (size_t i = 0; i < f.truth.PixelCount(); ++i) {
        int hits = 0;
        for (int s = 0; s < 4; ++s) hits += unit(rng) < p;
        zeros += hits == 0;
        for (int c = 0; c < 3; ++c)
            f.color.Plane(c)[i] = float(f.truth.Plane(c)[i] * hits / (4 * p));
    }
    ASSERT_GT(zeros, f.truth.PixelCount() / 2);
    auto holesAndError = [&](bool sparse) {
        NforOptions o;
        o.noSparseNoise = !sparse;
        Image out = NforDenoise(Ctx(), InputsOf(f), o).image;
        size_t holes = 0;
        double error = 0;
        for (size_t i = 0; i < out.PixelCount(); ++i) {
            double lum = 0, truth = 0;
            for (int c = 0; c < 3; ++c) lum += out.Plane(c)[i], truth += f.truth.Plane(c)[i];
            holes += lum < 0.25 * truth;
            error += (lum - truth) * (lum - truth) / (truth * truth + 0.01);
        }
        return std::pair{double(holes) / out.PixelCount(), error / out.PixelCount()};
    };
    auto [holes, error] = holesAndError(true);
    auto [medianHoles, medianError] = holesAndError(false);
    EXPECT_LT(holes, 0.05) << "error " << error;
    EXPECT_GT(medianHoles, 0.2) << "error " << medianError;
    EXPECT_LT(error, 0.5 * medianError);
}

// A frame the coarse pass's gate finds noisy is fitted over --noisy-radius's windows: its
// stages match the reference's (which decides on its own estimate), the output is a run at
// that radius bit for bit and the plan says so; a clean frame keeps the radius. The second
// pass's wide windows, no wider than the noisy radius, are left out there.
TEST_F(NforMethod, NoisyFramesTakeTheNoisyRadius) {
    NforOptions o = SmallWindowOptions();
    o.noisyRadius = 5;
    for (auto [w, h] : {std::pair{29, 23}, std::pair{1, 1}, std::pair{7, 1}})
        ExpectStagesMatch(Ctx(), w, h, o);
    NforOptions atNoisy = o, atRadius = o;
    atNoisy.radius = 5;
    atNoisy.noisyRadius = atRadius.noisyRadius = 0;
    auto plansNoisy = [](const NforResult &r) {
        for (const std::string &line : r.plan)
            if (line.find("windows of 11x11 (--noisy-radius 5") != std::string::npos)
                return true;
        return false;
    };
    for (double noise : {0.6, 0.02}) {
        SCOPED_TRACE(fmt::format("noise {}", noise));
        Frame f = MakeFrame(29, 23, noise, fmt::format("noisy radius {}", noise));
        NforResult run = NforDenoise(Ctx(), InputsOf(f), o);
        const bool noisy = noise > 0.1;
        ASSERT_EQ(run.coarseRan, noisy) << "level " << run.coarseLevel;
        EXPECT_EQ(plansNoisy(run), noisy);
        EXPECT_TRUE(BitIdentical(
            run.image, NforDenoise(Ctx(), InputsOf(f), noisy ? atNoisy : atRadius).image));
        EXPECT_FALSE(BitIdentical(
            run.image, NforDenoise(Ctx(), InputsOf(f), noisy ? atRadius : atNoisy).image));
    }
    Frame f = MakeFrame(29, 23, 0.6, "noisy radius wide");
    NforOptions wide = o;
    wide.pilotWideRadius = 4;
    NforResult run = NforDenoise(Ctx(), InputsOf(f), wide);
    EXPECT_TRUE(BitIdentical(run.image, NforDenoise(Ctx(), InputsOf(f), atNoisy).image));
    bool named = false;
    for (const std::string &line : run.plan)
        named =
            named || line.find("the second pass's 9x9 windows left out") != std::string::npos;
    EXPECT_TRUE(named);
}

// The coarse pass by default: a noisy frame (its own noise estimate relative to relMSE's
// denominator at least --coarse-gate) takes the pass as --nfor-coarse gives it, a clean one
// is left as without it, bit for bit; the level the gate read is the reference's estimate's
// and the same measured in strips of rows.
TEST_F(NforMethod, CoarseGateRunsThePassOnNoisyFramesOnly) {
    NforOptions o;
    o.radius = 3;
    NforOptions always = o, never = o;
    always.coarse = true;
    never.coarseGate = 0;
    const int w = 29, h = 23;
    for (double noise : {0.6, 0.02}) {
        SCOPED_TRACE(fmt::format("noise {}", noise));
        Frame f = MakeFrame(w, h, noise, fmt::format("coarse gate {}", noise));
        double expected = ref::NforRelativeNoise(
            f.color, ref::NforNoise(f.color, &f.albedo, o.noiseRadius, o.noiseCalibration,
                                    false, !o.noSparseNoise));
        const bool noisy = noise > 0.1;
        ASSERT_EQ(expected >= o.coarseGate, noisy) << "level " << expected;
        NforResult gated = NforDenoise(Ctx(), InputsOf(f), o);
        EXPECT_NEAR(gated.coarseLevel, expected, 1e-4 * expected);
        EXPECT_EQ(gated.coarseRan, noisy);
        EXPECT_TRUE(BitIdentical(
            gated.image, NforDenoise(Ctx(), InputsOf(f), noisy ? always : never).image));
        EXPECT_FALSE(BitIdentical(
            gated.image, NforDenoise(Ctx(), InputsOf(f), noisy ? never : always).image));
        for (int strip : {w, 3 * w + 5})
            EXPECT_EQ(NforCoarseLevel(Ctx(), InputsOf(f), o, strip), gated.coarseLevel)
                << "strips of " << strip << " pixels";
    }
}

// The coarse gate's level on a frame whose every pixel is half covered (alpha 0.5, colour
// and features premultiplied) is read on the frame divided by alpha, as the run reads it:
// NforCoarseLevel (what tiles read) gives the run's level bit for bit, the reference's on
// the straight frame, and not the premultiplied frame's.
TEST_F(NforMethod, CoarseGateReadsTheFrameDividedByAlpha) {
    NforOptions o;
    o.radius = 3;
    const int w = 29, h = 23;
    Frame f = MakeFrame(w, h, 0.3, "coarse gate alpha");
    Image alpha(w, h, 1, 0.5f);
    for (Image *layer : {&f.color, &f.albedo, &f.normal, &f.depth})
        for (float &v : layer->data) v *= 0.5f;
    Image straight = ref::NforStraight(f.color, alpha, 1),
          straightAlbedo = ref::NforStraight(f.albedo, alpha, 1);
    double expected = ref::NforRelativeNoise(
        straight, ref::NforNoise(straight, &straightAlbedo, o.noiseRadius, o.noiseCalibration,
                                 false, !o.noSparseNoise));
    NforInputs in = InputsOf(f);
    in.alpha = &alpha;
    NforResult run = NforDenoise(Ctx(), in, o);
    ASSERT_GT(run.partlyCovered, 0u);
    EXPECT_NEAR(run.coarseLevel, expected, 1e-4 * expected);
    for (int strip : {w, 3 * w + 5, 1 << 22})
        EXPECT_EQ(NforCoarseLevel(Ctx(), in, o, strip), run.coarseLevel)
            << "strips of " << strip << " pixels";
    NforOptions premultiplied = o;
    premultiplied.premultiplied = true;
    double asWritten = NforCoarseLevel(Ctx(), in, premultiplied);
    EXPECT_GT(std::abs(asWritten - expected), 1e-2 * expected)
        << "the premultiplied frame reads another level: " << asWritten;
}

// The kept pixels' mean against its reference: outputs that equal the input at random
// pixels (some beside moved ones, some not), a few emitters (weak ones smoothed or not), a
// NaN among the neighbours, the kept pixels smoothed or only the weak emitters; odd sizes
// and 1x1; two runs bit-identical.
TEST(NforKept, MatchesTheReferenceAndRepeats) {
    for (auto [w, h] : {std::pair{31, 17}, std::pair{1, 1}, std::pair{2, 5}, std::pair{16, 16}})
        for (InputKind kind :
             {InputKind::Uniform, InputKind::LogNormalFireflies, InputKind::Constant})
            for (auto [weak, keptPixels, line] :
                 {std::tuple{0.f, true, 0.f}, std::tuple{1.8f, true, 0.f},
                  std::tuple{1.8f, false, 0.f}, std::tuple{1.8f, false, 0.3f},
                  std::tuple{1.8f, true, 1.f}}) {
                std::string name = fmt::format("kept {}x{} {} weak {} kept pixels {}", w, h,
                                               InputKindName(kind), weak, keptPixels);
                if (line > 0) name += fmt::format(" line {}", line);
                uint64_t seed = SeedFromName(name);
                std::mt19937 random{uint32_t(seed)};
                Image input = MakeInput(kind, w, h, 3, seed), output = input;
                Image features = MakeVarianceInput(InputKind::Uniform, w, h, 7, seed + 1);
                Image albedo(w, h, 3);
                std::copy(features.data.begin(), features.data.begin() + albedo.Size(),
                          albedo.data.begin());
                Image mask(w, h, 1, 1.f);
                for (int y = 0; y < h; ++y)
                    for (int x = 0; x < w; ++x) {
                        if (random() % 2)
                            for (int c = 0; c < 3; ++c) output.At(c, y, x) *= 0.9f;
                        if (random() % 5 == 0) {
                            mask.At(0, y, x) = 0;
                            albedo.At(0, y, x) = random() % 2 ? 1.6f : 2.5f;
                        }
                    }
                if (w * h > 4) output.At(1, h / 2, w / 2 + 1) = std::nanf("");
                std::vector<float> s = {3.3f, 3.3f, 3.3f, 1.7f, 1.7f, 1.7f, 6.7f};
                std::vector<double> sd(s.begin(), s.end());
                NforKeptSettings k{2, weak, &albedo, 3, keptPixels, line, 0.5f};
                Image host = output, again = output, cpu = output;
                NforSmoothKept(input, features, s, mask, k, &host);
                NforSmoothKept(input, features, s, mask, k, &again);
                ref::NforSmoothKept(input, features, sd, mask, 2, weak, &albedo, 3, &cpu,
                                    keptPixels, line, 0.5);
                EXPECT_TRUE(ImagesMatch(cpu, host, {}, {1e-5, 0, 1e-7})) << name;
                EXPECT_EQ(0, std::memcmp(host.data.data(), again.data.data(),
                                         host.data.size() * sizeof(float)))
                    << name;
            }
}

// Only a pixel the fits left beside one they moved takes the mean: of its neighbours of
// like features (a silhouette's edge line), not of those unlike it nor of emitters. A frame
// reproduced everywhere (noise-free) is left.
TEST(NforKept, SmoothsOnlyPixelsTheFitsLeft) {
    int w = 9, h = 9;
    Image input(w, h, 3, 1.f), features(w, h, 1, 0.f), mask(w, h, 1, 1.f);
    std::vector<float> s = {10.f};
    Image reproduced = input;
    EXPECT_EQ(NforSmoothKept(input, features, s, mask, NforKeptSettings{}, &reproduced), 0u);
    EXPECT_EQ(reproduced.data, input.data);
    // Column 4 an edge line (feature 1) whose centre the fits left at 3; the rest moved.
    Image output(w, h, 3, 0.5f);
    for (int y = 0; y < h; ++y) {
        features.At(0, y, 4) = 1.f;
        for (int c = 0; c < 3; ++c) output.At(c, y, 4) = 2.f;
    }
    for (int c = 0; c < 3; ++c) input.At(c, 4, 4) = output.At(c, 4, 4) = 3.f;
    mask.At(0, 3, 4) = 0;  // an emitter on the line: left out of the mean
    Image smoothed = output;
    EXPECT_EQ(NforSmoothKept(input, features, s, mask, NforKeptSettings{}, &smoothed), 1u);
    // Weights along the line: exp(-dy^2 / 2) at dy = 1 (below only), 2 (both), 0 (itself).
    double e1 = std::exp(-0.5), e2 = std::exp(-2.0);
    double expected = (3 + 2 * e1 + 2 * 2 * e2) / (1 + e1 + 2 * e2);
    EXPECT_NEAR(smoothed.At(0, 4, 4), expected, 1e-3);  // unlike neighbours weigh e^-100
    for (size_t i = 0; i < output.PixelCount(); ++i)
        if (i != size_t(4 * w + 4)) {
            EXPECT_EQ(smoothed.data[i], output.data[i]);
        }
    EXPECT_EQ(NforSmoothKept(input, features, s, mask, NforKeptSettings{0}, &output), 0u);
    // The emitter on the line, weak (albedo below 2), is smoothed too, over the pixels
    // around it whatever their albedo (one plane here: none compared), the centre included.
    Image albedo(w, h, 3, 1.8f), weak = output;
    NforKeptSettings k{2, 2.f, &albedo, 1};
    EXPECT_EQ(NforSmoothKept(input, features, s, mask, k, &weak), 2u);
    EXPECT_NE(weak.At(0, 3, 4), output.At(0, 3, 4));
    EXPECT_LT(weak.At(0, 3, 4), 2.f);
    // Weak emitters alone (nfor's default): the emitter changes as above, the kept pixel
    // keeps its input.
    Image onlyWeak = output;
    k.keptPixels = false;
    EXPECT_EQ(NforSmoothKept(input, features, s, mask, k, &onlyWeak), 1u);
    EXPECT_EQ(onlyWeak.At(0, 3, 4), weak.At(0, 3, 4));
    EXPECT_EQ(onlyWeak.At(0, 4, 4), 3.f);
}

// A glossy highlight's streak two pixels wide on a darker surface of the same features,
// drawn by few samples (motion_blur's pendulum, issue 29): its pixels whose albedo reads the
// reflected light are weak emitters, and the 5x5 mean took the dark rows above and below
// into each, half the streak's light. On a line (a pixel at least lineRatio x as bright on
// both sides) the mean weighs its pixels by their brightness too: the streak keeps its
// light. Its ends and a lone weak emitter on the dark ground are on no line and are
// smoothed as before; lineRatio 0 is the pass as before, bit for bit.
TEST(NforKept, WeakEmittersOnABrightLineKeepTheirLight) {
    const int w = 21, h = 9;
    Image input(w, h, 3, 0.5f), features(w, h, 1, 0.f), mask(w, h, 1, 1.f),
        albedo(w, h, 3, 0.5f);
    // Rows 4 and 5, columns 5-15: noisy hits around 3.5, every one an emitter of albedo 2-4.
    const float hits[11] = {2.f, 5.f, 3.f, 4.5f, 2.5f, 3.5f, 5.f, 2.f, 4.f, 3.f, 2.5f};
    for (int y = 4; y <= 5; ++y)
        for (int x = 5; x <= 15; ++x) {
            float v = hits[(x - 5 + 3 * (y - 4)) % 11];
            for (int c = 0; c < 3; ++c) {
                input.At(c, y, x) = v;
                albedo.At(c, y, x) = 0.8f * v;
            }
            mask.At(0, y, x) = 0;
        }
    // A lone weak emitter on the ground.
    for (int c = 0; c < 3; ++c) {
        input.At(c, 1, 2) = 3.f;
        albedo.At(c, 1, 2) = 2.f;
    }
    mask.At(0, 1, 2) = 0;
    std::vector<float> s = {10.f};
    auto streak = [&](const Image &image) {
        double sum = 0;
        for (int y = 4; y <= 5; ++y)
            for (int x = 5; x <= 15; ++x) sum += image.At(0, y, x);
        return sum;
    };
    NforKeptSettings before{2, 8.f, &albedo, 1, false};
    Image off = input;
    EXPECT_EQ(NforSmoothKept(input, features, s, mask, before, &off), 23u);
    NforKeptSettings line = before;
    line.lineRatio = 0.3f;
    Image on = input;
    EXPECT_EQ(NforSmoothKept(input, features, s, mask, line, &on), 23u);
    const double light = streak(input);
    EXPECT_LT(streak(off), 0.75 * light);  // the mean with the dark ground
    EXPECT_GT(streak(on), 0.9 * light);
    EXPECT_LT(streak(on), 1.02 * light);
    // Smoother than the hits: the largest and smallest come closer to the streak's mean.
    for (int y = 4; y <= 5; ++y)
        for (int x = 6; x <= 14; ++x) {
            EXPECT_GE(on.At(0, y, x), 2.f) << x << "," << y;
            EXPECT_LE(on.At(0, y, x), 5.f) << x << "," << y;
        }
    // The ends (a pixel as bright on one side only) and the lone one: as before.
    for (auto [x, y] : {std::pair{5, 4}, std::pair{15, 5}, std::pair{2, 1}})
        EXPECT_EQ(on.At(0, y, x), off.At(0, y, x)) << x << "," << y;
    EXPECT_TRUE(NforWeakEmitterOnLine(input, 0.3f, 10, 4));
    EXPECT_FALSE(NforWeakEmitterOnLine(input, 0.3f, 2, 1));
    EXPECT_FALSE(NforWeakEmitterOnLine(input, 0.f, 10, 4));
    // The CPU reference agrees.
    Image cpu = input;
    ref::NforSmoothKept(input, features, {10.0}, mask, 2, 8.0, &albedo, 1, &cpu, false, 0.3,
                        line.lineRange);
    EXPECT_TRUE(ImagesMatch(cpu, on, {}, {1e-5, 0, 1e-7}));
}

// A pass that moves light between pixels: each channel's sum over the finite values of
// `before` kept in `after` to round-off, and the pixels `alpha` marks empty (0 or NaN) left
// with their bits.
void ExpectLightOnlyMoved(const Image &before, const Image &after, const Image *alpha,
                          const std::string &name) {
    for (int c = 0; c < before.channels; ++c) {
        double sumBefore = 0, sumAfter = 0, scale = 0;
        for (size_t p = 0; p < before.PixelCount(); ++p)
            if (std::isfinite(before.Plane(c)[p])) {
                sumBefore += before.Plane(c)[p], sumAfter += after.Plane(c)[p];
                scale += std::abs(before.Plane(c)[p]);
            }
        EXPECT_NEAR(sumAfter, sumBefore, 1e-6 * scale + 1e-12) << name << " channel " << c;
    }
    if (!alpha) return;
    for (size_t i = 0; i < after.Size(); ++i)
        if (!(alpha->data[i % after.PixelCount()] > 0.f)) {
            EXPECT_EQ(std::memcmp(&after.data[i], &before.data[i], sizeof(float)), 0)
                << name << " value " << i;
        }
}

// The lights' spread against its reference: values of every kind, emitters weak and
// strong scattered (some side by side), a non-finite value, frames of one pixel, one row,
// 3x3 and 31x17; the same pixels change, to round-off; some do; each channel's sum over the
// frame is kept (light only moves); a rerun is bit-identical.
TEST(NforLights, MatchesTheReferenceAndRepeats) {
    size_t gave = 0;
    for (auto [w, h] : {std::pair{31, 17}, std::pair{1, 1}, std::pair{9, 1}, std::pair{3, 3}})
        for (InputKind kind : {InputKind::Uniform, InputKind::LogNormalFireflies,
                               InputKind::Constant, InputKind::Impulse}) {
            std::string name = fmt::format("lights {}x{} {}", w, h, InputKindName(kind));
            uint64_t seed = SeedFromName(name);
            std::mt19937 random{uint32_t(seed)};
            Image input = MakeVarianceInput(kind, w, h, 3, seed);
            Image albedo = MakeVarianceInput(InputKind::Uniform, w, h, 3, seed + 1);
            for (size_t p = 0; p < input.PixelCount(); ++p) {
                int draw = int(random() % 6);
                // One channel above the threshold makes an emitter: weak, then strong.
                if (draw == 0) albedo.Plane(int(random() % 3))[p] = 3.f;
                if (draw == 1) albedo.Plane(int(random() % 3))[p] = 40.f;
            }
            if (w * h > 9) {
                albedo.At(0, 1, 1) = 40.f;
                input.At(2, 1, 1) = std::nanf("");
            }
            // Every other frame with an alpha whose zeros (and a NaN) take no part.
            Image alpha(w, h, 1, 1.f);
            const bool withAlpha = kind == InputKind::Uniform || kind == InputKind::Impulse;
            for (float &a : alpha.data) a = random() % 4 == 0 ? 0.f : random() % 2 ? 1.f : 0.5f;
            if (w * h > 9) alpha.At(0, 2, 2) = std::nanf("");
            NforLightSettings s{1.5f, 8.f, 0.08f, 0.004f};
            Image host = input, again = input, cpu = input;
            const Image *a = withAlpha ? &alpha : nullptr;
            size_t count = NforSpreadLights(albedo, a, s, &host);
            EXPECT_EQ(NforSpreadLights(albedo, a, s, &again), count);
            ref::NforSpreadLights(albedo, a, 1.5, 8, 0.08, 0.004, &cpu);
            EXPECT_TRUE(ImagesMatch(cpu, host, {}, {4 * kU, 0, 1e-12})) << name;
            EXPECT_TRUE(BitIdentical(host, again)) << name;
            ExpectLightOnlyMoved(input, host, withAlpha ? &alpha : nullptr, name);
            gave += count;
        }
    EXPECT_GT(gave, 0u);
}

// A 7x7 dim frame with a light's 3x3 core (albedo and colour 320) and, beside it, a pixel one
// of 16 samples hit (20) and one four hit (80): at core ratio 8 the first comes down to the
// geometric mean of its input and its ground's (0.04), the six core pixels within 2 of it
// share what it lost; the second, a quarter covered, stays; ratio 0 changes nothing.
TEST(NforRimHits, ARimHitComesDownToItsGround) {
    Image albedo(7, 7, 3, 0.5f), color(7, 7, 3, 0.04f);
    for (int y = 2; y <= 4; ++y)
        for (int x = 1; x <= 3; ++x)
            for (int c = 0; c < 3; ++c) albedo.At(c, y, x) = color.At(c, y, x) = 320.f;
    for (int c = 0; c < 3; ++c) {
        albedo.At(c, 3, 4) = color.At(c, 3, 4) = 20.f;
        albedo.At(c, 5, 2) = color.At(c, 5, 2) = 80.f;
    }
    NforRimSettings s;
    s.coreRatio = 8;
    Image out = color;
    EXPECT_EQ(NforFoldRimHits(color, albedo, nullptr, s, &out), 1u);
    const double kept = std::sqrt(0.04 * 20.0);
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(out.At(c, 3, 4), kept, 1e-5);
        EXPECT_EQ(out.At(c, 5, 2), 80.f);
        for (int y = 2; y <= 4; ++y)
            for (int x = 1; x <= 3; ++x)
                EXPECT_NEAR(out.At(c, y, x), x >= 2 ? 320 + (20 - kept) / 6 : 320, 1e-3)
                    << x << "," << y;
    }
    s.coreRatio = 0;
    Image off = color;
    EXPECT_EQ(NforFoldRimHits(color, albedo, nullptr, s, &off), 0u);
    EXPECT_TRUE(BitIdentical(off, color));
    EXPECT_EQ(NforRimRatio(16, 2), 8.f);
    EXPECT_EQ(NforRimRatio(8, 2), 4.f);
    EXPECT_EQ(NforRimRatio(4, 2), 0.f);
    EXPECT_EQ(NforRimRatio(0, 2), 0.f);
    EXPECT_EQ(NforRimRatio(16, 0), 0.f);
}

// The rim hits against their reference: lights of several cores with rims of one to four
// hits' share scattered on frames of every input kind, a transparent pixel, a NaN output,
// frames of one pixel, one row, 3x3 and 31x17; the same values to round-off, each channel's
// sum kept (light only moves), transparent pixels untouched, a rerun bit-identical.
TEST(NforRimHits, MatchesTheReferenceAndKeepsTheLight) {
    size_t folded = 0;
    for (auto [w, h] : {std::pair{31, 17}, std::pair{1, 1}, std::pair{9, 1}, std::pair{3, 3}})
        for (InputKind kind : {InputKind::Uniform, InputKind::LogNormalFireflies,
                               InputKind::Constant, InputKind::Impulse}) {
            std::string name = fmt::format("rim {}x{} {}", w, h, InputKindName(kind));
            uint64_t seed = SeedFromName(name);
            std::mt19937 random{uint32_t(seed)};
            Image output = MakeVarianceInput(kind, w, h, 3, seed);
            Image color = MakeVarianceInput(kind, w, h, 3, seed + 2);
            Image albedo = MakeVarianceInput(InputKind::Uniform, w, h, 3, seed + 1);
            for (size_t p = 0; p < output.PixelCount(); ++p) {
                // A core of 300 to 400, or a rim of 1 to 4 sixteenths of 320, read as lit.
                int draw = int(random() % 5);
                float level = draw == 0   ? 300.f + float(random() % 100)
                              : draw == 1 ? 20.f * float(1 + random() % 4)
                                          : 0.f;
                if (level == 0) continue;
                for (int c = 0; c < 3; ++c) {
                    albedo.Plane(c)[p] = level * (c == 2 ? 0.7f : 1.f);
                    output.Plane(c)[p] = color.Plane(c)[p] = level * (0.9f + 0.1f * float(c));
                }
            }
            if (w * h > 9) output.At(1, 1, 1) = std::nanf("");
            Image alpha(w, h, 1, 1.f);
            const bool withAlpha = kind == InputKind::Uniform || kind == InputKind::Impulse;
            for (float &a : alpha.data) a = random() % 5 == 0 ? 0.f : 1.f;
            const Image *a = withAlpha ? &alpha : nullptr;
            NforRimSettings s;
            s.coreRatio = 8;
            Image host = output, again = output, cpu = output;
            size_t count = NforFoldRimHits(color, albedo, a, s, &host);
            EXPECT_EQ(NforFoldRimHits(color, albedo, a, s, &again), count);
            ref::NforFoldRimHits(color, albedo, a, 1.5, 8, 2, &cpu);
            EXPECT_TRUE(ImagesMatch(cpu, host, {}, {16 * kU, 0, 1e-9})) << name;
            EXPECT_TRUE(BitIdentical(host, again)) << name;
            ExpectLightOnlyMoved(output, host, withAlpha ? &alpha : nullptr, name);
            folded += count;
        }
    EXPECT_GT(folded, 0u);
}

// nfor's defaults on a plain frame: a bright light (a 3x3 block of strong emitters) in a
// dim frame gives its 4-neighbours outside the block a share of its light, which they lack
// with --light-share 0 (the frame's sum kept, the block's corner-diagonal pixels as they
// were); a weak emitter gives its neighbours a larger share. Beside a variance layer read as
// the noise the same (the clamp reads the frame's own estimate); with --no-layer-passes the
// light shares change nothing, bit for bit. The glint bands (the block is a glint too) are
// left out of both runs: the lights' shares alone are measured.
TEST_F(NforMethod, DefaultsSpreadALightsRim) {
    Frame f = MakeFrame(24, 20, 0.05, "light rim");
    for (int y = 8; y <= 10; ++y)
        for (int x = 10; x <= 12; ++x)
            for (int c = 0; c < 3; ++c) f.albedo.At(c, y, x) = f.color.At(c, y, x) = 300.f;
    for (int c = 0; c < 3; ++c) f.albedo.At(c, 4, 4) = f.color.At(c, 4, 4) = 3.f;
    NforOptions defaults, off;
    defaults.glintBandRadius = off.glintBandRadius = 0;
    off.weakLightShare = off.lightShare = 0;
    NforResult a = NforDenoise(Ctx(), InputsOf(f), defaults);
    NforResult b = NforDenoise(Ctx(), InputsOf(f), off);
    EXPECT_EQ(a.lights, 9u);  // the block but its centre, and the weak one
    EXPECT_EQ(b.lights, 0u);
    for (int x = 10; x <= 12; ++x) {
        EXPECT_NEAR(a.image.At(0, 7, x) - b.image.At(0, 7, x), 0.004 * 300, 0.01) << x;
        EXPECT_NEAR(a.image.At(0, 11, x) - b.image.At(0, 11, x), 0.004 * 300, 0.01) << x;
    }
    EXPECT_EQ(a.image.At(0, 7, 9), b.image.At(0, 7, 9));
    EXPECT_NEAR(a.image.At(0, 8, 10), b.image.At(0, 8, 10) * (1 - 2 * 0.004), 1e-3);
    EXPECT_GT(a.image.At(0, 4, 5) - b.image.At(0, 4, 5), 0.05 * b.image.At(0, 4, 4));
    for (int c = 0; c < 3; ++c) {
        double sumA = 0, sumB = 0;
        for (size_t p = 0; p < a.image.PixelCount(); ++p)
            sumA += a.image.Plane(c)[p], sumB += b.image.Plane(c)[p];
        EXPECT_NEAR(sumA / sumB, 1.0, 1e-6) << c;
    }
    Image variance(f.color.width, f.color.height, 3, 0.01f);
    NforInputs layered = InputsOf(f);
    layered.variance = &variance;
    // Beside a layer the same (the clamp reads the frame's own estimate); with
    // --no-layer-passes the lights keep theirs.
    NforResult c = NforDenoise(Ctx(), layered, defaults), d = NforDenoise(Ctx(), layered, off);
    EXPECT_EQ(c.lights, 9u);
    EXPECT_EQ(d.lights, 0u);
    EXPECT_GT(c.image.At(0, 7, 11), d.image.At(0, 7, 11) + 0.5);
    NforOptions noPasses = defaults, noPassesOff = off;
    noPasses.noLayerPasses = noPassesOff.noLayerPasses = true;
    NforResult e = NforDenoise(Ctx(), layered, noPasses);
    NforResult g = NforDenoise(Ctx(), layered, noPassesOff);
    EXPECT_EQ(e.lights, 0u);
    EXPECT_TRUE(BitIdentical(e.image, g.image));
    EXPECT_GT(c.image.At(0, 7, 11), e.image.At(0, 7, 11) + 0.5);
}

// A light beside a transparent film's background (alpha 0, which the frame's colour
// replaces after the method): the lights' spread gives it nothing, so the frame's light
// stays through the whole run, as without the background (the glint bands left out: the
// light is a glint).
TEST(NforMethodAlpha, LightsSpreadKeepsTheLightBesideATransparentBackground) {
    const int w = 16, h = 16;
    Frame f = MakeFrame(w, h, 0.05, "light beside alpha 0");
    Image alpha(w, h, 1, 1.f);
    for (int y = 6; y <= 8; ++y)
        for (int x = 6; x <= 8; ++x)
            for (int c = 0; c < 3; ++c) f.albedo.At(c, y, x) = f.color.At(c, y, x) = 300.f;
    for (int y = 0; y < h; ++y)
        for (int x = 9; x < w; ++x) {
            alpha.At(0, y, x) = 0;
            for (int c = 0; c < 3; ++c) f.color.At(c, y, x) = 0;
        }
    mcd::Frame frame;
    frame.width = w;
    frame.height = h;
    frame.layers = {{"color", f.color},
                    {"albedo", f.albedo},
                    {"normal", f.normal},
                    {"depth", f.depth},
                    {"alpha", alpha}};
    Device device;
    Method method("nfor");
    method.Set("glint-band-radius", 0);
    Result a = method.Run(device, frame);
    method.Set("light-share", 0.f);
    method.Set("weak-light-share", 0.f);
    Result b = method.Run(device, frame);
    double sumA = 0, sumB = 0;
    for (size_t p = 0; p < a.image.PixelCount(); ++p)
        sumA += a.image.Plane(0)[p], sumB += b.image.Plane(0)[p];
    EXPECT_NEAR(sumA, sumB, 1e-6 * sumB);
    EXPECT_GT(a.image.At(0, 5, 7), b.image.At(0, 5, 7));
}

// nfor's defaults on a plain frame (no variance layer): a light's partly covered pixels
// (emitters of weak albedo, a 3x3 block, one of them seen by more samples than the rest)
// take the output's mean around them; with --weak-emitter-albedo 0 they keep their input.
// Nothing else changes.
TEST_F(NforMethod, DefaultsSmoothWeakEmittersOfPlainFrames) {
    Frame f = MakeFrame(24, 20, 0.2, "weak emitter");
    int w = f.color.width;
    auto inBlock = [](int x, int y) { return x >= 10 && x <= 12 && y >= 8 && y <= 10; };
    for (int y = 8; y <= 10; ++y)
        for (int x = 10; x <= 12; ++x)
            for (int c = 0; c < 3; ++c) {
                f.albedo.At(c, y, x) = 2.f;
                f.color.At(c, y, x) = x == 11 && y == 9 ? 4.f : 3.f;
            }
    NforOptions defaults, off;
    // The lights' spread (its own test) would move the block's neighbours in both.
    defaults.weakLightShare = defaults.lightShare = 0;
    off.weakEmitterAlbedo = 0;
    off.weakLightShare = off.lightShare = 0;
    Image a = NforDenoise(Ctx(), InputsOf(f), defaults).image;
    Image b = NforDenoise(Ctx(), InputsOf(f), off).image;
    EXPECT_EQ(b.At(0, 9, 11), 4.f);
    EXPECT_EQ(b.At(0, 8, 10), 3.f);
    EXPECT_LT(a.At(0, 9, 11), 3.9f);
    for (size_t i = 0; i < a.data.size(); ++i) {
        size_t p = i % a.PixelCount();
        if (inBlock(int(p % w), int(p / w)))
            EXPECT_NE(a.data[i], b.data[i]) << p;
        else
            EXPECT_EQ(a.data[i], b.data[i]) << p;
    }
}

// By default a weak emitters' streak two pixels wide (a glossy highlight whose albedo reads
// the reflected light, motion_blur's pendulum: issue 29) keeps its light: its pixels average
// along it, not with the dark ground above and below (--weak-emitter-line 0: as before).
TEST_F(NforMethod, DefaultsKeepAWeakEmittersStreaksLight) {
    Frame f = MakeFrame(32, 20, 0.2, "weak emitter streak");
    const float hits[7] = {2.f, 5.f, 3.f, 4.5f, 2.5f, 3.5f, 4.f};
    double light = 0;
    for (int y = 9; y <= 10; ++y)
        for (int x = 8; x <= 23; ++x)
            for (int c = 0; c < 3; ++c) {
                f.albedo.At(c, y, x) = 2.f;
                f.color.At(c, y, x) = hits[(x + 2 * y) % 7];
                light += f.color.At(c, y, x);
            }
    NforOptions defaults, off;
    defaults.weakLightShare = defaults.lightShare = 0;
    off.weakEmitterLine = 0;
    off.weakLightShare = off.lightShare = 0;
    EXPECT_GT(defaults.weakEmitterLine, 0.f);
    auto streak = [](const Image &image) {
        double sum = 0;
        for (int y = 9; y <= 10; ++y)
            for (int x = 8; x <= 23; ++x)
                for (int c = 0; c < 3; ++c) sum += image.At(c, y, x);
        return sum;
    };
    double kept = streak(NforDenoise(Ctx(), InputsOf(f), defaults).image);
    double before = streak(NforDenoise(Ctx(), InputsOf(f), off).image);
    EXPECT_LT(before, 0.8 * light);
    EXPECT_GT(kept, 0.9 * light);
    EXPECT_LT(kept, 1.02 * light);
}

TEST_F(NforMethod, RerunsAreBitIdentical) {
    Frame f = MakeFrame(33, 21, 0.4, "rerun");
    NforOptions o;
    o.radius = 4;
    EXPECT_TRUE(BitIdentical(NforDenoise(Ctx(), InputsOf(f), o).image,
                             NforDenoise(Ctx(), InputsOf(f), o).image));
}

// A first-order fit reproduces what is first order in its columns: a colour that is a
// plane in screen position times the albedo... here a plane in the position plus a linear
// function of the albedo, noise-free, comes back to float round-off of the fit.
TEST_F(NforMethod, KeepsAnImageLinearInItsColumns) {
    int w = 31, h = 25;
    Frame f = MakeFrame(w, h, 0, "linear");
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                f.color.At(c, y, x) =
                    float(0.3 + 0.01 * x - 0.004 * y + 0.8 * f.albedo.At(c, y, x));
    NforOptions o;
    o.ridge = 1e-4f;  // the ridge pulls the slopes: as little as allowed
    o.fireflyThreshold = 0;
    Image out = NforDenoise(Ctx(), InputsOf(f), o).image;
    EXPECT_TRUE(ImagesMatch(f.color, out, {}, {2e-3, 0, 1e-6}));
}

// Features that do not vary (constant albedo, zero normals, constant depth) leave the
// normal equations rank-deficient but for the ridge: the output is finite and denoised.
TEST_F(NforMethod, RankDeficientFeaturesDoNotBlowUp) {
    int w = 30, h = 24;
    Frame f = MakeFrame(w, h, 0.3, "rank");
    for (float &v : f.albedo.data) v = 0.5f;
    for (float &v : f.normal.data) v = 0.f;
    for (float &v : f.depth.data) v = 3.f;
    for (int c = 0; c < 3; ++c)
        for (size_t i = 0; i < f.truth.PixelCount(); ++i) {
            f.truth.Plane(c)[i] = 0.4f;
        }
    std::mt19937_64 rng(SeedFromName("rank noise"));
    std::normal_distribution<float> normal(0.f, 0.1f);
    for (float &v : f.color.data) v = 0.4f + normal(rng);
    NforResult r = NforDenoise(Ctx(), InputsOf(f), {});
    for (float v : r.image.data) ASSERT_TRUE(std::isfinite(v));
    double before = CompareImages(f.color, f.truth).relMse;
    double after = CompareImages(r.image, f.truth).relMse;
    EXPECT_LT(after, 0.2 * before) << before << " -> " << after;
}

// Emitters (albedo above the threshold) keep their input bits where their neighbours are
// emitters alike (a light's inside); a lone emitter pixel far above all around it (a
// sub-pixel light hit by a few samples) is clamped like a firefly, and kept with
// --firefly-lone-light at or below its albedo (its colour is its albedo: seen directly);
// every pixel of a 1x1 frame keeps its input; odd and one-pixel-wide frames give finite
// output. The lights' spread, which moves a light's edge, is off here (its own test).
TEST_F(NforMethod, EmittersKeepTheirInputAndTinyFramesRun) {
    NforOptions o;
    o.weakLightShare = o.lightShare = 0;
    for (auto [w, h] : {std::pair{1, 1}, std::pair{1, 13}, std::pair{17, 1}, std::pair{9, 7}}) {
        Frame f = MakeFrame(w, h, 0.5, fmt::format("emit{}x{}", w, h));
        int x0 = std::max(0, w / 2 - 1), x1 = std::min(w - 1, w / 2 + 1);
        int y0 = std::max(0, h / 2 - 1), y1 = std::min(h - 1, h / 2 + 1);
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x)
                for (int c = 0; c < 3; ++c) f.albedo.At(c, y, x) = f.color.At(c, y, x) = 12;
        NforResult r = NforDenoise(Ctx(), InputsOf(f), o);
        for (float v : r.image.data) ASSERT_TRUE(std::isfinite(v));
        EXPECT_EQ(r.emitters, size_t(x1 - x0 + 1) * (y1 - y0 + 1));
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x)
                for (int c = 0; c < 3; ++c) EXPECT_EQ(r.image.At(c, y, x), 12.f);
        if (w * h == 1) {
            EXPECT_TRUE(BitIdentical(r.image, f.color));
        }
    }
    // A lone light seen directly: kept by default, clamped with the rule off.
    Frame f = MakeFrame(9, 9, 0.1, "lone emitter");
    for (int c = 0; c < 3; ++c) f.albedo.At(c, 4, 4) = f.color.At(c, 4, 4) = 40;
    NforResult r = NforDenoise(Ctx(), InputsOf(f), o);
    EXPECT_EQ(r.emitters, 1u);
    for (int c = 0; c < 3; ++c) EXPECT_EQ(r.image.At(c, 4, 4), 40.f) << "channel " << c;
    o.fireflyLoneLight = 0;
    EXPECT_LT(NforDenoise(Ctx(), InputsOf(f), o).image.At(0, 4, 4), 2.f);
    o.fireflyLoneLight = 8;
    r = NforDenoise(Ctx(), InputsOf(f), o);
    for (int c = 0; c < 3; ++c) EXPECT_EQ(r.image.At(c, 4, 4), 40.f) << "channel " << c;
    o.fireflyLoneLight = 41;
    EXPECT_LT(NforDenoise(Ctx(), InputsOf(f), o).image.At(0, 4, 4), 2.f);
}

// A firefly (one value 1000x its neighbours) is clamped: the output there is near the
// truth, and its neighbours do not take its energy.
TEST_F(NforMethod, ClampsAFirefly) {
    Frame f = MakeFrame(25, 25, 0.1, "firefly");
    f.color.At(1, 12, 12) *= 1000;
    NforResult r = NforDenoise(Ctx(), InputsOf(f), {});
    EXPECT_GE(r.clamped, 1u);
    for (int y = 10; y <= 14; ++y)
        for (int x = 10; x <= 14; ++x)
            EXPECT_LT(std::fabs(r.image.At(1, y, x) - f.truth.At(1, y, x)),
                      0.5 * f.truth.At(1, y, x) + 0.05)
                << x << ", " << y;
}

// A firefly whose few samples report its own variance in the layer (as a sample variance
// does) is clamped all the same: the clamp reads the frame's own estimate, and the firefly
// alone, though it holds 8% of the frame's light, does not count as the frame's light
// (kClampLossMinShare). Against the layer (--clamp-layer) the threshold is sigmas of the
// firefly itself, and it stays.
TEST_F(NforMethod, ClampsAFireflyTheVarianceLayerHides) {
    Frame f = MakeFrame(64, 64, 0.1, "firefly layer");
    Image variance(64, 64, 3);
    for (size_t i = 0; i < variance.Size(); ++i)
        variance.data[i] = float(std::pow(0.1 * f.truth.data[i], 2));
    float &firefly = f.color.At(1, 32, 32);
    firefly *= 1000;
    // One sample of 16 carried it all: the sample variance of the mean is about its square.
    variance.At(1, 32, 32) = firefly * firefly / 16;
    NforInputs in = InputsOf(f);
    in.variance = &variance;
    NforResult r = NforDenoise(Ctx(), in, {});
    EXPECT_GE(r.clamped, 1u);
    // It holds much of the frame's light, but alone: not the frame's own light.
    EXPECT_FALSE(r.clampOnLayer);
    // Its neighbours do not take its energy; it keeps at most about the clamp's limit (the
    // weights still read its variance from the layer, which lets it weigh little).
    for (int y = 30; y <= 34; ++y)
        for (int x = 30; x <= 34; ++x)
            EXPECT_LT(std::fabs(r.image.At(1, y, x) - f.truth.At(1, y, x)),
                      (x == 32 && y == 32 ? 2 : 0.5) * f.truth.At(1, y, x) + 0.05)
                << x << ", " << y;
    NforOptions layer;
    layer.clampLayer = true;
    EXPECT_EQ(NforDenoise(Ctx(), in, layer).clamped, 0u);
}

// A constant frame stays constant (the fit of a constant is that constant).
TEST_F(NforMethod, KeepsAConstant) {
    Frame f = MakeFrame(20, 16, 0, "constant");
    for (float &v : f.color.data) v = 0.37f;
    Image out = NforDenoise(Ctx(), InputsOf(f), {}).image;
    EXPECT_TRUE(ImagesMatch(f.color, out, {}, {1e-5, 0, 1e-10}));
}

TEST_F(NforMethod, BadInputsAreRefusedWithTheirPlace) {
    Frame f = MakeFrame(8, 6, 0.3, "bad");
    NforInputs in = InputsOf(f);
    Image nan = f.color;
    nan.At(2, 4, 5) = std::numeric_limits<float>::quiet_NaN();
    in.color = &nan;
    std::string message = ErrorOf([&] { NforDenoise(Ctx(), in, {}); });
    EXPECT_TRUE(Contains(message, "color has NaN/Inf at pixel (5, 4), channel 2")) << message;
    in.color = &f.color;
    Image inf = f.normal;
    inf.At(0, 1, 3) = std::numeric_limits<float>::infinity();
    in.normal = &inf;
    message = ErrorOf([&] { NforDenoise(Ctx(), in, {}); });
    EXPECT_TRUE(Contains(message, "normal has NaN/Inf at pixel (3, 1)")) << message;
    in.normal = &f.normal;
    Image negative = f.color;
    negative.At(0, 0, 0) = -1;
    in.variance = &negative;
    EXPECT_TRUE(Contains(ErrorOf([&] { NforDenoise(Ctx(), in, {}); }),
                         "variance has a negative value"));
    in.variance = nullptr;
    Image small(8, 5, 1);
    in.depth = &small;
    EXPECT_TRUE(Contains(ErrorOf([&] { NforDenoise(Ctx(), in, {}); }), "depth is 8x5x1"));
    in.depth = &f.depth;
    NforOptions o;
    o.bandwidths = {};
    EXPECT_TRUE(Contains(ErrorOf([&] { NforDenoise(Ctx(), in, o); }), "bandwidths"));
    o = {};
    o.radius = 11;
    EXPECT_TRUE(Contains(ErrorOf([&] { NforDenoise(Ctx(), in, o); }), "radius 11"));
}

// Through the API: NaN in a plain frame is refused by default and replaced by 0 with a
// warning under non-finite=zero, the output then finite; the GPU's stages pair with the
// reference's by name (what `mcdenoise diff --method nfor` needs).
// A plain frame (colour, albedo, normal, depth) for the public API.
mcd::Frame PlainApiFrame(const Frame &f, const char *path) {
    mcd::Frame frame;
    frame.path = path;
    frame.width = f.color.width;
    frame.height = f.color.height;
    frame.layers = {
        {"color", f.color}, {"albedo", f.albedo}, {"normal", f.normal}, {"depth", f.depth}};
    return frame;
}

TEST_F(NforMethod, ApiRunsPlainFramesAndPairsStages) {
    mcd::Frame frame = PlainApiFrame(MakeFrame(19, 15, 0.3, "api"), "api.exr");
    Device device;
    Method method("nfor");
    method.Set("radius", 3);
    RunOptions run;
    run.keepStages = true;
    Result gpu = method.Run(device, frame, run);
    std::vector<Stage> cpu = method.Reference(device, frame);
    ASSERT_EQ(gpu.stages.size(), cpu.size());
    for (size_t i = 0; i < cpu.size(); ++i) EXPECT_EQ(gpu.stages[i].name, cpu[i].name);
    bool estimated = false;
    for (const std::string &line : gpu.plan)
        estimated |= Contains(line, "estimated from the frame");
    EXPECT_TRUE(estimated);
    frame.layers["color"].At(1, 3, 4) = std::numeric_limits<float>::quiet_NaN();
    EXPECT_TRUE(Contains(ErrorOf([&] { method.Run(device, frame); }), "NaN"));
    method.Set("non-finite", std::string("zero"));
    Result zeroed = method.Run(device, frame);
    EXPECT_FALSE(zeroed.warnings.empty());
    for (float v : zeroed.image.data) ASSERT_TRUE(std::isfinite(v));
}

// On a frame without a variance layer the second pass also fits over --plain-wide-radius
// windows, taken where they agree (the same bits as those options given as
// --pilot-wide-radius and --wide-agreement); beside a variance layer, with 0, or with a
// radius not below it, it does not.
TEST_F(NforMethod, PlainFramesTakeTheWideSecondPass) {
    mcd::Frame frame = PlainApiFrame(MakeFrame(19, 15, 0.3, "plain wide"), "plain.exr");
    Device device;
    // The plain frame's agreement as it is by default, given to the frame with statistics.
    const float agreement = std::get<float>(Method("nfor").Get("plain-wide-agreement"));
    auto run = [&](const mcd::Frame &input, int plainWide, int radius, int pilotWide) {
        Method method("nfor");
        method.Set("radius", radius);
        method.Set("noisy-radius", 0);
        method.Set("plain-wide-radius", plainWide);
        if (pilotWide > 0) {
            method.Set("pilot-wide-radius", pilotWide);
            method.Set("wide-agreement", agreement);
        }
        return method.Run(device, input);
    };
    auto wide = [](const Result &r, int radius) {
        bool found = false;
        for (const std::string &line : r.plan)
            found |= Contains(line, fmt::format("also over {0}x{0} windows", 2 * radius + 1));
        return found;
    };
    Result plain = run(frame, 5, 3, 0);
    EXPECT_TRUE(wide(plain, 5));
    EXPECT_TRUE(BitIdentical(plain.image, run(frame, 0, 3, 5).image));
    Result narrow = run(frame, 0, 3, 0);
    EXPECT_FALSE(wide(narrow, 5));
    EXPECT_FALSE(BitIdentical(plain.image, narrow.image));
    EXPECT_FALSE(wide(run(frame, 5, 5, 0), 5));

    mcd::Frame layered = frame;
    layered.layers["variance"] = Image(19, 15, 3, 0.01f);
    EXPECT_FALSE(wide(run(layered, 5, 3, 0), 5));
}

// Through the API: on a plain frame three far-out hits on a flat ground, within 3 of each
// other, which the firefly clamp cuts, give a share of their light around them (the plan
// names them; with --rare-light-share 0 the output differs); beside a variance layer the
// pass does not run.
TEST_F(NforMethod, PlainFramesSpreadTheRareLight) {
    Frame f = MakeFrame(29, 23, 0, "rare light");
    for (int y = 0; y < 23; ++y)
        for (int x = 0; x < 29; ++x)
            for (int c = 0; c < 3; ++c) {
                f.albedo.At(c, y, x) = 0.5f;
                f.normal.At(c, y, x) = c == 2 ? 1.f : 0.f;
                f.color.At(c, y, x) = 0.02f * (1 + 0.1f * float((x * 7 + y * 3) % 5));
            }
    for (int c = 0; c < 3; ++c)
        f.color.At(c, 11, 13) = f.color.At(c, 11, 16) = f.color.At(c, 14, 15) = 3.f;
    mcd::Frame frame = PlainApiFrame(f, "rare.exr");
    Device device;
    auto run = [&](const mcd::Frame &input, double share) {
        Method method("nfor");
        method.Set("rare-light-share", share);
        return method.Run(device, input);
    };
    auto rare = [](const Result &r) {
        bool found = false;
        for (const std::string &line : r.plan) found |= Contains(line, "rare light: 3 pixels");
        return found;
    };
    Result on = run(frame, 0.4), off = run(frame, 0);
    EXPECT_TRUE(rare(on));
    EXPECT_FALSE(rare(off));
    EXPECT_GT(on.image.At(1, 11, 14), off.image.At(1, 11, 14));
    mcd::Frame layered = frame;
    layered.layers["variance"] = Image(29, 23, 3, 0.0001f);
    EXPECT_FALSE(rare(run(layered, 0.4)));
}

// On a plain frame with a glint the plan names the glint bands' pass and a broken band beside
// it comes out more even than with --glint-band-radius 0; beside a variance layer the pass
// does not run.
TEST_F(NforMethod, PlainFramesSmoothGlintBands) {
    const int w = 36, h = 29, row = 14;
    Frame f = MakeFrame(w, h, 0, "glint bands");
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c) {
                f.albedo.At(c, y, x) = 0.5f;
                f.normal.At(c, y, x) = c == 2 ? 1.f : 0.f;
                f.color.At(c, y, x) = y == row ? (x % 2 ? 1.2f : 0.4f) : 0.05f;
            }
    for (int c = 0; c < 3; ++c) f.albedo.At(c, 3, 18) = 20.f;
    mcd::Frame frame = PlainApiFrame(f, "band.exr");
    Device device;
    auto run = [&](const mcd::Frame &input, int radius) {
        Method method("nfor");
        method.Set("glint-band-radius", radius);
        return method.Run(device, input);
    };
    auto band = [](const Result &r) {
        bool found = false;
        for (const std::string &line : r.plan) found |= Contains(line, "glint bands:");
        return found;
    };
    auto unevenness = [&](const Result &r) {
        double sum = 0;
        for (int x = 10; x < 26; ++x)
            sum += std::abs(r.image.At(1, row, x + 1) - r.image.At(1, row, x));
        return sum;
    };
    Result on = run(frame, 3), off = run(frame, 0);
    EXPECT_TRUE(band(on));
    EXPECT_FALSE(band(off));
    EXPECT_LT(unevenness(on), unevenness(off));
    mcd::Frame layered = frame;
    layered.layers["variance"] = Image(w, h, 3, 0.0001f);
    EXPECT_FALSE(band(run(layered, 3)));
}

// What the method is for: a rendered plain frame (colour, albedo, normal, depth only) comes
// out closer to the converged image and about as bright. The built-in renderer writes its
// light's reflectance as the albedo, the ceiling's too: no emitter is detected, and a
// clamp against the neighbours' median took the light for fireflies; against the 3rd largest it
// keeps pixels with two bright neighbours.
TEST_F(NforMethod, DenoisesARenderedPlainFrame) {
    render::Scene scene = render::BuildScene("cornell");
    render::RenderOptions o;
    o.width = 48, o.height = 48, o.spp = 16, o.seed = 5;
    o.layers = render::kLayersGbuffer;
    render::RenderResult noisy = render::Render(scene, o);
    o.spp = 512, o.seed = 77, o.layers = 0;
    render::RenderResult converged = render::Render(scene, o);
    auto layer = [](const render::RenderResult &r, const char *name) -> const Image & {
        for (const auto &[n, image] : r.layers)
            if (n == name) return image;
        throw Error(name);
    };
    NforInputs in;
    in.color = &layer(noisy, "color");
    in.albedo = &layer(noisy, "albedo");
    in.normal = &layer(noisy, "normal");
    in.depth = &layer(noisy, "depth");
    const Image &reference = layer(converged, "color");
    NforResult r = NforDenoise(Ctx(), in, {});
    ErrorMetrics before = CompareImages(*in.color, reference),
                 after = CompareImages(r.image, reference);
    EXPECT_LT(after.relMse, 0.7 * before.relMse) << before.relMse << " -> " << after.relMse;
    EXPECT_GT(after.psnr, before.psnr + 1) << before.psnr << " -> " << after.psnr;
    auto mean = [](const Image &image) {
        double sum = 0;
        for (float v : image.data) sum += v;
        return sum / double(image.Size());
    };
    double brightness = mean(r.image) / mean(reference);
    EXPECT_NEAR(brightness, 1, 0.1);
}

// A light under a glossy object's highlight line as a plain frame's few samples draw it: a
// light (albedo 40, colour 0.5) at the centre; a line stepping down one row every 6 pixels,
// 4 rows above the light at its column, every third pixel of it a hit of 10 (the clamp took
// it down to 1), its gaps 0.05; a lone firefly of 10 (clamped to 0.01) 3 pixels right of
// and below the light, off the line; the background 0.01 (albedo 0.5). The output given to
// the pass: the clamped colour.
struct LineFrame {
    Image color, clamped, albedo, output;
};

int LineRow(int x, int w, int h) {
    return h / 2 - 4 + (x - w / 2) / 6;
}

LineFrame MakeLineFrame(int w, int h, bool line = true, float lightAlbedo = 40.f) {
    LineFrame f{Image(w, h, 3, 0.01f), Image(w, h, 3, 0.01f), Image(w, h, 3, 0.5f), Image()};
    auto set = [&](int x, int y, float color, float clamped) {
        if (x >= w || y >= h) return;
        for (int c = 0; c < 3; ++c)
            f.color.At(c, y, x) = color, f.clamped.At(c, y, x) = clamped;
    };
    if (line)
        for (int x = 6; x < w - 6; ++x) {
            const bool hit = x % 3 == 0;
            set(x, LineRow(x, w, h), hit ? 10.f : 0.05f, hit ? 1.f : 0.05f);
        }
    set(w / 2 + 3, h / 2 + 3, 10.f, 0.01f);
    set(w / 2, h / 2, 0.5f, 0.5f);
    for (int c = 0; c < 3; ++c) f.albedo.At(c, h / 2, w / 2) = lightAlbedo;
    f.output = f.clamped;
    return f;
}

double Lum(const Image &image, int x, int y) {
    return 0.2126 * image.At(0, y, x) + 0.7152 * image.At(1, y, x) + 0.0722 * image.At(2, y, x);
}

// The line spread against its reference: random values of every kind (a NaN and an Inf in
// the colour, a NaN in a light's albedo), the clamp's light taken from random pixels, lights
// scattered, with and without an alpha whose zeros take no part; frames of one pixel, one row,
// 3x3, 31x17 and the line frame; a rerun is bit-identical; some pixels give. With no albedo
// above the gate the output is unchanged, bit for bit.
TEST(NforLine, MatchesTheReferenceAndRepeats) {
    size_t gave = 0;
    for (auto [w, h] : {std::pair{31, 17}, std::pair{1, 1}, std::pair{9, 1}, std::pair{3, 3},
                        std::pair{48, 40}})
        for (InputKind kind : {InputKind::Uniform, InputKind::LogNormalFireflies,
                               InputKind::Constant, InputKind::Impulse}) {
            std::string name = fmt::format("line {}x{} {}", w, h, InputKindName(kind));
            uint64_t seed = SeedFromName(name);
            std::mt19937 random{uint32_t(seed)};
            LineFrame f = MakeLineFrame(w, h);
            Image color = MakeVarianceInput(kind, w, h, 3, seed);
            for (size_t i = 0; i < color.Size(); ++i)
                f.color.data[i] += std::abs(color.data[i]);
            f.clamped = f.color;
            Image output = MakeVarianceInput(InputKind::Uniform, w, h, 3, seed + 2);
            for (size_t i = 0; i < output.Size(); ++i)
                f.output.data[i] = f.clamped.data[i] * (1 + 0.2f * output.data[i]);
            for (size_t p = 0; p < color.PixelCount(); ++p) {
                if (random() % 4 == 0)
                    for (int c = 0; c < 3; ++c) f.clamped.Plane(c)[p] *= 0.1f;
                if (random() % 40 == 0) f.albedo.Plane(int(random() % 3))[p] = 20.f;
            }
            if (w * h > 9) {
                f.color.At(1, 1, 1) = std::nanf("");
                f.color.At(0, 2, 1) = std::numeric_limits<float>::infinity();
                // The line's light with a NaN first channel: its others still make it one.
                f.albedo.At(0, h / 2, w / 2) = std::nanf("");
            }
            Image alpha(w, h, 1, 1.f);
            const bool withAlpha = kind == InputKind::Uniform || kind == InputKind::Impulse;
            for (float &a : alpha.data) a = random() % 8 == 0 ? 0.f : 1.f;
            const Image *a = withAlpha ? &alpha : nullptr;
            Image host = f.output, again = f.output, cpu = f.output;
            NforLineStats stats = NforSpreadLine(f.color, f.clamped, f.albedo, a, {}, &host);
            NforSpreadLine(f.color, f.clamped, f.albedo, a, {}, &again);
            int cpuGave =
                ref::NforSpreadLine(f.color, f.clamped, f.albedo, a, 8, 4, 3, 4, &cpu);
            EXPECT_EQ(int(stats.givers), cpuGave) << name;
            EXPECT_TRUE(ImagesMatch(cpu, host, {}, {4 * kU, 0, 1e-12})) << name;
            EXPECT_TRUE(BitIdentical(host, again)) << name;
            if (withAlpha)
                for (size_t i = 0; i < host.Size(); ++i)
                    if (!(alpha.data[i % host.PixelCount()] > 0.f)) {
                        EXPECT_EQ(std::memcmp(&host.data[i], &f.output.data[i], sizeof(float)),
                                  0)
                            << name << " value " << i;
                    }
            gave += stats.givers;
            // No light above the gate: nothing changes.
            Image unlit = f.output;
            NforLineSettings high;
            high.lightAlbedo = 1e6f;
            EXPECT_EQ(NforSpreadLine(f.color, f.clamped, f.albedo, a, high, &unlit).givers, 0u);
            EXPECT_TRUE(BitIdentical(unlit, f.output)) << name;
        }
    EXPECT_GT(gave, 0u);
}

// The line's hits near the light give the light the clamp took to the line, gaps included,
// no more than they lost; nothing below the light changes (the lone firefly beside it is
// not spread); where the output already holds the line's light the cap drops it all;
// without the line, or without a light above the gate, nothing changes at all.
TEST(NforLine, SpreadsALinesHitsNotALoneFirefly) {
    const int w = 48, h = 40;
    LineFrame f = MakeLineFrame(w, h);
    Image out = f.output;
    NforLineStats stats = NforSpreadLine(f.color, f.clamped, f.albedo, nullptr, {}, &out);
    // The hits within 4 pixels of the light: x = 21, 24, 27.
    EXPECT_GE(stats.givers, 2u);
    EXPECT_LE(stats.givers, 3u);
    double added = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) added += Lum(out, x, y) - Lum(f.output, x, y);
    EXPECT_GT(added, 0.5 * stats.givers * 9);
    EXPECT_LE(added, stats.moved + 1e-4);
    EXPECT_NEAR(added, stats.moved - stats.dropped, 1e-4);
    for (int x : {22, 23, 25, 26})
        EXPECT_GT(Lum(out, x, LineRow(x, w, h)), 0.5) << "gap at x " << x;
    for (int y = h / 2 - 1; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c)
                EXPECT_EQ(out.At(c, y, x), f.output.At(c, y, x)) << x << ", " << y;
    Image again = f.output;
    NforSpreadLine(f.color, f.clamped, f.albedo, nullptr, {}, &again);
    EXPECT_TRUE(BitIdentical(out, again));
    // The cap: where the output already holds the hits' light about the line, nothing is
    // added and all the light given is dropped.
    LineFrame lit = MakeLineFrame(w, h);
    for (int x = 0; x < w; ++x)
        for (int y = LineRow(x, w, h) - 1; y <= LineRow(x, w, h) + 1; ++y)
            for (int c = 0; c < 3; ++c) lit.output.At(c, y, x) = 10.f;
    Image capped = lit.output;
    NforLineStats full =
        NforSpreadLine(lit.color, lit.clamped, lit.albedo, nullptr, {}, &capped);
    EXPECT_EQ(full.givers, stats.givers);
    EXPECT_NEAR(full.dropped, full.moved, 1e-4);
    EXPECT_TRUE(BitIdentical(capped, lit.output));
    for (bool line : {false, true}) {
        LineFrame g = MakeLineFrame(w, h, line, line ? 7.f : 40.f);
        Image kept = g.output;
        EXPECT_EQ(NforSpreadLine(g.color, g.clamped, g.albedo, nullptr, {}, &kept).givers, 0u);
        EXPECT_TRUE(BitIdentical(kept, g.output)) << (line ? "light of albedo 7" : "no line");
    }
}

// A frame larger than the pass's reach about its lights: the line frame's light, bright
// edges 18 and 16 pixels beside it (read by the tensor and the line means of pixels it
// writes), a second light on the line 85 pixels right (a window of its own); against the
// reference, which reads the whole frame, and with the second light alone.
TEST(NforLine, LightsFarApartMatchTheReference) {
    const int w = 200, h = 120;
    LineFrame f = MakeLineFrame(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            if (x == w / 2 + 18 || y == h / 2 + 16)
                for (int c = 0; c < 3; ++c) f.color.At(c, y, x) = f.clamped.At(c, y, x) = 0.3f;
    f.output = f.clamped;
    const int x2 = w / 2 + 85, y2 = LineRow(x2, w, h) + 3;
    for (int c = 0; c < 3; ++c) f.albedo.At(c, y2, x2) = 40.f;
    for (bool first : {true, false}) {
        SCOPED_TRACE(first ? "both lights" : "the second light alone");
        if (!first)
            for (int c = 0; c < 3; ++c) f.albedo.At(c, h / 2, w / 2) = 0.5f;
        Image host = f.output, cpu = f.output;
        NforLineStats stats = NforSpreadLine(f.color, f.clamped, f.albedo, nullptr, {}, &host);
        int cpuGave =
            ref::NforSpreadLine(f.color, f.clamped, f.albedo, nullptr, 8, 4, 3, 4, &cpu);
        EXPECT_GE(stats.givers, first ? 4u : 2u);
        EXPECT_EQ(int(stats.givers), cpuGave);
        EXPECT_TRUE(ImagesMatch(cpu, host, {}, {4 * kU, 0, 1e-12}));
        size_t changed = 0;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) changed += host.At(1, y, x) != f.output.At(1, y, x);
        EXPECT_GT(changed, 0u);
    }
}

// A tile with a halo of kNforLineReach gives the pixels of the tile what the whole frame
// does, bit for bit.
TEST(NforLine, ATileWithItsHaloMatchesTheWholeFrame) {
    const int w = 120, h = 90, R = kNforLineReach;
    LineFrame f = MakeLineFrame(w, h);
    Image whole = f.output;
    ASSERT_GT(NforSpreadLine(f.color, f.clamped, f.albedo, nullptr, {}, &whole).givers, 0u);
    const int tx0 = w / 2 - 6, ty0 = h / 2 - 9, tw = 12, th = 8;
    const int x0 = tx0 - R, y0 = ty0 - R, cw = tw + 2 * R, chh = th + 2 * R;
    auto crop = [&](const Image &image) {
        Image part(cw, chh, image.channels);
        for (int c = 0; c < image.channels; ++c)
            for (int y = 0; y < chh; ++y)
                for (int x = 0; x < cw; ++x) part.At(c, y, x) = image.At(c, y0 + y, x0 + x);
        return part;
    };
    Image color = crop(f.color), clamped = crop(f.clamped), albedo = crop(f.albedo),
          tile = crop(f.output);
    NforSpreadLine(color, clamped, albedo, nullptr, {}, &tile);
    size_t changed = 0;
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < th; ++y)
            for (int x = 0; x < tw; ++x) {
                const float a = whole.At(c, ty0 + y, tx0 + x), b = tile.At(c, R + y, R + x);
                EXPECT_EQ(std::memcmp(&a, &b, sizeof(float)), 0) << x << ", " << y;
                changed += a != f.output.At(c, ty0 + y, tx0 + x);
            }
    EXPECT_GT(changed, 0u);
}

// nfor's defaults on a dark plain frame with a light under a highlight line of hits: the line
// spread gives the line the light the clamp took (the gaps beside the light brighter than
// with --line-spread 0), the rest of the frame as it was, bit for bit (the glint bands, which
// would smooth what the spread gave, left out of both runs).
TEST_F(NforMethod, DefaultsSpreadTheClampsLightAlongALine) {
    const int w = 48, h = 40;
    Frame f = MakeFrame(w, h, 0.05, "line spread");
    LineFrame line = MakeLineFrame(w, h);
    for (float &v : f.color.data) v *= 0.02f;  // a dark room
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            if (line.color.At(0, y, x) != 0.01f)
                for (int c = 0; c < 3; ++c) {
                    f.color.At(c, y, x) = line.color.At(c, y, x);
                    f.albedo.At(c, y, x) = line.albedo.At(c, y, x);
                }
    NforOptions defaults, off;
    defaults.glintBandRadius = off.glintBandRadius = 0;
    off.lineSpread = 0;
    NforResult a = NforDenoise(Ctx(), InputsOf(f), defaults);
    NforResult b = NforDenoise(Ctx(), InputsOf(f), off);
    EXPECT_GT(a.lineGivers, 0u);
    EXPECT_GT(a.lineMoved, 0);
    EXPECT_EQ(b.lineGivers, 0u);
    double gained = 0;
    for (int x : {22, 23, 25, 26})
        gained += Lum(a.image, x, LineRow(x, w, h)) - Lum(b.image, x, LineRow(x, w, h));
    EXPECT_GT(gained, 0.5);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            if (std::abs(x - w / 2) > 12 || y >= h / 2) {
                for (int c = 0; c < 3; ++c)
                    EXPECT_EQ(a.image.At(c, y, x), b.image.At(c, y, x)) << x << ", " << y;
            }
}

// The line frame's line partly covered (alpha 0.75, the colour as written), the rest
// covered: the method's line stage is its reference's pass on the stage before it, given
// the colour and the clamped colour (the "color" stage, straight) as written. Some pixels
// give.
TEST_F(NforMethod, PartlyCoveredLineSpreadsTheLightAsWritten) {
    const int w = 48, h = 40;
    Frame f = MakeFrame(w, h, 0.05, "line partly covered");
    LineFrame line = MakeLineFrame(w, h);
    Image alpha(w, h, 1, 1.f);
    for (float &v : f.color.data) v *= 0.02f;  // a dark room
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            if (line.color.At(0, y, x) != 0.01f) {
                if (line.albedo.At(0, y, x) < 1.f) alpha.At(0, y, x) = 0.75f;
                for (int c = 0; c < 3; ++c) {
                    f.color.At(c, y, x) = line.color.At(c, y, x);
                    f.albedo.At(c, y, x) = line.albedo.At(c, y, x);
                }
            }
    NforInputs in = InputsOf(f);
    in.alpha = &alpha;
    NforOptions o;
    o.keepStages = true;
    NforResult r = NforDenoise(Ctx(), in, o);
    EXPECT_GT(r.partlyCovered, 0u);
    EXPECT_GT(r.lineGivers, 0u);
    auto stage = [&](const std::string &name) {
        for (const auto &s : r.stages)
            if (s.first == name) return s.second;
        ADD_FAILURE() << "no stage " << name;
        return Image();
    };
    Image clamped = stage("color"), expected = stage("lights"), got = stage("line");
    ASSERT_EQ(clamped.Size(), f.color.Size());
    for (int c = 0; c < 3; ++c)
        for (size_t p = 0; p < clamped.PixelCount(); ++p) clamped.Plane(c)[p] *= alpha.data[p];
    int cpuGave =
        ref::NforSpreadLine(f.color, clamped, f.albedo, &alpha, 8, 4, 3, 4, &expected);
    EXPECT_EQ(int(r.lineGivers), cpuGave);
    EXPECT_TRUE(ImagesMatch(expected, got, {}, {4 * kU, 0, 1e-12}));
}

// The line frame painted into a dark room's colour and albedo as written, its drawn pixels
// partly covered (alpha a; the light at a 0.75 and 0.9 covered), the rest covered: every
// stage agrees with the reference's. The line's gap pixels beside a hit weigh next to
// nothing but themselves, so a fit gives their colour back only to within rounding, exact
// on one side and not on the other; the local means must take kept values from nfor's mask
// (the emitters), not from an output equal to its input, for the stages to agree.
TEST_F(NforMethod, PartlyCoveredLineStagesMatchTheReference) {
    NforOptions o;
    o.radius = 3;
    for (float a : {0.75f, 0.9f, 0.5f}) {
        SCOPED_TRACE(fmt::format("alpha {}", a));
        auto paint = [a](Frame *f, Image *alpha) {
            const int w = f->color.width, h = f->color.height;
            LineFrame line = MakeLineFrame(w, h);
            *alpha = Image(w, h, 1, 1.f);
            for (float &v : f->color.data) v *= 0.02f;
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x)
                    if (line.color.At(0, y, x) != 0.01f) {
                        const bool light = line.albedo.At(0, y, x) >= 1.f;
                        alpha->At(0, y, x) = light && a > 0.5f ? 1.f : a;
                        for (int c = 0; c < 3; ++c) {
                            f->color.At(c, y, x) = line.color.At(c, y, x);
                            f->albedo.At(c, y, x) = line.albedo.At(c, y, x);
                        }
                    }
        };
        ExpectStagesMatch(Ctx(), 48, 40, o, false, true, false, false, paint);
    }
}

}  // namespace
}  // namespace mcd::test
