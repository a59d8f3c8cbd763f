// nfor's albedo trust (shaders/nfor/trust.comp) against its CPU reference
// (ref::NforAlbedoTrust), and the rule itself on an albedo that is noise beside one that is
// texture, through the kernel and through nfor's colour distance.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <algorithm>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "cpu_reference/nfor.h"
#include "harness/compare.h"
#include "harness/gpu_fixture.h"
#include "harness/inputs.h"
#include "host/kernels/nfor_kernels.h"
#include "nfor/nfor.h"

namespace mcd::test {
namespace {

Image RunTrust(vk::Context &ctx, const Image &color, const Image &albedo, float noise) {
    vk::GpuImage c = UploadImage(ctx, color, "color"), a = UploadImage(ctx, albedo, "albedo");
    vk::GpuImage out(ctx, color.width, color.height, 1, "trust");
    vk::Recorder recorder(ctx);
    RecordNforTrust(ctx, recorder, c, a, noise, out);
    recorder.Submit();
    return out.Download();
}

// A frame whose left half has an albedo that is noise (random per pixel and channel, the
// colour a smooth light times a grain of its own) and whose right half has texture (random
// per pixel and channel too, the colour that albedo times the smooth light): the albedos
// are alike, only the colour tells them apart.
void NoiseBesideTexture(int w, int h, const std::string &name, Image *color, Image *albedo) {
    std::mt19937_64 rng(SeedFromName(name));
    std::uniform_real_distribution<float> reflectance(0.05f, 0.95f), grain(0.5f, 1.5f);
    *color = Image(w, h, 3);
    *albedo = Image(w, h, 3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float light = 1.f + 0.02f * float(x + y), speck = grain(rng);
            for (int c = 0; c < 3; ++c) {
                float a = reflectance(rng);
                albedo->At(c, y, x) = a;
                color->At(c, y, x) = x < w / 2 ? 0.5f * light * speck : a * light;
            }
        }
}

struct TrustCase {
    int w, h;
    InputKind kind;
};

std::string TrustCaseName(const testing::TestParamInfo<TrustCase> &info) {
    return fmt::format("{}x{}_{}", info.param.w, info.param.h, InputKindName(info.param.kind));
}

std::vector<TrustCase> TrustCases() {
    std::vector<TrustCase> cases;
    for (auto [w, h] : {std::pair{23, 17}, std::pair{1, 1}, std::pair{1, 9}, std::pair{11, 1}})
        for (InputKind kind : {InputKind::Uniform, InputKind::LogNormalFireflies,
                               InputKind::Constant, InputKind::Impulse, InputKind::NonFinite})
            cases.push_back({w, h, kind});
    return cases;
}

class NforTrustKernel : public GpuTestWithParam<TrustCase> {};

// Random and edge colours (fireflies, a constant, an impulse, NaN and Inf: a window with a
// non-finite value compares false, trusted on both sides) over random albedos (a tenth under
// the floor, some emitters), of 3 channels and of 1, at three bounds. The decision compares
// float sums against the reference's double ones; the inputs hold no near ties, so the two
// agree exactly (a window whose colour holds one non-zero value, an impulse, is an exact tie
// of the roughness test: trusted on both sides by its margin). Two runs are bit-identical.
TEST_P(NforTrustKernel, MatchesTheReferenceAndRepeats) {
    const auto [w, h, kind] = GetParam();
    const std::string name = fmt::format("trust{}x{}{}", w, h, InputKindName(kind));
    for (int albedoChannels : {3, 1}) {
        for (float noise : {0.01f, 0.1f, 1.f}) {
            SCOPED_TRACE(fmt::format("albedo {} channels, noise {}", albedoChannels, noise));
            Image color = MakeVarianceInput(kind, w, h, 3, SeedFromName(name));
            std::mt19937_64 rng(SeedFromName(name + "albedo"));
            std::uniform_real_distribution<float> unit(0.f, 1.f);
            Image albedo(w, h, albedoChannels);
            for (float &v : albedo.data) v = unit(rng) < 0.1f ? 0.01f : unit(rng);
            for (size_t i = 0; i < albedo.PixelCount(); i += 13)
                for (int c = 0; c < albedoChannels; ++c) albedo.Plane(c)[i] = 3.f;
            Image expected = ref::NforAlbedoTrust(color, albedo, noise);
            Image actual = RunTrust(Ctx(), color, albedo, noise);
            EXPECT_TRUE(BitIdentical(expected, actual));
            EXPECT_TRUE(BitIdentical(actual, RunTrust(Ctx(), color, albedo, noise)));
        }
    }
}

INSTANTIATE_TEST_SUITE_P(Cases, NforTrustKernel, testing::ValuesIn(TrustCases()),
                         TrustCaseName);

// NaN and Inf albedos (the API removes them; library and kernel callers need not): the kernel
// and the reference floor a NaN alike (a comparison, not max, whose NaN is undefined), on a
// colour and an albedo random enough that windows around them are untrusted.
TEST_F(GpuTest, NforTrustFloorsANonFiniteAlbedoAsTheReference) {
    const int w = 23, h = 17;
    Image color =
        MakeVarianceInput(InputKind::Uniform, w, h, 3, SeedFromName("trustNaNAlbedo"));
    std::mt19937_64 rng(SeedFromName("trustNaNAlbedoA"));
    std::uniform_real_distribution<float> unit(0.f, 1.f);
    Image albedo(w, h, 3);
    for (float &v : albedo.data) v = unit(rng);
    const float nan = std::numeric_limits<float>::quiet_NaN(),
                inf = std::numeric_limits<float>::infinity();
    for (size_t i = 0; i < albedo.data.size(); i += 7) albedo.data[i] = nan;
    for (size_t i = 3; i < albedo.data.size(); i += 29) albedo.data[i] = i % 2 ? inf : -inf;
    Image expected = ref::NforAlbedoTrust(color, albedo, 0.1);
    Image actual = RunTrust(Ctx(), color, albedo, 0.1f);
    EXPECT_TRUE(BitIdentical(expected, actual));
    EXPECT_LT(std::count(expected.data.begin(), expected.data.end(), 1.f),
              int(expected.data.size()));
}

// The rule: the albedo that is noise (left) is not trusted, the texture the colour follows
// (right) is; a bound above the albedo's roughness trusts every pixel, and so does a
// constant albedo. Kernel and reference alike, on an odd size.
TEST_F(GpuTest, NforTrustMarksNoiseAndKeepsTexture) {
    const int w = 31, h = 13;
    Image color, albedo;
    NoiseBesideTexture(w, h, "trustNoiseBesideTexture", &color, &albedo);
    const float noise = 0.02f;
    Image actual = RunTrust(Ctx(), color, albedo, noise);
    EXPECT_TRUE(BitIdentical(ref::NforAlbedoTrust(color, albedo, noise), actual));
    int left = 0, leftTrusted = 0, right = 0, rightTrusted = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            // Windows wholly on one side.
            if (x + 1 < w / 2) {
                ++left;
                leftTrusted += actual.At(0, y, x) != 0;
            } else if (x - 1 >= w / 2) {
                ++right;
                rightTrusted += actual.At(0, y, x) != 0;
            }
        }
    EXPECT_GT(left, 0);
    EXPECT_EQ(leftTrusted, 0);
    EXPECT_EQ(rightTrusted, right);
    Image all(w, h, 1);
    std::fill(all.data.begin(), all.data.end(), 1.f);
    EXPECT_TRUE(BitIdentical(RunTrust(Ctx(), color, albedo, 1e3f), all));
    Image constant(w, h, 3);
    std::fill(constant.data.begin(), constant.data.end(), 0.4f);
    EXPECT_TRUE(BitIdentical(RunTrust(Ctx(), color, constant, 1e-6f), all));
}

// Through the distance: on the noisy half a pair compares the colours (its distance is that
// of the colour alone), on the textured half colour / albedo (that of the divided colour).
TEST_F(GpuTest, NforDistanceComparesColoursWhereTheAlbedoIsNoise) {
    const int w = 31, h = 13, radius = 1, patch = 0;
    Image color, albedo;
    NoiseBesideTexture(w, h, "trustDistance", &color, &albedo);
    Image variance(w, h, 3);
    std::fill(variance.data.begin(), variance.data.end(), 0.01f);
    Image trust = ref::NforAlbedoTrust(color, albedo, 0.02);
    Image withTrust =
        ref::NforDistance(color, variance, &albedo, radius, patch, 1, false, &trust);
    Image colours = ref::NforDistance(color, variance, nullptr, radius, patch, 1, false);
    Image divided = ref::NforDistance(color, variance, &albedo, radius, patch, 1, false);
    vk::GpuImage c = UploadImage(Ctx(), color, "color"), v = UploadImage(Ctx(), variance, "v"),
                 a = UploadImage(Ctx(), albedo, "albedo"), t = UploadImage(Ctx(), trust, "t");
    const int offsets = ref::NforOffsetCount(radius);
    vk::GpuImage scratch(Ctx(), w, h, offsets, "scratch"), out(Ctx(), w, h, offsets, "D"),
        illumination(Ctx(), w, h, kNforIlluminationFloats, "illumination");
    vk::Recorder recorder(Ctx());
    RecordNforDistance(Ctx(), recorder, c, v, &a, radius, patch, 1, false, illumination,
                       scratch, out, &t);
    recorder.Submit();
    Image gpu = out.Download();
    for (int j = 0; j < offsets; ++j)
        for (int y = 1; y < h - 1; ++y)
            for (int x = 0; x < w; ++x) {
                const bool left = x + 2 < w / 2, right = x - 2 >= w / 2;
                if (!left && !right) continue;
                const float want = left ? colours.At(j, y, x) : divided.At(j, y, x);
                EXPECT_FLOAT_EQ(withTrust.At(j, y, x), want)
                    << x << "," << y << " offset " << j;
                EXPECT_NEAR(gpu.At(j, y, x), want, 1e-4 * (1 + std::fabs(want)))
                    << x << "," << y << " offset " << j;
            }
}

}  // namespace
}  // namespace mcd::test
