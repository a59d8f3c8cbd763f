// Highlights taken out before a filter (host/common/highlights.h) against the CPU reference,
// and awr keeping a small light's energy at the light.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <tuple>

#include "cpu_reference/highlights.h"
#include "harness/frames.h"
#include "harness/gpu_fixture.h"
#include "harness/inputs.h"
#include "host/api/device.h"
#include "host/common/highlights.h"
#include "host/common/parallel.h"
#include "host/metrics.h"
#include "mcdenoise/mcdenoise.h"

namespace mcd::test {
namespace {

// Pixels beside MakeFrame's bright block (rows h/3 to h/3 + 2, columns w/4 to w/4 + 3).
struct Pixel {
    int x, y;
};
Pixel GlintOf(int w, int h) {
    return {w / 4, h / 3};
}
Pixel GlintFireflyOf(int w, int h) {
    return {w / 4 - 1, h / 3 - 1};
}
Pixel RimPixelOf(int w, int h) {
    return {w / 4 - 1, h / 3 + 2};
}
Pixel BrighterFireflyOf(int w, int h) {
    return {w / 4 + 1, h / 3 + 3};
}

// MakeFrame's glint streak (frames from 17 wide): 2 columns against the right edge, 4 rows.
std::vector<Pixel> StreakOf(int w, int h) {
    std::vector<Pixel> streak;
    if (w < 17) return streak;
    for (int y = 1; y < std::min(h, 5); ++y)
        for (int x = w - 2; x < w; ++x) streak.push_back({x, y});
    return streak;
}

// A dim noisy frame with bright blocks (lights), lone fireflies and constants; from 17 wide
// also a glint streak at ratio k of the highlights, between k / 2 and k times the frame's mean.
void MakeFrame(int w, int h, int channels, double k, Image *color, Image *variance) {
    std::mt19937_64 rng(SeedFromName("highlights " + std::to_string(w) + "x" +
                                     std::to_string(h) + "x" + std::to_string(channels)));
    std::uniform_real_distribution<float> unit(0, 1);
    *color = Image(w, h, channels);
    *variance = Image(w, h, channels);
    for (size_t i = 0; i < color->data.size(); ++i) {
        float u = unit(rng);
        color->data[i] = u < 0.01f ? 500 * unit(rng) : u < 0.05f ? 0.f : unit(rng);
        variance->data[i] = unit(rng) * unit(rng);
    }
    for (int c = 0; c < channels; ++c)
        for (int y = h / 3; y < std::min(h, h / 3 + 3); ++y)
            for (int x = w / 4; x < std::min(w, w / 4 + 4); ++x)
                color->At(c, y, x) = 100 + 300 * unit(rng);
    // A light wider than the window's half (its interior is its own median: grown into),
    // with a dimmer rim.
    for (int c = 0; c < channels; ++c)
        for (int y = h / 2; y < std::min(h, h / 2 + 7); ++y)
            for (int x = w / 2; x < std::min(w, w / 2 + 7); ++x) {
                bool rim = y == h / 2 || x == w / 2;
                color->At(c, y, x) = (rim ? 20 : 200) + 100 * unit(rng);
            }
    if (w < 17) return;
    // One-sample pixels beside the bright block (variance = value^2: never 2 standard
    // deviations above the floor): a rim pixel dimmer than the block, one brighter than the
    // block, and one beside the block's corner made a glint (about 3 standard deviations above
    // its background, not sure of its light). The last two are a glint's fireflies.
    const Pixel glint = GlintOf(w, h);
    float glintSum = 0;
    for (int c = 0; c < channels; ++c) glintSum += color->At(c, glint.y, glint.x);
    for (int c = 0; c < channels; ++c) {
        variance->At(c, glint.y, glint.x) = glintSum * glintSum / (9.f * channels);
        for (auto [p, value] : {std::pair{RimPixelOf(w, h), 99.f},
                                {BrighterFireflyOf(w, h), 450.f},
                                {GlintFireflyOf(w, h), 99.f}}) {
            color->At(c, p.y, p.x) = value;
            variance->At(c, p.y, p.x) = value * value;
        }
    }
    // The streak's one-sample pixels, seeded around a share of k times the mean they raise
    // (found by fixed-point steps): over their windows and k / 2 x the mean, under k x it.
    const std::vector<Pixel> streak = StreakOf(w, h);
    std::vector<float> jitter;
    for (size_t i = 0; i < streak.size(); ++i) jitter.push_back(0.51f + 0.04f * unit(rng));
    double level = 0;
    for (int step = 0; step <= 20; ++step) {
        for (size_t i = 0; i < streak.size(); ++i)
            for (int c = 0; c < channels; ++c) {
                float value = float(jitter[i] * level / channels);
                color->At(c, streak[i].y, streak[i].x) = value;
                variance->At(c, streak[i].y, streak[i].x) = value * value;
            }
        level = k * HighlightFrameMean(*color);
    }
}

// Each value's largest sample: 1 to 16 times the value, seeded; the streak's its value (all
// its samples alike, a glossy reflection dimmer than the lights).
Image MaxSampleOf(const Image &color) {
    std::mt19937_64 rng(SeedFromName("highlights max " + std::to_string(color.width) + "x" +
                                     std::to_string(color.height) + "x" +
                                     std::to_string(color.channels)));
    std::uniform_real_distribution<float> unit(0, 1);
    Image maxSample = color;
    for (float &v : maxSample.data) v *= 1 + 15 * unit(rng);
    for (Pixel p : StreakOf(color.width, color.height))
        for (int c = 0; c < color.channels; ++c)
            maxSample.At(c, p.y, p.x) = color.At(c, p.y, p.x);
    return maxSample;
}

// The sparse lights added to a split (`split`, and the twin's mask and bases) against the
// twin, with the split's own highlights' median largest sample and with half of it given, in
// the default parts and forced into 1 and 3. Returns how many pixels under k times the frame's
// mean (a streak's) the split's own median marked.
size_t ExpectSparseLightsMatchReference(const Image &color, const Image &variance, double k,
                                        const HighlightSplit &split,
                                        const std::vector<char> &mask, const Image &base,
                                        const Image &baseVariance) {
    const int w = color.width, h = color.height;
    SCOPED_TRACE(testing::Message() << w << "x" << h << "x" << color.channels << ", k " << k);
    const Image maxSample = MaxSampleOf(color);
    const double own = HighlightSampleMedian(maxSample, split.highlight);
    const double mean = HighlightFrameMean(color);
    for (Pixel p : StreakOf(w, h)) {
        float s = 0, sample = 0;
        for (int c = 0; c < color.channels; ++c) {
            s += color.At(c, p.y, p.x);
            sample += maxSample.At(c, p.y, p.x);
        }
        EXPECT_LT(s, k * mean) << "the streak at " << p.x << ", " << p.y;
        EXPECT_GT(s, kStreakMeanShare * k * mean) << "the streak at " << p.x << ", " << p.y;
        EXPECT_LE(sample, kStreakSampleRatio * own) << "the streak at " << p.x << ", " << p.y;
    }
    size_t streakMarks = 0;
    for (double lightSample : {-1.0, own / 2}) {
        HighlightSplit got = split;
        const size_t added =
            AddSparseLights(color, &variance, maxSample, k, 3, lightSample, &got);
        std::vector<char> expected = mask;
        Image expectedBase = base, expectedVariance = baseVariance;
        ref::AddSparseLights(color, &variance, maxSample, k, 3, lightSample, &expected,
                             &expectedBase, &expectedVariance);
        EXPECT_EQ(got.highlight, expected) << "light sample " << lightSample;
        if (got.highlight != expected) return streakMarks;
        EXPECT_EQ(got.base.data, expectedBase.data);
        EXPECT_EQ(got.baseVariance.data, expectedVariance.data);
        const size_t count = size_t(std::count(expected.begin(), expected.end(), char(1)));
        EXPECT_EQ(got.count, count);
        EXPECT_EQ(added, count - split.count);
        EXPECT_EQ(got.sparse, added);
        if (w >= 40 && lightSample < 0) {
            EXPECT_GT(added, 0u) << "no sparse light to compare";
        }
        for (size_t p = 0; lightSample < 0 && p < expected.size(); ++p) {
            float s = 0;
            for (int c = 0; c < color.channels; ++c) s += color.Plane(c)[p];
            streakMarks += expected[p] && !mask[p] && !(s > k * mean);
        }
        for (int parts : {1, 3}) {
            ForceParallelParts force(parts);
            HighlightSplit parted = SplitHighlights(color, &variance, k, 3);
            EXPECT_EQ(AddSparseLights(color, &variance, maxSample, k, 3, lightSample, &parted),
                      added)
                << parts << " parts";
            EXPECT_EQ(parted.highlight, expected) << parts << " parts";
            EXPECT_EQ(parted.base.data, expectedBase.data) << parts << " parts";
            EXPECT_EQ(parted.baseVariance.data, expectedVariance.data) << parts << " parts";
            EXPECT_EQ(parted.count, count) << parts << " parts";
        }
    }
    // A NaN in the max layer: the sample cannot be compared, nothing is added.
    Image withNan = maxSample;
    withNan.data[withNan.data.size() / 2] = std::numeric_limits<float>::quiet_NaN();
    HighlightSplit got = split;
    EXPECT_EQ(AddSparseLights(color, &variance, withNan, k, 3, -1, &got), 0u);
    EXPECT_EQ(got.highlight, split.highlight);
    std::vector<char> expected = mask;
    Image expectedBase = base, expectedVariance = baseVariance;
    ref::AddSparseLights(color, &variance, withNan, k, 3, -1, &expected, &expectedBase,
                         &expectedVariance);
    EXPECT_EQ(expected, mask);
    EXPECT_EQ(expectedBase.data, base.data);
    return streakMarks;
}

TEST(Highlights, MatchesReference) {
    for (int channels : {1, 3})
        for (auto [w, h] : {std::pair{1, 1}, {3, 2}, {17, 13}, {44, 33}})
            for (double k : {4.0, 16.0}) {
                Image color, variance;
                MakeFrame(w, h, channels, k, &color, &variance);
                HighlightSplit got = SplitHighlights(color, &variance, k, 3);
                Image base, baseVariance;
                std::vector<char> mask =
                    ref::SplitHighlights(color, &variance, k, 3, &base, &baseVariance);
                // Medians are copied values and the sums the same float sums: bit for bit.
                ASSERT_EQ(got.highlight, mask) << w << "x" << h << "x" << channels;
                EXPECT_EQ(got.base.data, base.data);
                EXPECT_EQ(got.baseVariance.data, baseVariance.data);
                Image output(w, h, channels, 0.25f), expected = output;
                AddHighlights(color, got, &output);
                ref::AddHighlights(color, base, mask, &expected);
                EXPECT_EQ(output.data, expected.data);
                // Crests near the highlights against the twin, on a noisy output.
                Image crest = output, crestExpected = output;
                for (size_t i = 0; i < crest.data.size(); ++i)
                    crest.data[i] = crestExpected.data[i] +=
                        3 * color.data[(i * 7919) % color.data.size()];
                LowerToInputMaximumNearHighlights(color, got.highlight, 6, 1, &crest);
                ref::LowerToInputMaximumNearHighlights(color, mask, 6, 1, &crestExpected);
                EXPECT_EQ(crest.data, crestExpected.data);
                const size_t streakMarks = ExpectSparseLightsMatchReference(
                    color, variance, k, got, mask, base, baseVariance);
                auto marked = [&](Pixel p) { return got.highlight[size_t(p.y) * w + p.x]; };
                if (w >= 17) {
                    EXPECT_GT(got.count, 0u) << "the bright block is a highlight";
                    EXPECT_TRUE(marked(GlintOf(w, h))) << "the glint";
                    EXPECT_FALSE(marked(GlintFireflyOf(w, h))) << "beside the glint";
                    EXPECT_FALSE(marked(BrighterFireflyOf(w, h))) << "brighter than the block";
                    EXPECT_GT(streakMarks, 0u) << "the streak";
                }
                if (w >= 40) {
                    EXPECT_TRUE(got.highlight[size_t(h / 2 + 3) * w + w / 2 + 3])
                        << "the wide light's centre, k " << k << ", " << channels;
                    // k x the frame's mean stops it at k = 16 (and in the smaller frames).
                    if (k == 4) {
                        EXPECT_TRUE(marked(RimPixelOf(w, h)))
                            << "the rim pixel one sample saw, beside the block";
                    }
                }
            }
    // A frame without highlights has none to compare a sample with: a lone firefly whose
    // sample is its value stays out, as it does not with a light's sample given.
    Image color(9, 9, 3, 0.1f);
    for (int c = 0; c < 3; ++c) color.At(c, 4, 4) = 1000;
    HighlightSplit none = SplitHighlights(color, nullptr, 16, 3);
    ASSERT_EQ(none.count, 0u);
    EXPECT_EQ(HighlightSampleMedian(color, none.highlight), 0.0);
    EXPECT_EQ(AddSparseLights(color, nullptr, color, 16, 3, -1, &none), 0u);
    Image base = color, baseVariance;
    std::vector<char> mask = none.highlight;
    ref::AddSparseLights(color, nullptr, color, 16, 3, -1, &mask, &base, &baseVariance);
    EXPECT_EQ(mask, none.highlight);
    EXPECT_EQ(AddSparseLights(color, nullptr, color, 16, 3, 3000, &none), 1u);
    ref::AddSparseLights(color, nullptr, color, 16, 3, 3000, &mask, &base, &baseVariance);
    EXPECT_EQ(mask, none.highlight);
    EXPECT_EQ(base.data, none.base.data);
    // A color with -Inf or NaN has no sparse lights even with a light's sample given (its mean
    // is no bound: -Inf passes every test against it), in the host and the twin alike.
    for (float bad :
         {-std::numeric_limits<float>::infinity(), std::numeric_limits<float>::quiet_NaN()}) {
        Image broken = color;
        broken.At(1, 0, 0) = bad;
        HighlightSplit split = SplitHighlights(broken, nullptr, 16, 3);
        EXPECT_EQ(AddSparseLights(broken, nullptr, color, 16, 3, 3000, &split), 0u) << bad;
        EXPECT_EQ(split.count, 0u) << bad;
        std::vector<char> brokenMask(size_t(9) * 9, 0);
        Image brokenBase = broken, unused;
        ref::AddSparseLights(broken, nullptr, color, 16, 3, 3000, &brokenMask, &brokenBase,
                             &unused);
        EXPECT_EQ(brokenMask, split.highlight) << bad;
        for (int c = 0; c < 3; ++c) EXPECT_EQ(brokenBase.At(c, 4, 4), 1000.f) << bad;
    }
}

TEST(Highlights, LoneFireflyAndNonFiniteFramesHaveNone) {
    Image color(9, 9, 3, 0.1f);
    for (int c = 0; c < 3; ++c) color.At(c, 4, 4) = 1000;  // a lone firefly
    EXPECT_EQ(SplitHighlights(color, nullptr, 16, 3).count, 0u);
    for (int c = 0; c < 3; ++c) color.At(c, 4, 5) = color.At(c, 5, 4) = 1000;
    HighlightSplit three = SplitHighlights(color, nullptr, 16, 3);
    EXPECT_EQ(three.count, 3u);
    EXPECT_FLOAT_EQ(three.base.At(0, 4, 4), 0.1f);
    color.At(1, 0, 0) = std::numeric_limits<float>::quiet_NaN();
    EXPECT_EQ(SplitHighlights(color, nullptr, 16, 3).count, 0u);
}

// A small light's reflection in a mirror sphere covers two pixels, seen by most samples:
// far above its noise, without the 2 bright neighbours a light's core has. It is a
// highlight; a lone pixel as far above the median but within two of its standard deviations
// (a firefly) is not, nor is a lone pixel far above its noise (at 4 spp a firefly's few
// samples may agree).
TEST(Highlights, ConfidentTwoPixelReflectionsAreHighlights) {
    Image color(15, 15, 3, 0.1f), variance(15, 15, 3, 1e-4f);
    for (int c = 0; c < 3; ++c) {
        color.At(c, 7, 7) = color.At(c, 7, 8) = 300;  // 30 standard deviations above
        variance.At(c, 7, 7) = variance.At(c, 7, 8) = 100;
        color.At(c, 11, 11) = 300;  // alone, 30 standard deviations above
        variance.At(c, 11, 11) = 100;
        color.At(c, 2, 2) = 300;  // a firefly: 1 standard deviation above
        variance.At(c, 2, 2) = 90000;
    }
    HighlightSplit split = SplitHighlights(color, &variance, 16, 3);
    EXPECT_EQ(split.count, 2u);
    EXPECT_TRUE(split.highlight[7 * 15 + 7] && split.highlight[7 * 15 + 8]);
    EXPECT_FALSE(split.highlight[11 * 15 + 11]) << "the lone pixel";
    EXPECT_FALSE(split.highlight[2 * 15 + 2]) << "the firefly";
    Image base, baseVariance;
    EXPECT_EQ(split.highlight,
              ref::SplitHighlights(color, &variance, 16, 3, &base, &baseVariance));
    EXPECT_EQ(split.base.data, base.data);
}

class HighlightsAwr : public GpuTest {};

// A small light (exact inside, a noisy rim) on a dim floor with a small variance: awr's
// shrinkage by the rim's variance rings the light into the floor, far worse than its input.
TEST_F(HighlightsAwr, SmallLightDoesNotRingIntoTheFloor) {
    const int w = 48, h = 40;
    Image truth(w, h, 3, 0.05f), color(w, h, 3), variance(w, h, 3);
    std::mt19937_64 rng(SeedFromName("highlights awr light"));
    std::normal_distribution<float> normal(0, 1);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                int dx = std::abs(x - 20), dy = std::abs(y - 17);
                bool inside = dx <= 2 && dy <= 2, rim = std::max(dx, dy) == 3;
                float t = inside ? 400.f : rim ? 150.f : 0.05f;
                float sd = inside ? 0.f : rim ? 40.f : 0.01f;
                truth.At(c, y, x) = t;
                color.At(c, y, x) = std::max(0.f, t + sd * normal(rng));
                variance.At(c, y, x) = sd * sd;
            }
    Frame frame = ColorAndVariance(color, variance);
    Device device = api::BorrowDevice(Ctx());
    double input = CompareImages(color, truth).relMse;
    Method awr("awr");
    Result split = awr.Run(device, frame);
    awr.Set("awr-highlights", 0.f);
    Result whole = awr.Run(device, frame);
    double withSplit = CompareImages(split.image, truth).relMse;
    double without = CompareImages(whole.image, truth).relMse;
    // The rim's energy no longer rings into the floor: a fraction of the error (the
    // light's interior, wider than half the window, still rings).
    EXPECT_GT(without, input) << "the case no longer shows the ringing";
    EXPECT_LT(withSplit, 0.5 * without);
    // The energy stays as awr leaves it: within 1% of the input's sum.
    double sumIn = 0, sumOut = 0;
    for (size_t i = 0; i < color.data.size(); ++i)
        sumIn += color.data[i], sumOut += split.image.data[i];
    EXPECT_NEAR(sumOut, sumIn, 0.02 * sumIn);
}

// A two-pixel reflection of a small light, seen by most samples, on a dim surface: awr's
// shrinkage by its variance left its energy in the coarse bands, which rang dark holes
// into the surface around it (the chrome sphere of a real frame, issue 29). Taken out as a
// highlight, the surface around it keeps its level.
TEST_F(HighlightsAwr, AReflectionDoesNotRingDarkHoles) {
    const int w = 40, h = 40;
    Image truth(w, h, 3, 0.05f), color(w, h, 3), variance(w, h, 3);
    std::mt19937_64 rng(SeedFromName("highlights awr reflection"));
    std::normal_distribution<float> normal(0, 1);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                bool spot = y == 20 && (x == 20 || x == 21);
                float t = spot ? 300.f : 0.05f, sd = spot ? 60.f : 0.01f;
                truth.At(c, y, x) = t;
                color.At(c, y, x) = std::max(0.f, t + sd * normal(rng));
                variance.At(c, y, x) = sd * sd;
            }
    Frame frame = ColorAndVariance(color, variance);
    Device device = api::BorrowDevice(Ctx());
    Result out = Method("awr").Run(device, frame);
    // The darkest pixel within 6 of the reflection, against the surface's level.
    float darkest = 1e30f;
    for (int y = 14; y <= 26; ++y)
        for (int x = 14; x <= 27; ++x)
            if (y != 20 || (x != 20 && x != 21))
                for (int c = 0; c < 3; ++c) darkest = std::min(darkest, out.image.At(c, y, x));
    EXPECT_GT(darkest, 0.5f * 0.05f) << "a dark hole beside the reflection";
}

// A bulb of radius sqrt(12) around (cx, cy), 500 with a noise of 5, on a floor of 0.05 with a
// noise of 0.005, seeded by name; each value's variance is its noise's.
// The host's split with sparse lights (k 16, radius 3, no given light sample) is the CPU
// twin's, mask and bases to the bit.
void ExpectSparseSplitMatchesTwin(const HighlightSplit &split, const Image &color,
                                  const Image &variance, const Image &maxSample) {
    Image base, baseVariance;
    std::vector<char> highlight =
        ref::SplitHighlights(color, &variance, 16, 3, &base, &baseVariance);
    ref::AddSparseLights(color, &variance, maxSample, 16, 3, -1, &highlight, &base,
                         &baseVariance);
    EXPECT_EQ(split.highlight, highlight);
    EXPECT_EQ(split.base.data, base.data);
    EXPECT_EQ(split.baseVariance.data, baseVariance.data);
}

// relMSE of `image` against `truth` over the 9x9 window whose top left is (x0, y0).
double WindowRelMse(const Image &image, const Image &truth, int x0, int y0) {
    Image a(9, 9, 3), b(9, 9, 3);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < 9; ++y)
            for (int x = 0; x < 9; ++x) {
                a.At(c, y, x) = image.At(c, y0 + y, x0 + x);
                b.At(c, y, x) = truth.At(c, y0 + y, x0 + x);
            }
    return CompareImages(a, b).relMse;
}

void NoisyBulb(const std::string &name, int cx, int cy, Image *color, Image *variance) {
    std::mt19937_64 rng(SeedFromName(name));
    std::normal_distribution<float> normal(0, 1);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < color->height; ++y)
            for (int x = 0; x < color->width; ++x) {
                bool bulb = (x - cx) * (x - cx) + (y - cy) * (y - cy) <= 12;
                float t = bulb ? 500.f : 0.05f, sd = bulb ? 5.f : 0.005f;
                color->At(c, y, x) = std::max(0.f, t + sd * normal(rng));
                variance->At(c, y, x) = sd * sd;
            }
}

// A bulb 7 pixels wide (a real frame's are wider: issue 29) on a dim floor. Inside, each
// pixel is its own window's median, so only the rim was a highlight: the interior went through
// the shrinkage and its energy spread into a bright halo with dark rings around the bulb.
// Grown from the rim, the whole bulb is a highlight and the floor around it keeps its level.
TEST_F(HighlightsAwr, AWideBulbDoesNotHaloIntoTheFloor) {
    const int w = 48, h = 48, cx = 24, cy = 22;
    Image color(w, h, 3), variance(w, h, 3);
    NoisyBulb("highlights awr wide bulb", cx, cy, &color, &variance);
    HighlightSplit split = SplitHighlights(color, &variance, 16, 3);
    EXPECT_TRUE(split.highlight[size_t(cy) * w + cx]) << "the bulb's centre";
    Frame frame = ColorAndVariance(color, variance);
    Device device = api::BorrowDevice(Ctx());
    Result out = Method("awr").Run(device, frame);
    // The floor 2-6 pixels from the bulb: no worse than the input, no value off by half.
    double errOut = 0, errIn = 0;
    float worst = 0;
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                double d = std::sqrt(double((x - cx) * (x - cx) + (y - cy) * (y - cy)));
                if (d < 2 + std::sqrt(12.0) || d > 6 + std::sqrt(12.0)) continue;
                errOut += std::pow(out.image.At(c, y, x) - 0.05, 2);
                errIn += std::pow(color.At(c, y, x) - 0.05, 2);
                worst = std::max(worst, std::abs(out.image.At(c, y, x) - 0.05f));
            }
    EXPECT_LT(errOut, errIn) << "awr worse than its input beside the bulb";
    EXPECT_LT(worst, 0.5f * 0.05f) << "a halo or ring beside the bulb";
    EXPECT_LT(errOut, 0.5 * errIn);
}

// A bulb's rim pixel that one sample of 16 saw (a quarter of it covered, read as a
// sixteenth): its standard deviation is its own mean, so it stands under two of them above the
// floor, as a firefly does. Beside a highlight it is the light's rim, not noise: grown, it
// keeps its input, and the floor beside it does not glow with the energy the synthesis spread
// from it (the bulb at a real frame's edge, issue 29).
TEST_F(HighlightsAwr, ARimPixelOneSampleSawIsGrown) {
    const int w = 128, h = 128, cx = 64, cy = 64, rx = cx - 4;
    Image color(w, h, 3), variance(w, h, 3);
    NoisyBulb("highlights awr one-sample rim", cx, cy, &color, &variance);
    for (int c = 0; c < 3; ++c) {
        color.At(c, cy, rx) = 500.f / 16;
        variance.At(c, cy, rx) = (500.f / 16) * (500.f / 16);
    }
    HighlightSplit split = SplitHighlights(color, &variance, 16, 3);
    EXPECT_TRUE(split.highlight[size_t(cy) * w + rx]) << "the rim pixel";
    Image base, baseVariance;
    EXPECT_EQ(split.highlight,
              ref::SplitHighlights(color, &variance, 16, 3, &base, &baseVariance));
    EXPECT_EQ(split.base.data, base.data);
    EXPECT_EQ(split.baseVariance.data, baseVariance.data);
    Frame frame = ColorAndVariance(color, variance);
    Device device = api::BorrowDevice(Ctx());
    Result out = Method("awr").Run(device, frame);
    // The floor within 2 pixels of the rim pixel, off the bulb: no value off by half.
    float worst = 0;
    for (int c = 0; c < 3; ++c)
        for (int y = cy - 2; y <= cy + 2; ++y)
            for (int x = rx - 2; x <= rx + 2; ++x)
                if ((x - cx) * (x - cx) + (y - cy) * (y - cy) > 12 && (x != rx || y != cy))
                    worst = std::max(worst, std::abs(out.image.At(c, y, x) - 0.05f));
    EXPECT_LT(worst, 0.5f * 0.05f) << "a glow beside the rim pixel";
}

// A 128 x 128 dim floor with a bulb at (32, 32), a light's reflection one sample of 16 saw
// at (84, 80) (its sample the bulb's) and a firefly at (80, 40) (its sample ten times the
// bulb's): the color, its variance, the largest sample (maxSample) and the truth.
struct LoneReflection {
    static constexpr int w = 128, h = 128, cx = 32, cy = 32;
    static constexpr Pixel reflection{84, 80}, firefly{80, 40};
    Image color{w, h, 3}, variance{w, h, 3}, maxSample, truth{w, h, 3, 0.05f};

    explicit LoneReflection(const std::string &name) {
        NoisyBulb(name, cx, cy, &color, &variance);
        maxSample = color;
        for (int c = 0; c < 3; ++c)
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x)
                    if ((x - cx) * (x - cx) + (y - cy) * (y - cy) <= 12)
                        truth.At(c, y, x) = 500;
        for (auto [p, sample, reference] :
             {std::tuple{reflection, 500.f, 60.f}, std::tuple{firefly, 5000.f, 0.05f}})
            for (int c = 0; c < 3; ++c) {
                color.At(c, p.y, p.x) = sample / 16;
                variance.At(c, p.y, p.x) = (sample / 16) * (sample / 16);
                maxSample.At(c, p.y, p.x) = sample;
                truth.At(c, p.y, p.x) = reference;
            }
    }
};

// The side x side tile of the frame's colour, variance and max layers whose top left is
// (x0, y0).
void CropTile(const LoneReflection &frame, int x0, int y0, int side, Image *tile,
              Image *tileVariance, Image *tileMax) {
    *tile = Image(side, side, 3), *tileVariance = Image(side, side, 3),
    *tileMax = Image(side, side, 3);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < side; ++y)
            for (int x = 0; x < side; ++x) {
                tile->At(c, y, x) = frame.color.At(c, y0 + y, x0 + x);
                tileVariance->At(c, y, x) = frame.variance.At(c, y0 + y, x0 + x);
                tileMax->At(c, y, x) = frame.maxSample.At(c, y0 + y, x0 + x);
            }
}

// A light's reflection one sample of 16 saw (a metal sphere's, issue 29) has a firefly's
// statistics: its standard deviation is as large as its mean, and it has no bright
// neighbour. awr spread it into a bright square where the reference is dim, worse than its
// input. Its sample is no brighter than the bulb the frame shows, so with the frame's max
// layer it is a sparse light and keeps its input; a firefly, its sample ten times the bulb's,
// is still spread.
TEST_F(HighlightsAwr, ALoneReflectionIsNotSpread) {
    // A frame large enough that the bulb leaves its mean under a sixteenth of the reflection.
    const LoneReflection lone("highlights awr lone reflection");
    const int w = lone.w;
    const Pixel reflection = lone.reflection, firefly = lone.firefly;
    const Image &color = lone.color, &variance = lone.variance, &maxSample = lone.maxSample,
                &truth = lone.truth;
    HighlightSplit split = SplitHighlights(color, &variance, 16, 3);
    ASSERT_GT(split.count, 0u) << "the bulb";
    EXPECT_FALSE(split.highlight[size_t(reflection.y) * w + reflection.x]);
    EXPECT_EQ(AddSparseLights(color, &variance, maxSample, 16, 3, -1, &split), 1u);
    EXPECT_TRUE(split.highlight[size_t(reflection.y) * w + reflection.x]);
    EXPECT_FALSE(split.highlight[size_t(firefly.y) * w + firefly.x]);
    ExpectSparseSplitMatchesTwin(split, color, variance, maxSample);

    // The relMSE over the reflection's 9x9 window.
    auto windowError = [&](const Image &image) {
        return WindowRelMse(image, truth, reflection.x - 4, reflection.y - 4);
    };
    Frame frame = ColorAndVariance(color, variance);
    Device device = api::BorrowDevice(Ctx());
    Method awr("awr");
    Result without = awr.Run(device, frame);
    frame.layers["max"] = maxSample;
    Result with = awr.Run(device, frame);
    const double input = windowError(color);
    EXPECT_GT(windowError(without.image), input) << "the case no longer shows the spread";
    EXPECT_LE(windowError(with.image), input);
    for (int c = 0; c < 3; ++c)
        EXPECT_LT(with.image.At(c, firefly.y, firefly.x),
                  0.5f * color.At(c, firefly.y, firefly.x))
            << "the firefly is no longer spread";
    // A max layer of one channel (the runs refuse or zero NaN/Inf before) serves no sparse
    // light: the run is the one without it, and the plan says why.
    Image oneChannel(w, lone.h, 1);
    for (int c = 0; c < 3; ++c)
        for (size_t p = 0; p < oneChannel.PixelCount(); ++p)
            oneChannel.data[p] = std::max(oneChannel.data[p], maxSample.Plane(c)[p]);
    frame.layers["max"] = oneChannel;
    Result off = awr.Run(device, frame);
    EXPECT_EQ(off.image.data, without.image.data);
    bool said = false;
    for (const std::string &line : off.plan)
        said |= line.find("sparse lights off: the max layer is not the color's shape") !=
                std::string::npos;
    EXPECT_TRUE(said) << ::testing::PrintToString(off.plan);
}

// A light's reflection two pixels tall (issue 29, the pair at (98, 114-115) of the accumulated
// glossy_lights): the brighter pixel, one sample of 16 saw, is a sparse light; the other, one
// sample of the reflection's faint edge, is under 8 x the frame's mean and beside only that
// one bright pixel, so no rule took it out, and awr spread it into the floor below: the 9x9
// window worse than the input. The sparse light's one bright neighbour, its sample under a
// quarter of the light's, keeps its input. A caustic's pair, the dimmer pixel's one sample 0.4
// x the light's (its value that sample over 16, under 16 x the mean), is still spread, as is
// the firefly.
TEST_F(HighlightsAwr, ATwoPixelReflectionIsNotSpread) {
    LoneReflection pair("highlights awr two-pixel reflection");
    const int w = pair.w;
    const Pixel top = pair.reflection, bottom{top.x, top.y + 1};
    const Pixel causticTop{40, 96}, causticBottom{40, 97};
    for (auto [p, value, sample, reference] : {std::tuple{bottom, 6.f, 96.f, 5.f},
                                               {causticTop, 500.f / 16, 500.f, 0.05f},
                                               {causticBottom, 200.f / 16, 200.f, 0.05f}})
        for (int c = 0; c < 3; ++c) {
            pair.color.At(c, p.y, p.x) = value;
            pair.variance.At(c, p.y, p.x) = value * value;
            pair.maxSample.At(c, p.y, p.x) = sample;
            pair.truth.At(c, p.y, p.x) = reference;
        }
    const Image &color = pair.color, &variance = pair.variance, &maxSample = pair.maxSample;
    const double mean = HighlightFrameMean(color);
    ASSERT_GT(3 * color.At(0, top.y, top.x), 16 * mean) << "the top pixel, a sparse light";
    ASSERT_LT(3 * color.At(0, bottom.y, bottom.x), 8 * mean) << "the bottom one, not";
    ASSERT_LT(3 * color.At(0, causticBottom.y, causticBottom.x), 16 * mean)
        << "the caustic's dimmer pixel, not";
    HighlightSplit split = SplitHighlights(color, &variance, 16, 3);
    EXPECT_EQ(AddSparseLights(color, &variance, maxSample, 16, 3, -1, &split), 3u);
    auto marked = [&](Pixel p) { return split.highlight[size_t(p.y) * w + p.x] != 0; };
    EXPECT_TRUE(marked(top) && marked(bottom) && marked(causticTop));
    EXPECT_FALSE(marked(causticBottom)) << "the caustic's pair";
    EXPECT_FALSE(marked(pair.firefly));
    ExpectSparseSplitMatchesTwin(split, color, variance, maxSample);

    Frame frame = ColorAndVariance(color, variance);
    frame.layers["max"] = maxSample;
    Device device = api::BorrowDevice(Ctx());
    Result out = Method("awr").Run(device, frame);
    const double input = WindowRelMse(color, pair.truth, top.x - 4, top.y - 3);
    EXPECT_LE(WindowRelMse(out.image, pair.truth, top.x - 4, top.y - 3), input);
    for (int c = 0; c < 3; ++c) {
        EXPECT_LT(out.image.At(c, causticBottom.y, causticBottom.x),
                  0.75f * color.At(c, causticBottom.y, causticBottom.x))
            << "the caustic's pair is no longer spread";
        EXPECT_LT(out.image.At(c, pair.firefly.y, pair.firefly.x),
                  0.5f * color.At(c, pair.firefly.y, pair.firefly.x))
            << "the firefly is no longer spread";
    }
}

// A sparse light's partner is the one pixel beside it over its window, with no other such
// neighbour itself, not yet a highlight. On a dim floor with a light 7 x 9 pixels (its rim
// seeds, grown through): a two-pixel reflection, whose dimmer pixel joins; a sparse light
// between two dim pixels over their windows (a streak's or a rim's noise: neither joins); a
// line of a sparse light and two dim pixels (the first has two neighbours over their windows,
// the light and the last: neither joins, both are left to the filter as before the rule); and
// a sparse light whose one such neighbour is a pixel grown from the light's edge (it keeps
// its grown base and is counted once).
TEST(Highlights, ASparseLightsPartnerIsItsOnlyBrightNeighbour) {
    const int w = 128, h = 128;
    Image color(w, h, 3), variance(w, h, 3), maxSample;
    std::mt19937_64 rng(SeedFromName("highlights sparse light partners"));
    std::normal_distribution<float> normal(0, 1);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const bool light = x >= 20 && x < 27 && y >= 20 && y < 29;
                const float t = light ? 500.f : 0.05f, sd = light ? 5.f : 0.005f;
                color.At(c, y, x) = std::max(0.f, t + sd * normal(rng));
                variance.At(c, y, x) = sd * sd;
            }
    maxSample = color;
    // Sparse lights (one sample of 16, under twice the light's) and dim one-sample pixels
    // over their windows (a sample under a quarter of the lights'); `grown` an exact pixel
    // beside the light's edge, the grown light's.
    const Pixel grown{27, 24}, besideGrown{28, 24};
    const Pixel pairLight{90, 60}, pairDim{90, 61};
    const Pixel between{60, 30}, above{60, 29}, below{60, 31};
    const Pixel lineLight{60, 90}, lineNear{60, 91}, lineFar{60, 92};
    for (Pixel p : {besideGrown, pairLight, between, lineLight})
        for (int c = 0; c < 3; ++c) {
            color.At(c, p.y, p.x) = 50;
            variance.At(c, p.y, p.x) = 50 * 50;
            maxSample.At(c, p.y, p.x) = 800;
        }
    for (Pixel p : {pairDim, above, below, lineNear, lineFar})
        for (int c = 0; c < 3; ++c) {
            color.At(c, p.y, p.x) = 6;
            variance.At(c, p.y, p.x) = 6 * 6;
            maxSample.At(c, p.y, p.x) = 96;
        }
    for (int c = 0; c < 3; ++c) {
        color.At(c, grown.y, grown.x) = maxSample.At(c, grown.y, grown.x) = 40;
        variance.At(c, grown.y, grown.x) = 0.01f;
    }
    ASSERT_GT(150, 16 * HighlightFrameMean(color)) << "the sparse lights, over k x the mean";
    const HighlightSplit before = SplitHighlights(color, &variance, 16, 3);
    auto at = [&](Pixel p) { return size_t(p.y) * w + p.x; };
    ASSERT_TRUE(before.highlight[at(grown)] && before.grown > 0) << "the grown pixel";
    for (Pixel p :
         {besideGrown, pairLight, between, lineLight, pairDim, above, below, lineNear, lineFar})
        ASSERT_FALSE(before.highlight[at(p)]) << p.x << ", " << p.y;

    HighlightSplit split = before;
    EXPECT_EQ(AddSparseLights(color, &variance, maxSample, 16, 3, -1, &split), 5u);
    EXPECT_EQ(split.count, before.count + 5);
    for (Pixel p : {besideGrown, pairLight, between, lineLight, pairDim})
        EXPECT_TRUE(split.highlight[at(p)]) << p.x << ", " << p.y;
    EXPECT_FALSE(split.highlight[at(above)] || split.highlight[at(below)])
        << "a sparse light's two dim neighbours";
    EXPECT_FALSE(split.highlight[at(lineNear)] || split.highlight[at(lineFar)]) << "the line";
    for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(split.base.At(c, grown.y, grown.x), before.base.At(c, grown.y, grown.x));
        EXPECT_EQ(split.baseVariance.At(c, grown.y, grown.x),
                  before.baseVariance.At(c, grown.y, grown.x));
    }
    ExpectSparseSplitMatchesTwin(split, color, variance, maxSample);
}

// A glossy surface's reflection of a light one sample per pixel saw (a streak of glints on
// the edge of a floor, issue 29): each glint under 16 x the frame's mean, so no sparse light by
// that rule, and awr spread the streak across the edge into the dark side, its 9x9 window
// worse than its input. A streak's glints whose largest sample is at most half the bulb's are
// sparse lights from 8 x the mean; a caustic's block as dim, its sample over half the bulb's,
// is still spread, as are a lone glint and a pair of them (no 2 bright neighbours: a firefly's
// and its neighbour's) and a streak's block under 8 x the mean.
TEST_F(HighlightsAwr, AGlintStreakIsNotSpreadAcrossItsEdge) {
    const int w = 128, h = 128, edge = 80;
    const Pixel streak{60, edge - 2}, caustic{60, 30}, lone{100, 12}, pair{112, 24},
        dim{96, 36};
    Image color(w, h, 3), variance(w, h, 3);
    NoisyBulb("highlights awr glint streak", 32, 32, &color, &variance);
    Image truth(w, h, 3, 0.05f);
    // The floor below the edge is a fifth as bright (and as noisy).
    for (int c = 0; c < 3; ++c)
        for (int y = edge; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                color.At(c, y, x) *= 0.2f;
                variance.At(c, y, x) *= 0.04f;
                truth.At(c, y, x) = 0.01f;
            }
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                if ((x - 32) * (x - 32) + (y - 32) * (y - 32) <= 12) truth.At(c, y, x) = 500;
    Image maxSample = color;
    // One-sample pixels (rows x columns): the streak's 2 x 4 samples 224 a channel (under half
    // the bulb's 1500 summed), the caustic's 2 x 4 288 (over half of it), a lone glint's and a
    // 1 x 2 pair's 224.
    auto place = [&](Pixel at, int rows, int columns, float sample, float value) {
        for (int c = 0; c < 3; ++c)
            for (int y = at.y; y < at.y + rows; ++y)
                for (int x = at.x; x < at.x + columns; ++x) {
                    color.At(c, y, x) = value;
                    variance.At(c, y, x) = value * value;
                    maxSample.At(c, y, x) = sample;
                    truth.At(c, y, x) = 0.6f * value;
                }
    };
    for (auto [at, rows, columns, sample] : {std::tuple{streak, 2, 4, 224.f},
                                             {caustic, 2, 4, 288.f},
                                             {lone, 1, 1, 224.f},
                                             {pair, 1, 2, 224.f}})
        place(at, rows, columns, sample, sample / 16);
    // A streak's 2 x 4 block at about two fifths of 16 x the mean, its samples the streak's.
    place(dim, 2, 4, 224.f, float(0.4 * 16 * HighlightFrameMean(color) / 3));
    const double mean = HighlightFrameMean(color);
    ASSERT_GT(3 * 224.f / 16, 8 * mean);
    ASSERT_LT(3 * 288.f / 16, 16 * mean) << "the blocks are under the old rule's floor";
    ASSERT_LT(3 * color.At(0, dim.y, dim.x), 8 * mean) << "the dim block";
    ASSERT_GT(3 * color.At(0, dim.y, dim.x), 5 * mean) << "the dim block, near 0.4 x k";
    HighlightSplit split = SplitHighlights(color, &variance, 16, 3);
    EXPECT_EQ(AddSparseLights(color, &variance, maxSample, 16, 3, -1, &split), 8u);
    auto marked = [&](Pixel p) { return split.highlight[size_t(p.y) * w + p.x] != 0; };
    EXPECT_TRUE(marked(streak));
    EXPECT_FALSE(marked(caustic));
    EXPECT_FALSE(marked(lone)) << "the lone glint";
    EXPECT_FALSE(marked(pair) || marked({pair.x + 1, pair.y})) << "the pair";
    EXPECT_FALSE(marked(dim)) << "the block under k / 2 x the mean";
    ExpectSparseSplitMatchesTwin(split, color, variance, maxSample);

    // The relMSE over the 9x9 window round the streak's block.
    auto windowError = [&](const Image &image) {
        return WindowRelMse(image, truth, streak.x - 2, streak.y - 3);
    };
    Frame frame = ColorAndVariance(color, variance);
    frame.layers["max"] = maxSample;
    Device device = api::BorrowDevice(Ctx());
    Result out = Method("awr").Run(device, frame);
    EXPECT_LE(windowError(out.image), windowError(color));
    for (auto [p, what] : {std::pair{caustic, "the caustic's block"},
                           {lone, "the lone glint"},
                           {pair, "the pair"},
                           {dim, "the dim block"}})
        for (int c = 0; c < 3; ++c)
            EXPECT_LT(out.image.At(c, p.y, p.x), 0.75f * color.At(c, p.y, p.x))
                << what << " is no longer spread";
}

// A tile cut tight around a bulb has a mean near the bulb's own, so with that mean the growth's
// stop (k x the mean) keeps the bulb's interior out; given the whole frame's mean, as awr's
// tiles are, it grows as it does in the whole frame.
TEST(Highlights, ATileReadsTheFramesMean) {
    const int w = 48, h = 48, cx = 24, cy = 22, half = 5;
    Image color(w, h, 3), variance(w, h, 3);
    NoisyBulb("highlights tile mean", cx, cy, &color, &variance);
    const int side = 2 * half + 1;
    Image tile(side, side, 3), tileVariance(side, side, 3);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < side; ++y)
            for (int x = 0; x < side; ++x) {
                tile.At(c, y, x) = color.At(c, cy - half + y, cx - half + x);
                tileVariance.At(c, y, x) = variance.At(c, cy - half + y, cx - half + x);
            }
    HighlightSplit whole = SplitHighlights(color, &variance, 16, 3);
    HighlightSplit own = SplitHighlights(tile, &tileVariance, 16, 3);
    HighlightSplit given =
        SplitHighlights(tile, &tileVariance, 16, 3, HighlightFrameMean(color));
    ASSERT_TRUE(whole.highlight[size_t(cy) * w + cx]) << "the bulb's centre, whole frame";
    EXPECT_GT(own.count, 0u) << "the tile's seeds";
    EXPECT_EQ(own.grown, 0u) << "the tile's own mean stops the growth";
    EXPECT_GT(given.grown, 0u);
    EXPECT_TRUE(given.highlight[size_t(half) * side + half]) << "the bulb's centre, tile";
    for (int y = 0; y < side; ++y)
        for (int x = 0; x < side; ++x)
            EXPECT_EQ(given.highlight[size_t(y) * side + x],
                      whole.highlight[size_t(cy - half + y) * w + cx - half + x])
                << x << ", " << y;
}

// A tile holding the reflection one sample saw but not the bulb has no highlights of its own:
// with them it would keep the reflection out (and awr spread it), so the output would
// depend on the tile grid. Given the whole frame's highlights' median largest sample, as
// awr's tiles are, it marks the reflection as the whole frame does.
TEST(Highlights, ATileComparesSparseLightsWithTheFramesLights) {
    const LoneReflection frame("highlights tile sparse lights");
    const int w = frame.w, half = 8, side = 2 * half + 1;
    const Pixel reflection = frame.reflection;
    const int x0 = reflection.x - half, y0 = reflection.y - half;
    HighlightSplit whole = SplitHighlights(frame.color, &frame.variance, 16, 3);
    const double frameMean = HighlightFrameMean(frame.color),
                 lightSample = HighlightSampleMedian(frame.maxSample, whole.highlight);
    ASSERT_GT(lightSample, 0) << "the bulb";
    AddSparseLights(frame.color, &frame.variance, frame.maxSample, 16, 3, -1, &whole);
    ASSERT_TRUE(whole.highlight[size_t(reflection.y) * w + reflection.x]);
    Image tile, tileVariance, tileMax;
    CropTile(frame, x0, y0, side, &tile, &tileVariance, &tileMax);
    HighlightSplit own = SplitHighlights(tile, &tileVariance, 16, 3, frameMean);
    EXPECT_EQ(own.count, 0u) << "the tile holds no light";
    EXPECT_EQ(AddSparseLights(tile, &tileVariance, tileMax, 16, 3, -1, &own), 0u);
    HighlightSplit given = SplitHighlights(tile, &tileVariance, 16, 3, frameMean);
    EXPECT_EQ(AddSparseLights(tile, &tileVariance, tileMax, 16, 3, lightSample, &given), 1u);
    EXPECT_TRUE(given.highlight[size_t(half) * side + half]) << "the reflection, tile";
    for (int y = 0; y < side; ++y)
        for (int x = 0; x < side; ++x)
            EXPECT_EQ(given.highlight[size_t(y) * side + x],
                      whole.highlight[size_t(y0 + y) * w + x0 + x])
                << x << ", " << y;
    for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(given.base.At(c, half, half), whole.base.At(c, reflection.y, reflection.x));
        EXPECT_EQ(given.baseVariance.At(c, half, half),
                  whole.baseVariance.At(c, reflection.y, reflection.x));
    }
}

// A glint streak (2 x 4 one-sample pixels, under k but over k / 2 x the frame's mean, its
// samples under half the bulb's) in a tile without a light: with none of its own to compare
// with it stays out; given the frame's mean and lights' sample, the tile marks it as the whole
// frame does, and with a sample given that holds the streak's out, leaves it as the frame
// does.
TEST(Highlights, ATileComparesAStreakWithTheFramesLights) {
    LoneReflection frame("highlights tile streak");
    const int w = frame.w, half = 8, side = 2 * half + 1;
    const Pixel streak{40, 100};
    const int x0 = streak.x - half, y0 = streak.y - half;
    for (int c = 0; c < 3; ++c)
        for (int y = streak.y; y < streak.y + 2; ++y)
            for (int x = streak.x; x < streak.x + 4; ++x) {
                frame.color.At(c, y, x) = 224.f / 16;
                frame.variance.At(c, y, x) = (224.f / 16) * (224.f / 16);
                frame.maxSample.At(c, y, x) = 224;
            }
    const HighlightSplit split = SplitHighlights(frame.color, &frame.variance, 16, 3);
    const double frameMean = HighlightFrameMean(frame.color),
                 lightSample = HighlightSampleMedian(frame.maxSample, split.highlight);
    ASSERT_GT(3 * 224.f / 16, kStreakMeanShare * 16 * frameMean);
    ASSERT_LT(3 * 224.f / 16, 16 * frameMean);
    ASSERT_LE(3 * 224.f, kStreakSampleRatio * lightSample);
    Image tile, tileVariance, tileMax;
    CropTile(frame, x0, y0, side, &tile, &tileVariance, &tileMax);
    HighlightSplit own = SplitHighlights(tile, &tileVariance, 16, 3);
    EXPECT_EQ(own.count, 0u) << "the tile holds no light";
    EXPECT_EQ(AddSparseLights(tile, &tileVariance, tileMax, 16, 3, -1, &own), 0u)
        << "the tile's own lights";
    for (double given : {lightSample, lightSample / 2}) {
        SCOPED_TRACE(testing::Message() << "light sample " << given);
        HighlightSplit whole = split;
        AddSparseLights(frame.color, &frame.variance, frame.maxSample, 16, 3, given, &whole);
        Image base, baseVariance;
        std::vector<char> expected =
            ref::SplitHighlights(frame.color, &frame.variance, 16, 3, &base, &baseVariance);
        ref::AddSparseLights(frame.color, &frame.variance, frame.maxSample, 16, 3, given,
                             &expected, &base, &baseVariance);
        EXPECT_EQ(whole.highlight, expected) << "the twin";
        EXPECT_EQ(whole.base.data, base.data) << "the twin";
        HighlightSplit cut = SplitHighlights(tile, &tileVariance, 16, 3, frameMean);
        EXPECT_EQ(cut.mean, frameMean);
        const size_t added = AddSparseLights(tile, &tileVariance, tileMax, 16, 3, given, &cut);
        EXPECT_EQ(added, given == lightSample ? 8u : 0u);
        for (int y = 0; y < side; ++y)
            for (int x = 0; x < side; ++x) {
                const size_t p = size_t(y0 + y) * w + x0 + x;
                EXPECT_EQ(cut.highlight[size_t(y) * side + x], whole.highlight[p])
                    << x << ", " << y;
                for (int c = 0; c < 3 && whole.highlight[p]; ++c) {
                    EXPECT_EQ(cut.base.At(c, y, x), whole.base.At(c, y0 + y, x0 + x));
                    EXPECT_EQ(cut.baseVariance.At(c, y, x),
                              whole.baseVariance.At(c, y0 + y, x0 + x));
                }
            }
    }
}

// A ceiling panel 24 pixels wide is its own median but for its corners; grown from them it
// would take the panel's rim into highlights ring by ring (the cornell light). Still growing
// after the last round, its growth is undone; a bulb in the same frame still fills.
TEST(Highlights, ALargeLightDoesNotGrow) {
    const int w = 128, h = 128, x0 = 8, y0 = 8, size = 24, bx = 100, by = 100;
    Image color(w, h, 3), variance(w, h, 3);
    std::mt19937_64 rng(SeedFromName("highlights large light"));
    std::normal_distribution<float> normal(0, 1);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                bool panel = x >= x0 && x < x0 + size && y >= y0 && y < y0 + size;
                bool bulb = (x - bx) * (x - bx) + (y - by) * (y - by) <= 12;
                float t = panel || bulb ? 500.f : 0.05f, sd = panel || bulb ? 5.f : 0.005f;
                color.At(c, y, x) = std::max(0.f, t + sd * normal(rng));
                variance.At(c, y, x) = sd * sd;
            }
    HighlightSplit split = SplitHighlights(color, &variance, 16, 3);
    // Three pixels in from each corner: no window there is mostly dark, so only growth marks
    // it.
    for (auto [x, y] : {std::pair{x0 + 3, y0 + 3},
                        {x0 + size - 4, y0 + 3},
                        {x0 + 3, y0 + size - 4},
                        {x0 + size - 4, y0 + size - 4}}) {
        EXPECT_FALSE(split.highlight[size_t(y) * w + x]) << "grown into the panel at " << x;
        EXPECT_EQ(split.base.At(0, y, x), color.At(0, y, x));
    }
    EXPECT_TRUE(split.highlight[size_t(by) * w + bx]) << "the bulb's centre";
    Image base, baseVariance;
    std::vector<char> mask =
        ref::SplitHighlights(color, &variance, 16, 3, &base, &baseVariance);
    EXPECT_EQ(split.highlight, mask);
    EXPECT_EQ(split.base.data, base.data);
    EXPECT_EQ(split.baseVariance.data, baseVariance.data);
}

// A glow the synthesis spread beside a light: values within reach of a highlight above the
// input's 3x3 maximum (highlights left out) are lowered to it; those beyond reach, and troughs,
// are left.
TEST(Highlights, CrestsNearLightsAreCut) {
    Image color(20, 9, 3, 0.1f);
    std::vector<char> highlight(20 * 9, 0);
    for (int c = 0; c < 3; ++c) color.At(c, 4, 3) = 500;
    highlight[4 * 20 + 3] = 1;
    Image output(20, 9, 3, 0.1f);
    for (int c = 0; c < 3; ++c) {
        output.At(c, 4, 5) = 0.4f;   // a glow 2 pixels from the light
        output.At(c, 4, 15) = 0.4f;  // a crest 12 pixels away
        output.At(c, 2, 4) = 0.05f;  // a trough beside it
    }
    Image expected = output;
    EXPECT_EQ(LowerToInputMaximumNearHighlights(color, highlight, 6, 1, &output), 3u);
    for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(output.At(c, 4, 5), 0.1f) << "the glow beside the light";
        EXPECT_EQ(output.At(c, 4, 15), 0.4f) << "the crest beyond reach";
        EXPECT_EQ(output.At(c, 2, 4), 0.05f) << "the trough";
        EXPECT_EQ(output.At(c, 4, 3), 0.1f) << "the highlight itself";
    }
    ref::LowerToInputMaximumNearHighlights(color, highlight, 6, 1, &expected);
    EXPECT_EQ(output.data, expected.data);
}

// A 64 x 48 dim floor (0.05, a small variance) with a ceiling panel of 24 x 4 pixels at 30 a
// channel, sure of itself (a small variance), and a rim row above and below it that the
// panel's edge crosses: each rim pixel `covered` (a quarter unless told), its 16 samples 30 or
// 0.05, so its mean a binomial count of sixteenths and its largest sample 30 where any sample
// hit. The color, its variance, the largest sample and the truth (the rim that share of the
// panel).
struct PanelLight {
    static constexpr int w = 64, h = 48, x0 = 20, x1 = 44, y0 = 20, y1 = 24;
    Image color{w, h, 3}, variance{w, h, 3}, maxSample{w, h, 3}, truth{w, h, 3, 0.05f};

    explicit PanelLight(const std::string &name, float covered = 0.25f) {
        std::mt19937_64 rng(SeedFromName(name));
        std::normal_distribution<float> normal(0, 1);
        std::binomial_distribution<int> hits(16, covered);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const bool panel = x >= x0 && x < x1 && y >= y0 && y < y1;
                const bool rim = x >= x0 && x < x1 && (y == y0 - 1 || y == y1);
                const int n = rim ? hits(rng) : 0;
                for (int c = 0; c < 3; ++c) {
                    float value, var, top;
                    if (panel) {
                        value = 30 + 0.05f * normal(rng), var = 0.0025f, top = value + 0.1f;
                    } else if (rim) {
                        const float p = n / 16.f;
                        value = 30 * p + 0.05f * (1 - p);
                        var = 30.f * 30.f * p * (1 - p) / 16;
                        top = n ? 30.f : 0.05f;
                        truth.At(c, y, x) = 30 * covered + 0.05f * (1 - covered);
                    } else {
                        value = std::max(0.f, 0.05f + 0.005f * normal(rng));
                        var = 0.005f * 0.005f, top = value + 0.01f;
                    }
                    if (panel) truth.At(c, y, x) = 30;
                    color.At(c, y, x) = value, variance.At(c, y, x) = var;
                    maxSample.At(c, y, x) = top;
                }
            }
    }
};

// Lights and rims, and the cut beyond them, against the twin: on the panel, on a frame with
// a rim pixel every sample missed beside the panel's full interior (kept: the spread may be
// its light) and a pixel beside a light the edge crosses and no full light (cut: past the
// light's edge), and on the noisy frames MakeFrame makes (a wide light among them).
TEST(Highlights, LightRimsMatchReference) {
    PanelLight panel("highlights light rims twin");
    const int w = panel.w, h = panel.h;
    // A rim pixel every sample missed; two pixels the panel's edge crosses (two thirds
    // covered, 20 a channel): one in its bottom row, one past its right side.
    const int crossX = PanelLight::x1, crossY = PanelLight::y0 + 1;
    for (int c = 0; c < 3; ++c) {
        panel.color.At(c, PanelLight::y0 - 1, 30) = 0.05f;
        panel.variance.At(c, PanelLight::y0 - 1, 30) = 0;
        panel.maxSample.At(c, PanelLight::y0 - 1, 30) = 0.05f;
        for (auto [x, y] : {std::pair{40, PanelLight::y1 - 1}, {crossX, crossY}}) {
            panel.color.At(c, y, x) = 20;
            panel.variance.At(c, y, x) = 0.0025f;
            panel.maxSample.At(c, y, x) = 20.1f;
        }
    }
    const double mean = HighlightFrameMean(panel.color);
    auto sumAt = [&](int x, int y) {
        return panel.color.At(0, y, x) + panel.color.At(1, y, x) + panel.color.At(2, y, x);
    };
    // The crossed pixels are lights (over 16 x the mean), not full ones (under 0.75 x the
    // panel beside them): the frame's numbers, not luck.
    ASSERT_GT(sumAt(crossX, crossY), 16 * mean);
    ASSERT_LT(sumAt(crossX, crossY), kFullLightShare * sumAt(crossX - 1, crossY));
    LightRims rims = FindLightRims(panel.color, panel.variance, &panel.maxSample, 16, mean);
    // The lights: the panel (the crossed pixel in it too), the crossed pixel past it, and the
    // rim pixels whose binomial mean (s^2 >= 16 v where a quarter or more of the samples hit)
    // passes 16 x the mean.
    size_t rimLights = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const bool inPanel = x >= PanelLight::x0 && x < PanelLight::x1 &&
                                 y >= PanelLight::y0 && y < PanelLight::y1;
            const bool rimRow = x >= PanelLight::x0 && x < PanelLight::x1 &&
                                (y == PanelLight::y0 - 1 || y == PanelLight::y1);
            const bool rimLight = rimRow && sumAt(x, y) > 16 * mean;
            rimLights += rimLight;
            EXPECT_EQ(bool(rims.light[size_t(y) * w + x]),
                      inPanel || (x == crossX && y == crossY) || rimLight)
                << x << "," << y << " (sum " << sumAt(x, y) << ")";
        }
    EXPECT_EQ(rims.lights, size_t(24 * 4 + 1) + rimLights);
    Image output(w, h, 3, 0.5f), expected = output;
    EXPECT_GT(
        ClampBeyondLightRims(panel.color, panel.variance, rims, kLightRimReach, 1, &output),
        0u);
    // The twin takes the frame's own mean (-1), the host HighlightFrameMean.
    ref::ClampBeyondLightRims(panel.color, panel.variance, &panel.maxSample, 16, -1,
                              kLightRimReach, 1, &expected);
    EXPECT_EQ(output.data, expected.data);
    // Troughs: an output of 0 (the floor is 0.05) is raised within kFullLightReach of the
    // panel's full interior, past the rim's reach too, and left beyond it.
    Image dark(w, h, 3, 0.f), darkWant = dark;
    EXPECT_GT(ClampBeyondLightRims(panel.color, panel.variance, rims, kLightRimReach, 1, &dark),
              0u);
    ref::ClampBeyondLightRims(panel.color, panel.variance, &panel.maxSample, 16, -1,
                              kLightRimReach, 1, &darkWant);
    EXPECT_EQ(dark.data, darkWant.data);
    for (int c = 0; c < 3; ++c) {
        EXPECT_GT(dark.At(c, PanelLight::y0 - 1 - kFullLightReach + 1, 25), 0.02f)
            << "a trough within reach of the full light";
        EXPECT_EQ(dark.At(c, PanelLight::y0 - 1 - kFullLightReach, 25), 0.f) << "out of reach";
    }
    for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(output.At(c, PanelLight::y0 - 1, 30), 0.5f) << "the missed rim pixel";
        EXPECT_LT(output.At(c, PanelLight::y0 - 2, 25), 0.1f) << "past the top rim";
        EXPECT_LT(output.At(c, PanelLight::y1 + 1, 40), 0.1f) << "past the crossed pixel";
        // Beside the crossed pixel past the panel's side and beside no full light: cut (with
        // every light full it would be kept as a rim).
        EXPECT_LT(output.At(c, crossY, crossX + 1), 0.1f) << "beside a light, not a full one";
        EXPECT_EQ(output.At(c, 2, 2), 0.5f) << "out of reach";
    }
    // Rims crossed over half: noisy lights, some over 0.75 x the panel, no full ones.
    PanelLight covered("highlights awr half-covered rim", 0.55f);
    Image coveredOut(w, h, 3, 0.5f), coveredWant = coveredOut;
    LightRims coveredRims = FindLightRims(covered.color, covered.variance, &covered.maxSample,
                                          16, HighlightFrameMean(covered.color));
    EXPECT_GT(ClampBeyondLightRims(covered.color, covered.variance, coveredRims, kLightRimReach,
                                   1, &coveredOut),
              0u);
    ref::ClampBeyondLightRims(covered.color, covered.variance, &covered.maxSample, 16, -1,
                              kLightRimReach, 1, &coveredWant);
    EXPECT_EQ(coveredOut.data, coveredWant.data);
    // Without a max layer: lights, no rims; NaN in the variance: nothing.
    EXPECT_EQ(FindLightRims(panel.color, panel.variance, nullptr, 16, mean).rims, 0u);
    Image broken = panel.variance;
    broken.At(0, 0, 0) = std::numeric_limits<float>::quiet_NaN();
    EXPECT_EQ(FindLightRims(panel.color, broken, &panel.maxSample, 16, mean).lights, 0u);
    for (int channels : {1, 3})
        for (auto [fw, fh] : {std::pair{1, 1}, {3, 2}, {17, 13}, {44, 33}})
            for (double k : {4.0, 16.0}) {
                Image color, variance;
                MakeFrame(fw, fh, channels, k, &color, &variance);
                Image maxSample = color;
                for (size_t i = 0; i < maxSample.data.size(); ++i)
                    maxSample.data[i] += 4 * std::sqrt(variance.data[i]);
                const double frameMean = HighlightFrameMean(color);
                // Crests and troughs: the color plus or minus twice a shuffled color, and a
                // NaN and an Inf in the output (left).
                for (float sign : {2.f, -2.f}) {
                    Image got(fw, fh, channels), want;
                    const size_t n = got.data.size();
                    for (size_t i = 0; i < n; ++i)
                        got.data[i] = color.data[i] + sign * color.data[(i * 7919) % n];
                    got.data[n / 2] = std::numeric_limits<float>::quiet_NaN();
                    got.data[n / 3] = -std::numeric_limits<float>::infinity();
                    want = got;
                    ClampBeyondLightRims(
                        color, variance,
                        FindLightRims(color, variance, &maxSample, k, frameMean), 1, 1, &got);
                    ref::ClampBeyondLightRims(color, variance, &maxSample, k, -1, 1, 1, &want);
                    // Bit for bit, NaN included.
                    EXPECT_EQ(0,
                              std::memcmp(got.data.data(), want.data.data(), n * sizeof(float)))
                        << fw << "x" << fh << "x" << channels << " " << k << " " << sign;
                }
            }
}

// The light's sum is in float, in channel order, in the host and its twin alike: a pixel of
// 2^24, 1 and 1 sums to 2^24 in float (2^24 + 2 in double), under a threshold of 2^24 + 1,
// so it is no light and the pixel past its would-be rim keeps its value.
TEST(Highlights, LightRimsSumChannelsInFloat) {
    Image color(5, 1, 3, 0.05f), variance(5, 1, 3, 0.f), maxSample = color;
    color.At(0, 0, 2) = 16777216.f, color.At(1, 0, 2) = 1, color.At(2, 0, 2) = 1;
    maxSample.At(0, 0, 3) = 16777216.f;
    const double frameMean = 16777217;
    Image output(5, 1, 3, 0.5f), expected = output;
    LightRims rims = FindLightRims(color, variance, &maxSample, 1, frameMean);
    EXPECT_EQ(rims.lights, 0u);
    ClampBeyondLightRims(color, variance, rims, 1, 1, &output);
    ref::ClampBeyondLightRims(color, variance, &maxSample, 1, frameMean, 1, 1, &expected);
    EXPECT_EQ(output.data, expected.data);
    EXPECT_EQ(output.At(0, 0, 4), 0.5f);
}

// awr at its defaults on the panel's colour, variance and largest sample.
Result RunAwrOnPanel(const PanelLight &panel) {
    Frame frame = ColorAndVariance(panel.color, panel.variance);
    frame.layers["max"] = panel.maxSample;
    Device device = api::BorrowDevice(TestContext());
    return Method("awr").Run(device, frame);
}

// The largest error of awr's output in the rows just past the panel's rims, over its width.
float WorstPastRims(const Image &image, const PanelLight &panel) {
    float worst = 0;
    for (int c = 0; c < 3; ++c)
        for (int y : {PanelLight::y0 - 2, PanelLight::y1 + 1})
            for (int x = PanelLight::x0; x < PanelLight::x1; ++x)
                worst = std::max(worst, std::abs(image.At(c, y, x) - panel.truth.At(c, y, x)));
    return worst;
}

// A large light's noisy rim (a ceiling panel's edge, our cornell at 4-64 spp): the filter
// spread it into the dim rows past it, worse than the input there. The values past the rim
// are lowered to the input's maximum over their window, rims and lights left out.
TEST_F(HighlightsAwr, ALargeLightsRimDoesNotGlowPastIt) {
    PanelLight panel("highlights awr panel rim");
    Result out = RunAwrOnPanel(panel);
    // The row past each rim, over the panel's width: no value off by half the floor (the
    // floor's own noise is a tenth of it).
    float worst = WorstPastRims(out.image, panel);
    EXPECT_LT(worst, 0.5f * 0.05f) << "a glow past the rim";
}

// The panel's edge crossing its rim rows over half (cornell at 256x256, 16 spp): a crossed
// pixel whose samples hit the light 12 or 13 times in 16 reaches 0.75 x the panel, yet it is
// no full light (its standard deviation says the edge crosses it), so the row past it is cut
// like the rest and no blotch stays beside it.
TEST_F(HighlightsAwr, AHalfCoveredRimDoesNotGlowPastIt) {
    PanelLight panel("highlights awr half-covered rim", 0.55f);
    // The frame's numbers, not luck: crossed pixels over 0.75 x the panel are there, and
    // none that 14 or more samples hit (full within 2 standard deviations: the light's).
    int overShare = 0;
    for (int y : {PanelLight::y0 - 1, PanelLight::y1})
        for (int x = PanelLight::x0; x < PanelLight::x1; ++x) {
            overShare += panel.color.At(0, y, x) >= kFullLightShare * 30;
            ASSERT_LT(panel.color.At(0, y, x), 30 * 14 / 16.f) << x << "," << y;
        }
    ASSERT_GE(overShare, 3);
    Result out = RunAwrOnPanel(panel);
    float worst = WorstPastRims(out.image, panel);
    EXPECT_LT(worst, 0.5f * 0.05f) << "a glow past the rim";
    // Within 2 of the panel's full interior the bound is the window's mean (plus 2 standard
    // deviations of it) or the pixel's own input: the row's squared error no more than the
    // input's.
    double outError = 0, inError = 0;
    for (int c = 0; c < 3; ++c)
        for (int y : {PanelLight::y0 - 2, PanelLight::y1 + 1})
            for (int x = PanelLight::x0; x < PanelLight::x1; ++x) {
                const double truth = panel.truth.At(c, y, x);
                outError += std::pow(out.image.At(c, y, x) - truth, 2);
                inError += std::pow(panel.color.At(c, y, x) - truth, 2);
            }
    EXPECT_LE(outError, inError) << "the rows past the rims worse than their input";
}

// The synthesis's trough a few rows past a sharp light's rim (cornell at 256x256, 16 spp: a
// dark line above the ceiling panel, held only by the input's minimum): within
// kFullLightReach of the panel's full interior no row past the rim is darker than its input
// by more than its noise, nor worse than the input in squared error.
TEST_F(HighlightsAwr, ALightsTroughStaysAtTheInputsLevel) {
    PanelLight panel("highlights awr trough past the rim", 0.55f);
    Result out = RunAwrOnPanel(panel);
    // Rows 1-3 past each rim, each within kFullLightReach of the panel's interior.
    for (int past = 1; past <= kFullLightReach - 1; ++past)
        for (int y : {PanelLight::y0 - 1 - past, PanelLight::y1 + past}) {
            double outSum = 0, inSum = 0, outError = 0, inError = 0;
            for (int c = 0; c < 3; ++c)
                for (int x = PanelLight::x0; x < PanelLight::x1; ++x) {
                    const double truth = panel.truth.At(c, y, x);
                    outSum += out.image.At(c, y, x), inSum += panel.color.At(c, y, x);
                    outError += std::pow(out.image.At(c, y, x) - truth, 2);
                    inError += std::pow(panel.color.At(c, y, x) - truth, 2);
                }
            // The floor's noise is a tenth of its value: a 5x5 window's mean is its level to
            // 2%, held to 2 of those below, and a row's mean over 72 values to 1.2%; 0.92
            // leaves the row's own three of those.
            EXPECT_GE(outSum, 0.92 * inSum) << "row " << y << ": a trough";
            EXPECT_LE(outError, inError) << "row " << y << " worse than its input";
        }
}

}  // namespace
}  // namespace mcd::test
