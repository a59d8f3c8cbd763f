// Beside the half-buffers auto adjusts its final error estimates (host/methods/auto_halves.h):
// each raised to half1's variance, at most a multiple of the candidates' median, and a
// candidate far above the others over the frame left out.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "cpu_reference/auto_combine.h"
#include "harness/inputs.h"
#include "host/methods/auto_halves.h"
#include "host/metrics.h"

namespace mcd {
namespace {

using test::SeedFromName;

// K planes of random estimates (some negative, as the halves' estimates are) and a noise
// plane, seeded by the test's name.
struct Estimates {
    Image smooth, noise;
};

Estimates RandomEstimates(int w, int h, int count, const char *name) {
    std::mt19937_64 rng(SeedFromName(name));
    std::uniform_real_distribution<float> error(-0.002f, 0.02f), noise(0.f, 0.1f);
    Estimates e{Image(w, h, count), Image(w, h, 1)};
    for (float &x : e.smooth.data) x = error(rng);
    for (float &x : e.noise.data) x = noise(rng);
    return e;
}

// Normal deviates by Box-Muller from std::mt19937, whose output the standard fixes (unlike
// std::normal_distribution's), so that a figure a test compares does not move with the
// library.
struct Normal {
    std::mt19937 rng;
    explicit Normal(uint64_t seed) : rng(uint32_t(seed ^ (seed >> 32))) {}
    // In (0, 1).
    double Uniform() { return (double(rng() >> 8) + 0.5) / double(1 << 24); }
    float operator()() {
        const double r = std::sqrt(-2 * std::log(Uniform()));
        return float(r * std::cos(6.283185307179586 * Uniform()));
    }
};

// Each factor as expected, to a float's rounding.
void ExpectFactors(const std::vector<float> &factors, const std::vector<float> &expected) {
    ASSERT_EQ(factors.size(), expected.size());
    for (size_t k = 0; k < factors.size(); ++k)
        EXPECT_FLOAT_EQ(factors[k], expected[k]) << "candidate " << k;
}

TEST(AutoHalvesEstimates, RaisesEveryEstimateToTheNoiseAtMostAShareOfTheMedian) {
    const int w = 19, h = 13, count = 5;
    Estimates e = RandomEstimates(w, h, count, "auto halves floor");
    Image adjusted = e.smooth;
    AutoHalvesSettings settings{0.5f, 0.f, 1e-5f};
    AutoHalvesResult result = AutoAdjustHalvesEstimates(adjusted, e.noise, settings);
    const size_t n = e.noise.PixelCount();
    size_t raised = 0;
    for (size_t i = 0; i < n; ++i) {
        std::vector<float> at;
        for (int k = 0; k < count; ++k) at.push_back(std::max(e.smooth.data[k * n + i], 1e-5f));
        std::sort(at.begin(), at.end());
        float least = std::min(e.noise.data[i], 0.5f * at[count / 2]);
        for (int k = 0; k < count; ++k) {
            float before = e.smooth.data[k * n + i];
            EXPECT_EQ(adjusted.data[k * n + i], std::max(before, least))
                << "pixel " << i << " candidate " << k;
            raised += before < least;
        }
    }
    EXPECT_GT(raised, n / 4);
    for (bool dropped : result.dropped) EXPECT_FALSE(dropped);
    Image again = e.smooth;
    AutoAdjustHalvesEstimates(again, e.noise, settings);
    EXPECT_EQ(again.data, adjusted.data);
}

// The drop compares with the candidates' median over the frame, not with the best: an
// estimate below zero (a candidate that keeps the bias the halves share) leaves the others.
TEST(AutoHalvesEstimates, LeavesOutOnlyCandidatesFarAboveTheMedian) {
    const int w = 8, h = 8;
    const std::vector<float> levels = {0.004f, 0.005f, -0.001f, 0.006f, 0.03f};
    Image smooth(w, h, int(levels.size())), noise(w, h, 1);
    for (size_t k = 0; k < levels.size(); ++k)
        std::fill_n(smooth.Plane(int(k)), smooth.PixelCount(), levels[k]);
    Image adjusted = smooth;
    AutoHalvesResult result = AutoAdjustHalvesEstimates(adjusted, noise, {0.f, 3.f, 1e-5f});
    EXPECT_NEAR(result.median, 0.005, 1e-9);
    for (size_t k = 0; k < levels.size(); ++k) {
        bool far = k == 4;
        EXPECT_EQ(result.dropped[k], far) << "candidate " << k;
        for (size_t i = 0; i < smooth.PixelCount(); ++i)
            if (far)
                EXPECT_TRUE(std::isinf(adjusted.Plane(int(k))[i]));
            else
                EXPECT_EQ(adjusted.Plane(int(k))[i], levels[k]);
    }
}

// Where the candidates' median over the frame is about zero or below, the estimates over
// the frame tell nothing (half1's noise, or the bias the halves share, outweighs them): none
// is left out, however far above it one is.
TEST(AutoHalvesEstimates, LeavesNoneOutWhereTheMedianIsAboutZero) {
    const int w = 6, h = 5;
    const std::vector<float> levels = {-0.009f, -0.013f, 0.068f, -0.013f, 0.022f};
    Image smooth(w, h, int(levels.size())), noise(w, h, 1);
    for (size_t k = 0; k < levels.size(); ++k)
        std::fill_n(smooth.Plane(int(k)), smooth.PixelCount(), levels[k]);
    Image adjusted = smooth;
    AutoHalvesResult result = AutoAdjustHalvesEstimates(adjusted, noise, {0.f, 3.5f, 1e-5f});
    for (bool dropped : result.dropped) EXPECT_FALSE(dropped);
    EXPECT_EQ(adjusted.data, smooth.data);
}

// A median over the frame above 1e-4 but under 0.01 x half1's variance over the frame is
// within the halves' noise (a frame like fence_grass's accumulated one, docs/methods/auto.md):
// none is left out; with a hundredth of that variance the same estimates leave out the far
// ones.
TEST(AutoHalvesEstimates, LeavesNoneOutWhereTheMedianIsUnderTheFramesNoise) {
    const int w = 6, h = 5;
    const std::vector<float> levels = {0.00018f, 0.00032f, 0.0017f, 0.0018f, -0.0004f};
    Image smooth(w, h, int(levels.size()));
    for (size_t k = 0; k < levels.size(); ++k)
        std::fill_n(smooth.Plane(int(k)), smooth.PixelCount(), levels[k]);
    for (float frameNoise : {0.084f, 0.00084f}) {
        Image noise(w, h, 1), adjusted = smooth;
        std::fill(noise.data.begin(), noise.data.end(), frameNoise);
        AutoHalvesResult result =
            AutoAdjustHalvesEstimates(adjusted, noise, {0.f, 3.5f, 1e-5f});
        EXPECT_NEAR(result.median, 0.00032, 1e-9);
        const bool noisy = frameNoise > 0.01f;
        for (size_t k = 0; k < levels.size(); ++k)
            EXPECT_EQ(result.dropped[k], !noisy && (k == 2 || k == 3))
                << "candidate " << k << ", half1's variance " << frameNoise;
        if (noisy) EXPECT_EQ(adjusted.data, smooth.data);
    }
}

// Where half1's noise dominates every window the plain floor raises the candidates' estimates
// to one level, and 1 / e^2 weighs them alike; with the rank each floor is scaled by the
// candidate's estimate over the frame over the smallest, so the weights follow the frame's
// ranking there (the floor here 2x the median, so that it binds for all). A candidate whose
// frame estimate is about zero or below (under a share of the frame's noise) counts as that
// share, so it cannot take every weight.
TEST(AutoHalvesEstimates, TheRankKeepsTheFramesOrderWhereTheNoiseDominates) {
    const int w = 16, h = 12;
    const std::vector<float> levels = {0.002f, 0.004f, 0.008f};
    std::mt19937_64 rng(SeedFromName("auto halves rank"));
    std::uniform_real_distribution<float> scatter(-0.001f, 0.001f);
    Image smooth(w, h, int(levels.size())), noise(w, h, 1);
    for (size_t k = 0; k < levels.size(); ++k)
        for (size_t i = 0; i < smooth.PixelCount(); ++i)
            smooth.Plane(int(k))[i] = levels[k] + scatter(rng);
    for (float &x : noise.data) x = 0.1f;
    Image adjusted = smooth;
    AutoHalvesSettings settings{2.f, 0.f, 1e-5f, 1.f};
    AutoHalvesResult result = AutoAdjustHalvesEstimates(adjusted, noise, settings);
    const size_t n = smooth.PixelCount();
    for (size_t i = 0; i < n; ++i) {
        std::vector<float> at;
        for (size_t k = 0; k < levels.size(); ++k) at.push_back(smooth.Plane(int(k))[i]);
        std::sort(at.begin(), at.end());
        const float least = 2.f * at[1];
        for (size_t k = 0; k < levels.size(); ++k) {
            float factor = float(result.frameEstimates[k] / result.frameEstimates[0]);
            float expected = std::max(smooth.Plane(int(k))[i], least * factor);
            EXPECT_NEAR(adjusted.Plane(int(k))[i], expected, 1e-6f * expected)
                << "pixel " << i << " candidate " << k;
        }
        // The floors bind for all three: their ratios are the frame's.
        EXPECT_NEAR(adjusted.Plane(2)[i] / adjusted.Plane(0)[i],
                    result.frameEstimates[2] / result.frameEstimates[0], 1e-4);
    }
    // An estimate over the frame below zero counts as 1% of the frame's noise: the others'
    // factors are their estimates over that, not over ~0.
    for (size_t i = 0; i < n; ++i) smooth.Plane(0)[i] = -0.003f;
    adjusted = smooth;
    AutoAdjustHalvesEstimates(adjusted, noise, settings);
    for (size_t i = 0; i < n; ++i) {
        EXPECT_NEAR(adjusted.Plane(0)[i], 2.f * smooth.Plane(1)[i], 1e-9f);
        EXPECT_LT(adjusted.Plane(2)[i], 10 * adjusted.Plane(0)[i]);
    }
}

// A good candidate and a worse one (each the truth plus its own noise, the second's 4x the
// first's relative error), and estimates that scatter about their true errors as much as
// those errors, as a window's halves estimate does on a noisy frame: where the worse one's
// falls near zero by chance, 1 / e^2 gives it all the weight there. Raised to half the
// median, no estimate near zero outweighs the other's, and the good candidate keeps most
// of the weight.
TEST(AutoHalvesEstimates, AnEstimateNearZeroByChanceDoesNotTakeAllTheWeight) {
    const int w = 48, h = 48;
    std::mt19937_64 rng(SeedFromName("auto halves near zero"));
    std::normal_distribution<float> unit(0.f, 1.f);
    Image truth(w, h, 3), color(w, h, 3), variance(w, h, 3);
    std::vector<Image> outputs(2, Image(w, h, 3));
    const float spread[2] = {0.03f, 0.06f};
    for (size_t i = 0; i < truth.data.size(); ++i) {
        truth.data[i] = 0.5f;
        color.data[i] = 0.5f + 0.2f * unit(rng);
        variance.data[i] = 0.04f;
        for (int k = 0; k < 2; ++k) outputs[k].data[i] = 0.5f + spread[k] * unit(rng);
    }
    std::vector<double> trueError;
    for (const Image &o : outputs) trueError.push_back(CompareImages(o, truth).relMse);
    Image smooth(w, h, 2), noise(w, h, 1);
    for (int k = 0; k < 2; ++k)
        for (size_t i = 0; i < smooth.PixelCount(); ++i)
            smooth.Plane(k)[i] = float(trueError[k] * (1 + unit(rng)));
    for (float &x : noise.data) x = 0.15f;
    auto combined = [&](const Image &errors) {
        Image f =
            ref::AutoCombineRelative(color, outputs, errors, variance, 2, 1e-5, 30, 4).color;
        return CompareImages(f, truth).relMse;
    };
    Image adjusted = smooth;
    AutoAdjustHalvesEstimates(adjusted, noise, {0.5f, 0.f, 1e-5f});
    double before = combined(smooth), after = combined(adjusted);
    fmt::print(
        "relMSE: candidates {:.4g} and {:.4g}, estimates as they are {:.4g}, raised "
        "{:.4g}\n",
        trueError[0], trueError[1], before, after);
    EXPECT_LT(after, 0.95 * before);
}

// A method's variants share one candidate's weight under 1 / e^power: each estimate left in
// times (its method's candidates left in) ^ (1 / power), after the floor and read as
// max(e, floorError) like the combination reads it (an estimate under floorError shares
// too); a variant whose sibling is left out weighs alone again. Where every estimate is
// under floorError (the combination's equal weights) they stay as they are.
TEST(AutoHalvesEstimates, AMethodsVariantsShareOneWeight) {
    const std::vector<int> method = {0, 1, 2, 1, 2};
    std::vector<bool> none(5, false), third(5, false);
    third[3] = true;
    const float root2 = std::sqrt(2.f);
    ExpectFactors(AutoVariantFactors(method, none, 2.f), {1.f, root2, root2, root2, root2});
    ExpectFactors(AutoVariantFactors(method, third, 2.f), {1.f, 1.f, root2, 1.f, root2});
    ExpectFactors(AutoVariantFactors(method, none, 0.f), std::vector<float>(5, 1.f));
    ExpectFactors(AutoVariantFactors({}, none, 2.f), std::vector<float>(5, 1.f));

    const int w = 11, h = 7, count = 5;
    const float floorError = 1e-5f;
    Estimates e = RandomEstimates(w, h, count, "auto halves variants");
    // Pixel 0: every estimate under floorError, and no noise to raise them.
    e.noise.data[0] = 0;
    for (int k = 0; k < count; ++k) e.smooth.Plane(k)[0] = -1e-3f;
    // Pixel 1: a variant's estimate under floorError beside others above it.
    e.smooth.Plane(1)[1] = -1e-3f, e.noise.data[1] = 0;
    AutoHalvesSettings plain;
    plain.floor = 0.5f, plain.floorError = floorError;
    AutoHalvesSettings shared = plain;
    shared.method = method, shared.power = 2.f;
    Image before = e.smooth, after = e.smooth;
    AutoAdjustHalvesEstimates(before, e.noise, plain);
    AutoHalvesResult result = AutoAdjustHalvesEstimates(after, e.noise, shared);
    const std::vector<float> factors = AutoVariantFactors(method, none, 2.f);
    EXPECT_EQ(result.variants, factors);
    size_t under = 0;
    for (size_t i = 0; i < before.PixelCount(); ++i) {
        bool weighed = false;
        for (int k = 0; k < count; ++k) weighed = weighed || before.Plane(k)[i] >= floorError;
        EXPECT_EQ(weighed, i != 0) << "pixel " << i;
        for (int k = 0; k < count; ++k) {
            const float b = before.Plane(k)[i];
            if (b >= floorError || !weighed || factors[k] == 1.f) {
                const float expected = weighed ? b * factors[k] : b;
                EXPECT_EQ(after.Plane(k)[i], expected) << "pixel " << i << " candidate " << k;
            } else {
                EXPECT_EQ(after.Plane(k)[i], floorError * factors[k])
                    << "pixel " << i << " candidate " << k;
                ++under;
            }
        }
    }
    EXPECT_GT(under, 0u);
    EXPECT_EQ(after.Plane(1)[1], floorError * root2);
}

// Below a power of about 0.01 the factor's root overflows a float: it is capped at the
// largest, and every estimate stays finite (an infinite one would leave its candidate out).
TEST(AutoHalvesEstimates, ATinyPowerLeavesEveryVariantIn) {
    const std::vector<int> method = {0, 1, 1};
    const std::vector<bool> none(3, false);
    const float largest = std::numeric_limits<float>::max();
    for (float power : {1e-3f, 5e-3f}) {
        const std::vector<float> factors = AutoVariantFactors(method, none, power);
        EXPECT_EQ(factors, (std::vector<float>{1.f, largest, largest})) << power;
        Estimates e = RandomEstimates(7, 5, 3, "auto halves tiny power");
        AutoHalvesSettings settings;
        settings.floor = 0.5f, settings.floorError = 1e-5f;
        settings.method = method, settings.power = power;
        AutoHalvesResult result = AutoAdjustHalvesEstimates(e.smooth, e.noise, settings);
        for (bool dropped : result.dropped) EXPECT_FALSE(dropped);
        for (float x : e.smooth.data) EXPECT_TRUE(std::isfinite(x)) << power;
    }
    ExpectFactors(AutoVariantFactors(method, none, 0.1f), {1.f, 1024.f, 1024.f});
}

// One method's run and three variants of another whose errors go together (the same noise
// but for a small part of their own), estimates that scatter about the errors and a floor
// that binds, as on a noisy accumulated frame: each candidate weighing alone gives the
// variants three quarters of the weight and keeps their shared error; sharing one weight
// gives them half. The noise is the test's own (Normal), not the library's.
TEST(AutoHalvesEstimates, VariantsWhoseErrorsGoTogetherWeighAsOne) {
    const int w = 48, h = 48;
    // The estimates' scatter: enough for the floor to bind, little enough that the ratio
    // below stands well clear of its bound whatever the seed.
    const float kScatter = 0.3f;
    Normal unit(SeedFromName("auto halves variants together"));
    Image truth(w, h, 3), color(w, h, 3), variance(w, h, 3);
    std::vector<Image> outputs(4, Image(w, h, 3));
    for (size_t i = 0; i < truth.data.size(); ++i) {
        truth.data[i] = 0.5f;
        color.data[i] = 0.5f + 0.2f * unit();
        variance.data[i] = 0.04f;
        const float shared = 0.04f * unit();
        outputs[0].data[i] = 0.5f + 0.04f * unit();
        outputs[1].data[i] = 0.5f + shared + 0.005f * unit();
        outputs[2].data[i] = 0.5f + shared + 0.005f * unit();
        outputs[3].data[i] = 0.5f + shared + 0.005f * unit();
    }
    Image smooth(w, h, 4), noise(w, h, 1);
    for (int k = 0; k < 4; ++k) {
        const double error = CompareImages(outputs[k], truth).relMse;
        for (size_t i = 0; i < smooth.PixelCount(); ++i)
            smooth.Plane(k)[i] = float(error * (1 + kScatter * unit()));
    }
    for (float &x : noise.data) x = 0.15f;
    auto combined = [&](bool share) {
        AutoHalvesSettings settings;
        settings.floor = 0.5f, settings.floorError = 1e-5f;
        if (share) settings.method = {0, 1, 1, 1}, settings.power = 2.f;
        Image adjusted = smooth;
        AutoAdjustHalvesEstimates(adjusted, noise, settings);
        Image f =
            ref::AutoCombineRelative(color, outputs, adjusted, variance, 2, 1e-5, 30, 4).color;
        return CompareImages(f, truth).relMse;
    };
    const double alone = combined(false), shared = combined(true);
    fmt::print("relMSE: each alone {:.4g}, the variants sharing one weight {:.4g}\n", alone,
               shared);
    EXPECT_LT(shared, 0.95 * alone);
}

// The guard of the local means, loop by loop from its definition: each pixel's tent window
// (weights (r + 1 - |dx|)(r + 1 - |dy|) over the pixels in the frame), the departure of the
// candidate's window mean from the colour's over the standard error of the colour's (the
// variances with the squared weights, plus 1% of the mean squared), t their root mean
// square over channels, the estimate (at least floorError) times exp(min((t^2 - z^2) / 2,
// 16)) where t > z. Random inputs, some candidates offset; odd sizes, 1x1, a non-finite
// estimate, and a window of exact values (variance 0, capped). Two runs give the same bits.
double GuardFactor(const Image &color, const Image &output, const Image &variance, int x0,
                   int y0, int radius, float z) {
    double t2 = 0;
    for (int c = 0; c < color.channels; ++c) {
        double weights = 0, colour = 0, candidate = 0, spread = 0;
        for (int y = std::max(0, y0 - radius); y <= std::min(color.height - 1, y0 + radius);
             ++y)
            for (int x = std::max(0, x0 - radius); x <= std::min(color.width - 1, x0 + radius);
                 ++x) {
                const double wt = double(radius + 1 - std::abs(x - x0)) *
                                  double(radius + 1 - std::abs(y - y0));
                weights += wt;
                colour += wt * color.At(c, y, x);
                candidate += wt * output.At(c, y, x);
                spread += wt * wt * variance.At(c, y, x);
            }
        const double mean = colour / weights, departure = candidate / weights - mean;
        const double least = std::max(1e-2 * std::abs(mean), 1e-4);
        const double error2 = spread / (weights * weights) + least * least;
        if (std::isnan(error2)) return 1;  // a NaN variance is not noise: unguarded
        if (departure != 0) t2 += departure * departure / error2;
    }
    const double logRatio = std::min(0.5 * (t2 / color.channels - double(z) * z), 16.0);
    return logRatio > 0 ? std::exp(logRatio) : 1;
}

TEST(AutoHalvesEstimates, GuardRaisesCandidatesWhoseLocalMeanDeparts) {
    const float z = 2, floorError = 1e-5f;
    for (auto [w, h, radius] : {std::array<int, 3>{17, 11, 2}, {1, 1, 2}, {5, 9, 3}}) {
        std::mt19937_64 rng(SeedFromName(fmt::format("auto guard {}x{}", w, h).c_str()));
        std::uniform_real_distribution<float> unit(0.f, 1.f);
        Image color(w, h, 3), variance(w, h, 3);
        for (float &x : color.data) x = 0.2f + unit(rng);
        for (float &x : variance.data) x = 0.01f * unit(rng);
        // A window of exact values: variance 0 around the frame's last pixel.
        for (int c = 0; c < 3; ++c) variance.At(c, h - 1, w - 1) = 0;
        // A NaN variance in one channel leaves the tents that reach it unguarded.
        double unguarded = 0;
        if (w * h > 1) {
            variance.At(1, 0, w / 2) = std::numeric_limits<float>::quiet_NaN();
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x)
                    if (std::abs(x - w / 2) <= radius && y <= radius)
                        unguarded += 1.0 / (double(w) * h);
        }
        std::vector<Image> outputs(4, color);
        for (size_t i = 0; i < color.data.size(); ++i) {
            outputs[1].data[i] += 0.05f * (unit(rng) - 0.5f);  // within the noise, mostly
            outputs[2].data[i] *= 0.5f;                        // fades everything
            outputs[3].data[i] += (i % 7 == 0) ? 0.5f : 0.f;   // ghosts in places
        }
        Image smooth(w, h, 4);
        for (float &x : smooth.data) x = 0.02f * unit(rng) - 0.002f;
        smooth.Plane(3)[0] = std::numeric_limits<float>::quiet_NaN();
        std::vector<const Image *> pointers;
        for (const Image &o : outputs) pointers.push_back(&o);
        Image guarded = smooth;
        AutoMeanGuard guard{z, radius, floorError};
        std::vector<double> raised =
            AutoGuardLocalMeans(guarded, color, pointers, variance, guard);
        for (int k = 0; k < 4; ++k)
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) {
                    const size_t i = size_t(y) * w + x;
                    const float before = smooth.Plane(k)[i], after = guarded.Plane(k)[i];
                    const double factor =
                        GuardFactor(color, outputs[k], variance, x, y, radius, z);
                    if (!std::isfinite(before)) {
                        EXPECT_TRUE(std::isnan(after));
                    } else if (factor == 1) {
                        EXPECT_EQ(after, before) << k << " at " << x << "," << y;
                    } else {
                        // Double sums in another order: a few float roundings.
                        const double expected = std::max(before, floorError) * factor;
                        EXPECT_NEAR(after, expected, 1e-5 * expected)
                            << k << " at " << x << "," << y;
                    }
                }
        EXPECT_EQ(raised[0], 0.0);  // the colour itself departs by nothing
        // Half the colour everywhere: far past its noise, but where the variance is NaN.
        EXPECT_NEAR(raised[2], 1.0 - unguarded, 1e-9);
        Image again = smooth;
        AutoGuardLocalMeans(again, color, pointers, variance, guard);
        EXPECT_EQ(std::memcmp(again.data.data(), guarded.data.data(),
                              again.data.size() * sizeof(float)),
                  0);
        // Off: nothing changes.
        Image off = smooth;
        AutoGuardLocalMeans(off, color, pointers, variance, {0.f, radius, floorError});
        EXPECT_EQ(
            std::memcmp(off.data.data(), smooth.data.data(), off.data.size() * sizeof(float)),
            0);
    }
}

TEST(AutoHalvesEstimates, GuardNeedsARealDepartureWhereTheColourIsExactlyBlack) {
    // A black background: colour and variance exactly 0. A bleed of rounding is no
    // departure; one of a hundred least standard errors is.
    const int w = 8, h = 6;
    Image color(w, h, 3), variance(w, h, 3);
    std::vector<Image> outputs(3, color);
    for (float &x : outputs[1].data) x = 1e-9f;
    for (float &x : outputs[2].data) x = 100 * kAutoGuardLeastError;
    std::vector<const Image *> pointers;
    for (const Image &o : outputs) pointers.push_back(&o);
    Image smooth(w, h, 3);
    for (float &x : smooth.data) x = 1e-3f;
    const Image before = smooth;
    std::vector<double> raised =
        AutoGuardLocalMeans(smooth, color, pointers, variance, {2.f, 2, 1e-5f});
    EXPECT_EQ(raised[0], 0.0);
    EXPECT_EQ(raised[1], 0.0);
    EXPECT_NEAR(raised[2], 1.0, 1e-9);
    for (size_t i = 0; i < size_t(w) * h; ++i) {
        EXPECT_EQ(smooth.Plane(1)[i], before.Plane(1)[i]);
        EXPECT_GT(smooth.Plane(2)[i], before.Plane(2)[i]);
    }
}

}  // namespace
}  // namespace mcd
