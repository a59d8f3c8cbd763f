// Error metrics (ARCHITECTURE.md): known values, edge cases, refusals.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "harness/errors.h"
#include "harness/inputs.h"
#include "host/metrics.h"

namespace mcd::test {
namespace {

TEST(Metrics, IdenticalImagesArePerfect) {
    Image a = MakeInput(InputKind::Uniform, 23, 17, 3, SeedFromName("metrics"));
    ErrorMetrics m = CompareImages(a, a);
    EXPECT_EQ(m.relMse, 0);
    EXPECT_TRUE(std::isinf(m.psnr));
    EXPECT_NEAR(m.ssim, 1.0, 1e-12);
}

TEST(Metrics, KnownOffset) {
    // r = 0.25 everywhere, x = r + 0.05: relMSE = 0.0025 / (0.0625 + 0.01); PSNR from the
    // sRGB-encoded difference; SSIM of two constants is (2ab + c1) / (a^2 + b^2 + c1).
    Image r(16, 16, 3, 0.25f), x(16, 16, 3, 0.30f);
    ErrorMetrics m = CompareImages(x, r);
    EXPECT_NEAR(m.relMse, 0.0025 / 0.0725, 1e-6);
    auto srgb = [](double v) { return 1.055 * std::pow(v, 1 / 2.4) - 0.055; };
    double d = srgb(0.30) - srgb(0.25);
    EXPECT_NEAR(m.psnr, 10 * std::log10(1 / (d * d)), 1e-4);
    double a = srgb(0.30), b = srgb(0.25), c1 = 1e-4;
    EXPECT_NEAR(m.ssim, (2 * a * b + c1) / (a * a + b * b + c1), 1e-6);
}

TEST(Metrics, BrightnessIsTheMeanLuminanceOverTheReferences) {
    // Two pixels: luminance (0.2126 + 0.0722) * 0.5 and 0.7152 * 0.25 in x against 0.4
    // and 0.4 in r, a NaN pixel in x left out of both sums.
    Image r(3, 1, 3, 0.4f), x(3, 1, 3, 0.f);
    x.At(0, 0, 0) = x.At(2, 0, 0) = 0.5f;
    x.At(1, 0, 1) = 0.25f;
    x.At(1, 0, 2) = std::numeric_limits<float>::quiet_NaN();
    double want = ((0.2126 + 0.0722) * 0.5 + 0.7152 * 0.25) / 0.8;
    EXPECT_NEAR(CompareImages(x, r).brightness, want, 1e-6);
    Image one(4, 4, 1, 0.3f), half(4, 4, 1, 0.15f);
    EXPECT_NEAR(CompareImages(half, one).brightness, 0.5, 1e-6);
    EXPECT_EQ(CompareImages(one, one).brightness, 1.0);
    EXPECT_TRUE(std::isnan(CompareImages(one, Image(4, 4, 1, 0.f)).brightness));
}

TEST(Metrics, NoiseLowersSsimAndPsnr) {
    Image r(32, 32, 3, 0.5f), small = r, large = r;
    Image n = MakeInput(InputKind::Uniform, 32, 32, 3, SeedFromName("noise"));
    for (size_t i = 0; i < r.Size(); ++i)
        small.data[i] += 0.02f * n.data[i], large.data[i] += 0.2f * n.data[i];
    ErrorMetrics a = CompareImages(small, r), b = CompareImages(large, r);
    EXPECT_GT(a.ssim, b.ssim);
    EXPECT_GT(a.psnr, b.psnr);
    EXPECT_LT(a.relMse, b.relMse);
    EXPECT_LT(b.ssim, 0.9);
}

TEST(Metrics, NonFiniteAndMismatchedInputs) {
    Image r(8, 8, 3, 0.5f), x = r;
    x.At(1, 2, 3) = std::numeric_limits<float>::quiet_NaN();
    ErrorMetrics m = CompareImages(x, r);
    EXPECT_EQ(m.nonFinite, 1u);
    // Non-finite output scores as badly as possible, never as well as a perfect one.
    EXPECT_TRUE(std::isinf(m.relMse));
    EXPECT_EQ(m.psnr, 0);
    EXPECT_EQ(m.ssim, 0);
    EXPECT_TRUE(
        ThrowsError(ErrorKind::InvalidArgument, [&] { CompareImages(Image(8, 8, 1), r); }));
    EXPECT_TRUE(
        ThrowsError(ErrorKind::InvalidArgument, [&] { CompareImages(Image(8, 7, 3), r); }));
    EXPECT_TRUE(ThrowsError(ErrorKind::NonFiniteInput, [&] { CompareImages(r, x); }));
}

// MeasureDifference (`mcdenoise diff`'s and ImagesMatch's NMSE): known sums, elements
// finite on one side counted apart, both-non-finite ones skipped, an all-zero reference.
TEST(Metrics, MeasureDifference) {
    Image r(2, 2, 1), x(2, 2, 1);
    r.data = {1.f, 2.f, -2.f, std::numeric_limits<float>::infinity()};
    x.data = {1.5f, 2.f, -1.f, std::numeric_limits<float>::quiet_NaN()};
    ElementDifference d = MeasureDifference(x, r);
    EXPECT_EQ(d.parity, 0u);
    EXPECT_DOUBLE_EQ(d.nmse, (0.25 + 1.0) / (1 + 4 + 4));
    EXPECT_DOUBLE_EQ(d.maxRel, 1.0 / 2);
    x.data[1] = std::numeric_limits<float>::infinity();
    EXPECT_EQ(MeasureDifference(x, r).parity, 1u);
    Image zero(2, 2, 1), ones(2, 2, 1, 1.f);
    EXPECT_DOUBLE_EQ(MeasureDifference(ones, zero).nmse, 4.0);
    EXPECT_DOUBLE_EQ(MeasureDifference(ones, zero).maxRel, 1.0);
    EXPECT_DOUBLE_EQ(MeasureDifference(zero, zero).nmse, 0.0);
    EXPECT_TRUE(
        ThrowsError(ErrorKind::InvalidArgument, [&] { MeasureDifference(Image(3, 2, 1), r); }));
}

}  // namespace
}  // namespace mcd::test
