// Restoring an input's local means (host/common/local_mean.h) against its CPU reference
// (cpu_reference/local_mean.h), and its properties.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include "cpu_reference/local_mean.h"
#include "harness/frames.h"
#include "harness/inputs.h"
#include "host/common/local_mean.h"
#include "host/common/parallel.h"
#include "host/common/squared_tent.h"
#include "host/error.h"

namespace mcd {
namespace {

using test::SeedFromName;

struct LocalMeanCase {
    int w, h, channels, r;
};

// Random input with zeros, negatives, NaN and Inf; an output of random positive values
// with zeros.
void MakeImages(const LocalMeanCase &c, Image *input, Image *output) {
    std::mt19937_64 rng(SeedFromName("local mean " + std::to_string(c.w) + "x" +
                                     std::to_string(c.h) + " r" + std::to_string(c.r)));
    std::uniform_real_distribution<float> unit(0, 1);
    *input = Image(c.w, c.h, c.channels);
    *output = Image(c.w, c.h, c.channels);
    for (size_t i = 0; i < input->data.size(); ++i) {
        float u = unit(rng);
        input->data[i] = u < 0.05f   ? 0.f
                         : u < 0.08f ? -unit(rng)
                         : u < 0.09f ? std::numeric_limits<float>::quiet_NaN()
                         : u < 0.10f ? std::numeric_limits<float>::infinity()
                         : u > 0.97f ? 100 * unit(rng)
                                     : unit(rng);
        output->data[i] = unit(rng) < 0.05f ? 0.f : 0.5f * unit(rng);
    }
}

// MakeImages' input with its NaN and Inf made 3: a box mean's windows all finite.
Image FiniteInput(const LocalMeanCase &c) {
    Image input, unused;
    MakeImages(c, &input, &unused);
    for (float &v : input.data)
        if (!std::isfinite(v)) v = 3;
    return input;
}

// The host's restore against its reference, value by value: float running sums against
// double windows, a few float roundings per pass. `finite`: every value must be.
void ExpectRestoreNear(const Image &got, const Image &expected, const std::string &label,
                       bool finite) {
    for (size_t i = 0; i < got.data.size(); ++i) {
        if (finite) {
            ASSERT_TRUE(std::isfinite(got.data[i])) << label << " " << i;
        }
        ASSERT_NEAR(got.data[i], expected.data[i], 3e-5 * std::fabs(expected.data[i]) + 1e-12)
            << label << " " << i;
    }
}

// A variance of the case's shape that makes about a tenth of the pixels lights (0, or tiny
// against the value) and the rest noisy.
Image LightsVariance(const LocalMeanCase &c, std::mt19937_64 *rng) {
    std::uniform_real_distribution<float> unit(0, 1);
    Image variance(c.w, c.h, c.channels);
    for (size_t i = 0; i < variance.data.size(); ++i) {
        float u = unit(*rng);
        variance.data[i] = u < 0.1f ? 0.f : u < 0.15f ? 1e-7f : unit(*rng);
    }
    return variance;
}

// The case's random input and a variance of lights (LightsVariance) drawn by a generator
// seeded by `name` and the size; the generator, to draw on.
std::mt19937_64 LightsCase(const LocalMeanCase &c, const std::string &name, Image *input,
                           Image *variance) {
    Image unused;
    MakeImages(c, input, &unused);
    std::mt19937_64 rng(
        SeedFromName(name + " " + std::to_string(c.w) + "x" + std::to_string(c.h)));
    *variance = LightsVariance(c, &rng);
    return rng;
}

// Where a uniform draw u makes a variance NaN (u < nan), Inf (u < inf), negative
// (u < negative) or zero (u < zero); the rest are positive.
struct OddShares {
    float nan, inf, negative, zero;
};

// A variance of the input's size with `channels` channels and odd values at the given
// shares, drawn from `rng`; its positive values span sixteen decades if `decades`, else
// lie under 0.01.
Image OddVariance(const Image &input, int channels, const OddShares &shares, bool decades,
                  std::mt19937_64 *rng) {
    std::uniform_real_distribution<float> unit(0, 1);
    Image variance(input.width, input.height, channels);
    for (float &v : variance.data) {
        float u = unit(*rng);
        if (u < shares.nan)
            v = std::numeric_limits<float>::quiet_NaN();
        else if (u < shares.inf)
            v = std::numeric_limits<float>::infinity();
        else if (u < shares.negative)
            v = -unit(*rng);
        else if (u < shares.zero)
            v = 0.f;
        else if (decades)
            v = std::pow(10.f, 16 * unit(*rng) - 8) * (1 + unit(*rng));
        else
            v = 0.01f * unit(*rng);
    }
    return variance;
}

class LocalMeanMatches : public ::testing::TestWithParam<LocalMeanCase> {};

TEST_P(LocalMeanMatches, Reference) {
    Image input, output;
    MakeImages(GetParam(), &input, &output);
    // Without the last coarse pass, unshrunk, pivot's and auto's weight, the first's.
    // Each with the window's noise and with each value's (pivot's, rhf's and auto's).
    for (double rebalance : {-1.0, 0.0, kLocalMeanRebalance, 1.0})
        for (bool pixelNoise : {false, true}) {
            Image expected = output, got = output;
            ref::RestoreLocalMeans(input, GetParam().r, &expected, nullptr, rebalance,
                                   pixelNoise);
            RestoreLocalMeans(input, GetParam().r, &got, nullptr, rebalance, pixelNoise);
            ASSERT_NO_FATAL_FAILURE(
                ExpectRestoreNear(got, expected, std::to_string(rebalance), true));
            // Bit-identical when repeated, with the loops split among threads.
            Image again = output;
            ForceParallelParts split(3);
            RestoreLocalMeans(input, GetParam().r, &again, nullptr, rebalance, pixelNoise);
            EXPECT_EQ(0, std::memcmp(again.data.data(), got.data.data(), got.data.size() * 4))
                << rebalance;
        }
}

// With a variance layer (one channel, and the input's), the highlights' test reads it.
TEST_P(LocalMeanMatches, ReferenceWithVariance) {
    Image input, output;
    MakeImages(GetParam(), &input, &output);
    std::mt19937_64 rng(SeedFromName("local mean variance"));
    std::uniform_real_distribution<float> unit(0, 1);
    for (int channels : {1, GetParam().channels}) {
        Image variance(input.width, input.height, channels);
        for (float &v : variance.data)
            v = unit(rng) < 0.5f ? 0.01f * unit(rng) : 50 * unit(rng);
        Image expected = output, got = output;
        ref::RestoreLocalMeans(input, GetParam().r, &expected, &variance, kLocalMeanRebalance,
                               true);
        RestoreLocalMeans(input, GetParam().r, &got, &variance, kLocalMeanRebalance, true);
        ASSERT_NO_FATAL_FAILURE(
            ExpectRestoreNear(got, expected, std::to_string(channels), false));
    }
}

// One scale of the restore alone (nfor's clamp's light) against its reference: unshrunk and
// with each value's noise twice; bit-identical when repeated.
TEST_P(LocalMeanMatches, RestoreAtMatchesReference) {
    Image input, output;
    MakeImages(GetParam(), &input, &output);
    for (double noiseWeight : {0.0, 2.0}) {
        Image expected = output, got = output;
        ref::RestoreLocalMeanAt(input, GetParam().r, noiseWeight, &expected);
        RestoreLocalMeanAt(input, GetParam().r, noiseWeight, &got);
        ASSERT_NO_FATAL_FAILURE(
            ExpectRestoreNear(got, expected, std::to_string(noiseWeight), true));
        Image again = output;
        RestoreLocalMeanAt(input, GetParam().r, noiseWeight, &again);
        EXPECT_EQ(0, std::memcmp(again.data.data(), got.data.data(), got.data.size() * 4))
            << noiseWeight;
    }
}

// The case's output with a tenth of its values given their finite input back (not kept: a
// fit that gave one back) and a sixth marked kept, a third of those given their input too
// (an emitter's); the mask.
std::vector<bool> GivenBackAndKept(const Image &input, Image *output) {
    std::mt19937_64 rng(SeedFromName("local mean kept mask " + std::to_string(input.width) +
                                     "x" + std::to_string(input.height)));
    std::uniform_real_distribution<float> unit(0, 1);
    std::vector<bool> kept(input.data.size(), false);
    for (size_t i = 0; i < kept.size(); ++i) {
        const float u = unit(rng);
        const bool finite = std::isfinite(input.data[i]);
        if (u < 0.1f && finite) output->data[i] = input.data[i];
        kept[i] = u >= 0.1f && u < 0.27f;
        if (u >= 0.21f && u < 0.27f && finite) output->data[i] = input.data[i];
    }
    return kept;
}

// Expects each value `kept` marks left as it was in `output`, and returns how many values
// given their input back (`input`) but not marked were restored.
size_t ExpectKeptStay(const Image &input, const Image &output, const std::vector<bool> &kept,
                      const Image &got) {
    size_t restored = 0;
    for (size_t i = 0; i < kept.size(); ++i) {
        if (kept[i]) {
            EXPECT_EQ(std::memcmp(&got.data[i], &output.data[i], 4), 0) << i;
        } else if (output.data[i] == input.data[i] && got.data[i] != output.data[i]) {
            ++restored;
        }
    }
    return restored;
}

// An explicit kept mask (nfor's) in place of the equality: both restores against their
// references; the marked values stay, values given their input back unmarked are restored as
// any other, and the mask returned adds the highlights taken (the same as the reference's),
// each given its input back, some on every case of 100 pixels or more.
TEST_P(LocalMeanMatches, KeptMaskMatchesReference) {
    Image input, output;
    MakeImages(GetParam(), &input, &output);
    const std::vector<bool> kept = GivenBackAndKept(input, &output);
    const bool large = input.PixelCount() >= 100;
    for (bool pixelNoise : {false, true}) {
        Image expected = output, got = output;
        std::vector<bool> keptExpected = kept, keptGot = kept;
        ref::RestoreLocalMeans(input, GetParam().r, &expected, nullptr, kLocalMeanRebalance,
                               pixelNoise, &keptExpected);
        RestoreLocalMeans(input, GetParam().r, &got, nullptr, kLocalMeanRebalance, pixelNoise,
                          &keptGot);
        ASSERT_NO_FATAL_FAILURE(ExpectRestoreNear(got, expected, "means", true));
        EXPECT_EQ(keptGot, keptExpected);
        // The mask returned holds the one given and adds the highlights, each its input back.
        size_t added = 0;
        for (size_t i = 0; i < kept.size(); ++i) {
            if (kept[i]) {
                EXPECT_TRUE(keptGot[i]) << i;
            } else if (keptGot[i]) {
                EXPECT_EQ(std::memcmp(&got.data[i], &input.data[i], 4), 0) << i;
                ++added;
            }
        }
        if (large) {
            EXPECT_GT(added, 0u) << pixelNoise;
        }
        const size_t restored = ExpectKeptStay(input, output, kept, got);
        if (large) {
            EXPECT_GT(restored, 0u) << pixelNoise;
        }
        Image again = output;
        std::vector<bool> keptAgain = kept;
        RestoreLocalMeans(input, GetParam().r, &again, nullptr, kLocalMeanRebalance, pixelNoise,
                          &keptAgain);
        EXPECT_EQ(0, std::memcmp(again.data.data(), got.data.data(), got.data.size() * 4));
    }
    for (double noiseWeight : {0.0, 2.0}) {
        Image expected = output, got = output;
        ref::RestoreLocalMeanAt(input, GetParam().r, noiseWeight, &expected, &kept);
        RestoreLocalMeanAt(input, GetParam().r, noiseWeight, &got, &kept);
        ASSERT_NO_FATAL_FAILURE(ExpectRestoreNear(got, expected, "at", true));
        const size_t restored = ExpectKeptStay(input, output, kept, got);
        if (large) {
            EXPECT_GT(restored, 0u) << noiseWeight;
        }
    }
    // A mask of another size is refused, by both.
    std::vector<bool> wrong(kept.size() + 1, false);
    Image got = output;
    EXPECT_THROW(RestoreLocalMeanAt(input, GetParam().r, 2, &got, &wrong), Error);
    EXPECT_THROW(RestoreLocalMeans(input, GetParam().r, &got, nullptr, -1, false, &wrong),
                 Error);
    EXPECT_THROW(ref::RestoreLocalMeanAt(input, GetParam().r, 2, &got, &wrong), Error);
    EXPECT_THROW(ref::RestoreLocalMeans(input, GetParam().r, &got, nullptr, -1, false, &wrong),
                 Error);
}

// The noise bound against its reference: variances of one channel and of the input's,
// with NaN, Inf and negative values among them and among the inputs; the same bits (both
// clamp in double and round once), and the same when repeated.
TEST_P(LocalMeanMatches, BoundToNoiseMatchesReference) {
    Image input, output;
    MakeImages(GetParam(), &input, &output);
    std::mt19937_64 rng(SeedFromName("local mean bound"));
    for (int channels : {1, GetParam().channels}) {
        Image variance = OddVariance(input, channels, {0.02f, 0.03f, 0.04f, 0.2f}, false, &rng);
        Image expected = output, got = output;
        size_t count = ref::BoundToNoise(input, variance, 3, &expected);
        EXPECT_EQ(BoundToNoise(input, variance, 3, &got), count);
        EXPECT_EQ(0, std::memcmp(got.data.data(), expected.data.data(), got.data.size() * 4))
            << channels;
        Image again = output;
        BoundToNoise(input, variance, 3, &again);
        EXPECT_EQ(0, std::memcmp(again.data.data(), got.data.data(), got.data.size() * 4));
    }
}

// The input-range bound against its reference on the random inputs (NaN, Inf, zeros,
// negatives, spikes) and outputs, radii 1 and 2: the same count and bits (both take the
// share in double and round once), and the same when repeated.
TEST_P(LocalMeanMatches, BoundToInputRangeMatchesReference) {
    Image input, output;
    MakeImages(GetParam(), &input, &output);
    std::mt19937_64 rng(SeedFromName("local mean range"));
    for (int channels : {1, GetParam().channels}) {
        // No Inf: its share is empty.
        Image variance = OddVariance(input, channels, {0.02f, 0.02f, 0.03f, 0.2f}, false, &rng);
        for (int radius : {1, 2})
            for (double k : {0.0, 1.0}) {
                Image expected = output, got = output;
                size_t count = ref::BoundToInputRange(input, variance, radius, k, &expected);
                EXPECT_EQ(BoundToInputRange(input, variance, radius, k, &got), count)
                    << radius << " " << k;
                EXPECT_EQ(
                    0, std::memcmp(got.data.data(), expected.data.data(), got.data.size() * 4))
                    << channels << " " << radius << " " << k;
                if (input.PixelCount() > 100) {
                    EXPECT_GT(count, 0u) << "the case moves nothing";
                }
                Image again = output;
                BoundToInputRange(input, variance, radius, k, &again);
                EXPECT_EQ(0,
                          std::memcmp(again.data.data(), got.data.data(), got.data.size() * 4));
            }
    }
}

// The bounds' noise spread (k > 0 widens the input range by it) against its reference, at
// every pixel and channel of variances that span sixteen decades (more than a double sums
// floats exactly over, so a sum in another order differs in the last bits), with NaN, Inf,
// zeros and negatives among them: the same bits.
TEST_P(LocalMeanMatches, NoiseSpreadMatchesReference) {
    Image input, output;
    MakeImages(GetParam(), &input, &output);
    std::mt19937_64 rng(SeedFromName("local mean spread"));
    for (int channels : {1, GetParam().channels}) {
        Image variance = OddVariance(input, channels, {0.02f, 0.03f, 0.04f, 0.1f}, true, &rng);
        size_t spread = 0;
        for (int c = 0; c < input.channels; ++c)
            for (int y = 0; y < input.height; ++y)
                for (int x = 0; x < input.width; ++x) {
                    const double got = NoiseSpread(variance, c, x, y);
                    const double expected = ref::NoiseSpread(variance, c, x, y);
                    ASSERT_EQ(0, std::memcmp(&got, &expected, sizeof got))
                        << channels << " " << c << " " << x << " " << y << " " << got << " "
                        << expected;
                    spread += got >= 0;
                }
        if (input.PixelCount() > 100) {
            EXPECT_GT(spread, 0u) << "no spread computed";
        }
    }
}

// The frame's robust noise estimate against its reference: with an albedo of one channel
// and of the colour's (values at and under the 0.02 floor among them) and without; the
// same bits (both take z in float and the rest in double, and pick the same median), and
// the same when repeated.
TEST_P(LocalMeanMatches, FrameNoiseMatchesReference) {
    Image input, output;
    MakeImages(GetParam(), &input, &output);
    std::mt19937_64 rng(SeedFromName("frame noise albedo"));
    std::uniform_real_distribution<float> unit(0, 1);
    for (int channels : {0, 1, GetParam().channels}) {
        Image albedo(input.width, input.height, std::max(channels, 1));
        for (float &a : albedo.data) a = unit(rng) < 0.1f ? 0.01f * unit(rng) : unit(rng);
        const Image *guide = channels ? &albedo : nullptr;
        Image expected = ref::FrameNoise(input, guide), got = FrameNoise(input, guide);
        ASSERT_TRUE(got.SameShape(expected));
        EXPECT_EQ(0, std::memcmp(got.data.data(), expected.data.data(), got.data.size() * 4))
            << channels;
        Image again = FrameNoise(input, guide);
        EXPECT_EQ(0, std::memcmp(again.data.data(), got.data.data(), got.data.size() * 4));
    }
}

INSTANTIATE_TEST_SUITE_P(Cases, LocalMeanMatches,
                         ::testing::Values(LocalMeanCase{1, 1, 3, 1}, LocalMeanCase{7, 5, 1, 1},
                                           LocalMeanCase{33, 17, 3, 3},
                                           LocalMeanCase{64, 48, 3, 8},
                                           LocalMeanCase{5, 40, 4, 16}));

// The tent means against windows summed one by one, in order, in double (the definition
// the restore keeps, so a tile gives the whole frame's values): the same bits, on odd sizes,
// windows wider than the image, and planes large enough to be split among threads.
TEST(LocalMeanTent, SameBitsAsWindowsSummedOneByOne) {
    auto box = [](const Image &in, int r, bool rows) {
        Image out(in.width, in.height, in.channels);
        int length = rows ? in.width : in.height;
        for (int c = 0; c < in.channels; ++c)
            for (int y = 0; y < in.height; ++y)
                for (int x = 0; x < in.width; ++x) {
                    int i = rows ? x : y;
                    int a = std::max(0, i - r), b = std::min(length - 1, i + r);
                    double sum = 0;
                    for (int j = a; j <= b; ++j) sum += rows ? in.At(c, y, j) : in.At(c, j, x);
                    out.At(c, y, x) = float(sum / (b - a + 1));
                }
        return out;
    };
    for (LocalMeanCase c : {LocalMeanCase{1, 1, 1, 1}, LocalMeanCase{7, 5, 3, 4},
                            LocalMeanCase{37, 3, 2, 2}, LocalMeanCase{301, 203, 3, 20}}) {
        Image input = FiniteInput(c);
        Image expected =
            box(box(box(box(input, c.r, true), c.r, false), c.r, true), c.r, false);
        Image got = TentMean(input, c.r);
        ASSERT_EQ(0, std::memcmp(got.data.data(), expected.data.data(), got.data.size() * 4))
            << c.w << "x" << c.h << " r" << c.r;
    }
}

// Kind 0: random values with zeros, negatives, NaN, Inf and fireflies; 1: a constant; 2:
// finite values over eight decades with fireflies.
Image TentInput(const LocalMeanCase &c, int kind, std::mt19937_64 *rng) {
    std::uniform_real_distribution<float> unit(0, 1);
    Image image(c.w, c.h, c.channels);
    for (float &v : image.data) {
        const float u = unit(*rng);
        if (kind == 1)
            v = 0.37f;
        else if (kind == 0)
            v = u < 0.05f   ? 0.f
                : u < 0.1f  ? -unit(*rng)
                : u < 0.12f ? std::numeric_limits<float>::quiet_NaN()
                : u < 0.14f ? std::numeric_limits<float>::infinity()
                : u < 0.15f ? -std::numeric_limits<float>::infinity()
                : u < 0.18f ? 1e4f * unit(*rng)
                            : unit(*rng);
        else
            v = u < 0.03f ? 1e5f * unit(*rng) : std::pow(10.f, 8 * unit(*rng) - 4);
    }
    return image;
}

// The clipped tent (RestoreLocalMeanAt's means) against each window summed on its own, in
// double, in order of rising offset, rows then columns: the same bits (NaN for NaN) on odd
// sizes, 1x1, windows wider than the image, NaN/Inf, fireflies and constants, squared
// weights too, and the same when the loops are split among threads.
TEST(LocalMeanTent, ClippedTentSameBitsAsWindowsSummedOneByOne) {
    auto pass = [](const Image &in, int s, bool squared, bool rows) {
        const int reach = 2 * s, length = rows ? in.width : in.height;
        Image out(in.width, in.height, in.channels);
        for (int c = 0; c < in.channels; ++c)
            for (int y = 0; y < in.height; ++y)
                for (int x = 0; x < in.width; ++x) {
                    const int i = rows ? x : y;
                    const int a = std::max(0, i - reach), b = std::min(length - 1, i + reach);
                    double total = 0;
                    for (int j = a; j <= b; ++j) total += reach + 1 - std::abs(j - i);
                    double sum = 0;
                    for (int j = a; j <= b; ++j) {
                        double weight = (reach + 1 - std::abs(j - i)) / total;
                        if (squared) weight *= weight;
                        sum += weight * (rows ? in.At(c, y, j) : in.At(c, j, x));
                    }
                    out.At(c, y, x) = float(sum);
                }
        return out;
    };
    auto same = [](const Image &got, const Image &expected) {
        for (size_t i = 0; i < got.data.size(); ++i) {
            const bool bothNaN = std::isnan(got.data[i]) && std::isnan(expected.data[i]);
            if (!bothNaN && std::memcmp(&got.data[i], &expected.data[i], 4) != 0) return false;
        }
        return true;
    };
    std::mt19937_64 rng(SeedFromName("clipped tent"));
    for (LocalMeanCase c :
         {LocalMeanCase{1, 1, 1, 1}, LocalMeanCase{1, 9, 3, 2}, LocalMeanCase{9, 1, 2, 1},
          LocalMeanCase{7, 5, 3, 4}, LocalMeanCase{37, 3, 2, 2}, LocalMeanCase{40, 23, 3, 3},
          LocalMeanCase{9, 9, 3, 2}, LocalMeanCase{10, 5, 3, 2}, LocalMeanCase{8, 4, 1, 2},
          LocalMeanCase{301, 67, 3, 8}, LocalMeanCase{150, 140, 2, 32}})
        for (int kind = 0; kind < 3; ++kind) {
            Image input = TentInput(c, kind, &rng);
            for (bool squared : {false, true}) {
                const Image expected =
                    pass(pass(input, c.r, squared, true), c.r, squared, false);
                Image got = ClippedTentFilter(input, c.r, squared);
                ASSERT_TRUE(got.SameShape(input));
                EXPECT_TRUE(same(got, expected))
                    << c.w << "x" << c.h << " s" << c.r << " kind " << kind << " " << squared;
                ForceParallelParts split(3);
                EXPECT_TRUE(same(ClippedTentFilter(input, c.r, squared), expected))
                    << c.w << "x" << c.h << " s" << c.r << " split";
            }
        }
}

// TentSquaredMean shares one plane of scratch among the channels: each channel's values are
// still its own plane's two passes, bit for bit, whatever the other channels held.
TEST(LocalMeanTent, SquaredTentMeanIsEachChannelsOwnPasses) {
    for (LocalMeanCase c : {LocalMeanCase{1, 1, 1, 1}, LocalMeanCase{7, 5, 3, 4},
                            LocalMeanCase{37, 3, 4, 2}, LocalMeanCase{301, 203, 3, 20}}) {
        Image input = FiniteInput(c);
        Image got = TentSquaredMean(input, c.r);
        ASSERT_TRUE(got.SameShape(input));
        std::vector<float> rows(input.PixelCount()), expected(input.PixelCount());
        for (int ch = 0; ch < c.channels; ++ch) {
            SquaredTentMeanRows(input.Plane(ch), rows.data(), c.w, c.h, c.r);
            SquaredTentMeanColumns(rows.data(), expected.data(), c.w, c.h, c.r);
            ASSERT_EQ(0, std::memcmp(got.Plane(ch), expected.data(), expected.size() * 4))
                << c.w << "x" << c.h << " r" << c.r << " channel " << ch;
        }
    }
}

// An output darkened by a constant factor gets the input back (to the shrinkage's share
// of it); a window whose input is all zero within reach leaves the output as it is; a value
// the method left (a light) stays and weighs in no mean.
TEST(LocalMeanProperties, UndoesAUniformDarkeningAndLeavesBlackAlone) {
    const int w = 80, h = 30, r = 2;
    Image input(w, h, 3), output(w, h, 3);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                float v = x < 40 ? 0.f : 0.2f + 0.01f * ((x * 7 + y * 3 + c) % 11);
                input.At(c, y, x) = v;
                output.At(c, y, x) = x < 40 ? 0.3f : 0.6f * v;
            }
    input.At(1, 15, 70) = output.At(1, 15, 70) = 1000;
    ASSERT_LT(LocalMeanReach(r), 40 - 5);
    RestoreLocalMeans(input, r, &output);
    EXPECT_EQ(output.At(1, 15, 70), 1000.f);
    EXPECT_NEAR(output.At(1, 15, 71), input.At(1, 15, 71), 0.02 * input.At(1, 15, 71));
    for (int y = 0; y < h; ++y) {
        EXPECT_EQ(output.At(0, y, 5), 0.3f);  // no input brightness within reach: left
        EXPECT_NEAR(output.At(1, y, 65), input.At(1, y, 65), 0.02 * input.At(1, y, 65));
    }
}

// A wall of noisy values around 0.5 that the method darkened to 0.45, with a small bright
// light (a disc of radius 2) that the method cut to the wall: the light takes its input
// back, and the wall around it is restored to about 0.5 without the light's energy spread
// over it (the glowing square of a plain ratio of local means).
TEST(LocalMeanProperties, ASmallLightDoesNotRaiseItsSurroundings) {
    const int w = 96, h = 96, r = 8, cx = 48, cy = 48;
    std::mt19937_64 rng(SeedFromName("local mean light"));
    std::normal_distribution<float> noise(0, 0.1f);
    Image input(w, h, 3), output(w, h, 3);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                bool light = (x - cx) * (x - cx) + (y - cy) * (y - cy) <= 4;
                input.At(c, y, x) = light ? 200.f : std::max(0.f, 0.5f + noise(rng));
                output.At(c, y, x) = 0.45f;
            }
    RestoreLocalMeans(input, r, &output);
    EXPECT_EQ(output.At(0, cy, cx), 200.f);
    EXPECT_EQ(output.At(2, cy + 2, cx), 200.f);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                int d2 = (x - cx) * (x - cx) + (y - cy) * (y - cy);
                if (d2 <= 9) continue;
                ASSERT_NEAR(output.At(c, y, x), 0.5f, 0.03f) << c << " " << y << " " << x;
            }
}

// A small light as a render has it: a core of 900 with a rim of 120 (pixels the light
// partly covers), which the method cut to 500 and 50, and its own smear lifting the wall
// beside it. The core alone passes the first test (the rim is under 16 times the tent mean
// the core's output lifts); the rim passes once the core is kept, so it takes its input
// back too and its cut energy is not spread over the wall in a glowing square.
TEST(LocalMeanProperties, ALightsRimIsKeptWithItsCore) {
    const int w = 96, h = 96, r = 8, cx = 48, cy = 48;
    std::mt19937_64 rng(SeedFromName("local mean light rim"));
    std::normal_distribution<float> noise(0, 0.1f);
    Image input(w, h, 3), output(w, h, 3);
    auto light = [&](int x, int y) {
        int d2 = (x - cx) * (x - cx) + (y - cy) * (y - cy);
        return d2 <= 2 ? 2 : d2 <= 5 ? 1 : 0;
    };
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                int l = light(x, y);
                input.At(c, y, x) = l == 2   ? 900.f
                                    : l == 1 ? 120.f
                                             : std::max(0.f, 0.3f + noise(rng));
                output.At(c, y, x) = l == 2 ? 500.f : l == 1 ? 50.f : 0.3f;
            }
    Image got = output;
    RestoreLocalMeans(input, r, &got, nullptr, kLocalMeanRebalance, true);
    Image expected = output;
    ref::RestoreLocalMeans(input, r, &expected, nullptr, kLocalMeanRebalance, true);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                ASSERT_NEAR(got.At(c, y, x), expected.At(c, y, x),
                            3e-5 * std::fabs(expected.At(c, y, x)) + 1e-12);
                if (light(x, y))
                    ASSERT_EQ(got.At(c, y, x), input.At(c, y, x)) << c << " " << y << " " << x;
                else
                    ASSERT_NEAR(got.At(c, y, x), 0.3f, 0.015f) << c << " " << y << " " << x;
            }
}

// A small light seen in a mirror: one sample of the pixel's 16 hit it, so the variance
// layer gives the pixel a standard deviation as large as its value, as a firefly's, and its
// input is not 4 of them from the method's output. Its neighbours' samples all agree (variance
// 0, lit): its spread is its footprint's coverage, not a rare path, so it takes its input
// back rather than have its energy spread over the restore's tents. Beside noisy neighbours,
// or black ones (samples that all missed a light), it does not.
TEST(LocalMeanProperties, ALightAmongExactPixelsIsKept) {
    const int w = 48, h = 48, r = 4, cx = 20, cy = 22;
    for (int around : {0, 1, 2}) {  // exact and lit, noisy, exact and black
        Image input(w, h, 3), output(w, h, 3), variance(w, h, 3);
        for (int c = 0; c < 3; ++c)
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) {
                    input.At(c, y, x) = around == 2 ? 0.f : 1.425f;
                    variance.At(c, y, x) = around == 1 ? 1e-4f : 0.f;
                    output.At(c, y, x) = around == 2 ? 0.01f : 1.5f;
                }
        for (int c = 0; c < 3; ++c) {
            input.At(c, cy, cx) = 238.8f;
            variance.At(c, cy, cx) = 56364.f;
            output.At(c, cy, cx) = 1.7f;
        }
        Image got = output, expected = output;
        RestoreLocalMeans(input, r, &got, &variance, kLocalMeanRebalance, true);
        ref::RestoreLocalMeans(input, r, &expected, &variance, kLocalMeanRebalance, true);
        ASSERT_NO_FATAL_FAILURE(
            ExpectRestoreNear(got, expected, "around " + std::to_string(around), true));
        for (int c = 0; c < 3; ++c) {
            if (around == 0)
                EXPECT_EQ(got.At(c, cy, cx), input.At(c, cy, cx)) << c;
            else
                EXPECT_NE(got.At(c, cy, cx), input.At(c, cy, cx)) << around << " " << c;
        }
    }
}

// One pixel's energy the method cut (a firefly, or a light of one pixel: the neighbours
// cannot tell them apart) on a wall the method left as it was: with each value's own noise
// its difference is all noise wherever it lies in a window, and the wall stays; with the
// window's mean noise it is restored near the centres of the windows that hold it, a
// square around the pixel.
TEST(LocalMeanProperties, OnePixelsEnergyIsNotSpreadWithItsOwnNoise) {
    const int w = 80, h = 80, r = 4;
    Image input(w, h, 3), output(w, h, 3);
    // A wall the method flattened: a zero-mean pattern taken out, so no value is left.
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                input.At(c, y, x) = 0.5f + 0.01f * float((x + 2 * y + c) % 5 - 2);
                output.At(c, y, x) = 0.5f;
            }
    for (int c = 0; c < 3; ++c) input.At(c, 40, 40) = 60;
    Image own = output, window = output;
    RestoreLocalMeans(input, r, &own, nullptr, -1, true);
    RestoreLocalMeans(input, r, &window, nullptr, -1, false);
    double ownMost = 0, windowMost = 0;
    for (size_t i = 0; i < own.data.size(); ++i) {
        ownMost = std::max(ownMost, std::fabs(own.data[i] - 0.5));
        windowMost = std::max(windowMost, std::fabs(window.data[i] - 0.5));
    }
    EXPECT_LT(ownMost, 5e-3);
    EXPECT_GT(windowMost, 20 * ownMost) << ownMost;
}

// A firefly on a wall the method darkened: the restore gives the wall its light back, and
// the firefly's noise, in every window that holds it, holds the gain back there. The gain
// must ramp down towards the firefly, not step at the edge of the square of windows that
// hold it (the squares nfor drew on glossy lights' floor), and the firefly adds no light.
TEST(LocalMeanProperties, RestoreAtGainHasNoStepAroundAFirefly) {
    const int w = 40, h = 40, s = 2;
    Image input(w, h, 1), output(w, h, 1);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            input.At(0, y, x) = 0.05f + 0.001f * float((x + 2 * y) % 5 - 2);
            output.At(0, y, x) = 0.04f;
        }
    input.At(0, 20, 20) = 5;
    RestoreLocalMeanAt(input, s, 2, &output);
    auto gain = [&](int y, int x) { return output.At(0, y, x) / 0.04 - 1; };
    const double far = gain(2, 2);
    EXPECT_GT(far, 0.2);
    double step = 0, most = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            most = std::max(most, gain(y, x));
            if (x + 1 < w) step = std::max(step, std::fabs(gain(y, x + 1) - gain(y, x)));
            if (y + 1 < h) step = std::max(step, std::fabs(gain(y + 1, x) - gain(y, x)));
        }
    EXPECT_LT(step, 0.25 * far) << far;
    EXPECT_LT(gain(20, 20), 0.25 * far);
    EXPECT_LT(most, 1.05 * far);
}

// The bound: a value within k standard deviations stays; one beyond ends at k of them,
// on either side; a pixel of variance 0 (every sample equal) is left, and one firefly's
// variance beside a pixel does not widen its bound.
TEST(LocalMeanProperties, BoundToNoiseClampsAtKStandardDeviations) {
    Image input(7, 1, 1), output(7, 1, 1), variance(7, 1, 1);
    for (int x = 0; x < 7; ++x) input.At(0, 0, x) = 1, variance.At(0, 0, x) = 0.01f;
    output.At(0, 0, 0) = 1.25f;  // 2.5 sd: stays
    output.At(0, 0, 1) = 2.f;    // 10 sd up
    output.At(0, 0, 2) = -1.f;   // 20 sd down
    output.At(0, 0, 3) = 1.5f;
    variance.At(0, 0, 3) = 0;  // every sample equal: says nothing, left
    output.At(0, 0, 5) = 5.f;
    variance.At(0, 0, 6) = 100;  // a firefly beside it: its window {0.01, 0.01, 100}
    output.At(0, 0, 4) = output.At(0, 0, 6) = 1;
    EXPECT_EQ(BoundToNoise(input, variance, 3, &output), 3u);
    EXPECT_EQ(output.At(0, 0, 0), 1.25f);
    EXPECT_FLOAT_EQ(output.At(0, 0, 1), 1.3f);
    EXPECT_FLOAT_EQ(output.At(0, 0, 2), 0.7f);
    EXPECT_EQ(output.At(0, 0, 3), 1.5f);
    EXPECT_FLOAT_EQ(output.At(0, 0, 5), 1.3f);
}

// Issue #29, a chrome sphere's contact with the floor: one share of the pixel's move for
// every channel, so a bound on one channel does not tint the pixel (fits of 0.008 on a
// black input whose channels' noise differ came out red and blue), and not below 0 where
// the input is not negative.
TEST(LocalMeanProperties, BoundMovesAPixelsChannelsByOneShare) {
    Image input(2, 1, 3), output(2, 1, 3), variance(2, 1, 3);
    for (int c = 0; c < 3; ++c) {
        input.At(c, 0, 0) = 1, output.At(c, 0, 0) = 2;
        input.At(c, 0, 1) = 0.1f, output.At(c, 0, 1) = c == 1 ? -0.2f : 0.1f;
        for (int x = 0; x < 2; ++x) variance.At(c, 0, x) = c == 1 ? 1e-4f : 0.01f;
    }
    EXPECT_EQ(BoundToNoise(input, variance, 3, &output), 4u);
    // Green allows 0.03 of the move up, so each channel moves 0.03.
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(output.At(c, 0, 0), 1.03f, 1e-6f) << c;
    // Green's bound, 0.03 below 0.1, keeps it at 0.07; the others do not move.
    EXPECT_NEAR(output.At(1, 0, 1), 0.07f, 1e-6f);
    for (int c : {0, 2}) EXPECT_EQ(output.At(c, 0, 1), 0.1f) << c;
    // Not below 0: 3 standard deviations of 0.1 below 0.04 would be -0.26.
    Image dark(1, 1, 1, 0.04f), wide(1, 1, 1, 0.01f), negative(1, 1, 1, -1.f);
    EXPECT_EQ(BoundToNoise(dark, wide, 3, &negative), 1u);
    EXPECT_GE(negative.At(0, 0, 0), 0.f);
    EXPECT_LT(negative.At(0, 0, 0), 1e-7f);
    Image reference(1, 1, 1, -1.f);
    EXPECT_EQ(ref::BoundToNoise(dark, wide, 3, &reference), 1u);
    EXPECT_EQ(reference.At(0, 0, 0), negative.At(0, 0, 0));
}

// Issue #29, a chrome sphere's contact with the floor (glossy_lights accumulated): pixels
// whose samples were all 0 (variance 0) took fits that went negative, and the bound, which
// leaves what its noise cannot say, let them through. A value of variance 0 is still not
// moved below 0 where its input is not, on its own (its pixel's other channels stay: moved
// to their input they brought back a dim frame's grain); a positive one stays, and so does
// a negative input's.
TEST(LocalMeanProperties, BoundKeepsValuesOfVarianceZeroFromGoingNegative) {
    Image input(3, 1, 3), output(3, 1, 3), variance(3, 1, 3, 0.f);
    const float black[3] = {0.005f, 0.0033f, -0.0008f};
    const float dim[3] = {0.03f, -0.001f, 0.02f};
    for (int c = 0; c < 3; ++c) {
        input.At(c, 0, 0) = 0, output.At(c, 0, 0) = black[c];
        input.At(c, 0, 1) = 0.02f, output.At(c, 0, 1) = dim[c];
        input.At(c, 0, 2) = -0.01f, output.At(c, 0, 2) = -0.02f;
    }
    Image reference = output;
    EXPECT_EQ(BoundToNoise(input, variance, 3, &output), 2u);
    for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(output.At(c, 0, 0), std::max(0.f, black[c])) << c;
        EXPECT_EQ(output.At(c, 0, 1), std::max(0.f, dim[c])) << c;
        EXPECT_EQ(output.At(c, 0, 2), -0.02f) << c;
    }
    EXPECT_EQ(ref::BoundToNoise(input, variance, 3, &reference), 2u);
    EXPECT_EQ(0,
              std::memcmp(reference.data.data(), output.data.data(), output.data.size() * 4));
}

// Issue #29, a glossy ring's highlights: fits several times the brightest input around them
// end at that input's range, the pixel's channels moved by one share (no tint); a value
// inside the range stays, a firefly within the window widens it, and so does the noise by k
// of its standard deviations; a pixel of variance 0 is left.
TEST(LocalMeanProperties, BoundToInputRangeMovesAPixelsChannelsByOneShare) {
    Image input(5, 1, 3), output(5, 1, 3), variance(5, 1, 3, 1e-4f);
    for (int c = 0; c < 3; ++c)
        for (int x = 0; x < 5; ++x) input.At(c, 0, x) = output.At(c, 0, x) = 1 + 0.1f * x;
    // Pixel 2: red 4 times the largest red within 1 (1.3); green inside the range.
    output.At(0, 0, 2) = 5.2f;
    output.At(1, 0, 2) = 1.25f;
    // Pixel 4: below the range in blue only (its window 1.3 .. 1.4).
    output.At(2, 0, 4) = 1.f;
    Image widened = output, still = output;
    EXPECT_EQ(BoundToInputRange(input, variance, 1, 0, &output), 3u);
    // Red allows 0.1 of its 4.0 move (and the range's slack, kRangeSlack of 1.3): t about
    // 1 / 40, every channel moves by it.
    EXPECT_NEAR(output.At(0, 0, 2), 1.3 * (1 + kRangeSlack), 1e-6);
    EXPECT_NEAR(output.At(1, 0, 2), 1.2f + 0.05f / 40, 1e-6f);
    EXPECT_EQ(output.At(2, 0, 2), 1.2f);
    EXPECT_NEAR(output.At(2, 0, 4), 1.3 - 1.4 * kRangeSlack, 1e-6);
    for (int c = 0; c < 3; ++c) EXPECT_EQ(output.At(c, 0, 1), input.At(c, 0, 1)) << c;
    Image wide = input;
    wide.At(0, 0, 3) = 10;  // a firefly within 1 widens pixel 2's range
    Image kept(5, 1, 3);
    kept.data = input.data;
    kept.At(0, 0, 2) = 5.2f;
    EXPECT_EQ(BoundToInputRange(wide, variance, 1, 0, &kept), 0u);
    EXPECT_EQ(kept.At(0, 0, 2), 5.2f);
    // Widened by 10 deviations of 0.01: red allows 0.2 of its 4.0 move.
    BoundToInputRange(input, variance, 1, 10, &widened);
    EXPECT_NEAR(widened.At(0, 0, 2), 1.4 + 1.3 * kRangeSlack, 1e-6);
    // Variance 0 in red: red is not bounded, green and blue stay inside theirs.
    variance.At(0, 0, 2) = 0;
    EXPECT_EQ(BoundToInputRange(input, variance, 1, 0, &still), 1u);
    EXPECT_EQ(still.At(0, 0, 2), 5.2f);
}

// Issue #29, the range pass's flip: a pixel that is its window's largest value, whose fit
// lies one rounding above it, keeps its fits (the range's slack); before the slack the share
// was 0 and every channel went back to its input, so a GPU and a twin whose fits differed by
// an ulp ended the pass far apart. Beyond the slack the share falls from 1, not to 0, and
// the host and the reference agree to the bit on both.
TEST(LocalMeanProperties, BoundToInputRangeIsContinuousAtTheWindowsExtreme) {
    Image input(3, 1, 3), variance(3, 1, 3, 1e-4f);
    for (int c = 0; c < 3; ++c)
        for (int x = 0; x < 3; ++x) input.At(c, 0, x) = 0.5f + 0.25f * x;
    // Pixel 2 holds its window's largest red; its fit lies one float step above that red,
    // and its green well inside the range.
    Image output = input;
    output.At(0, 0, 2) = std::nextafter(1.f, 2.f);
    output.At(1, 0, 2) = 0.75f;
    Image reference = output;
    EXPECT_EQ(BoundToInputRange(input, variance, 1, 0, &output), 0u);
    EXPECT_EQ(output.At(0, 0, 2), std::nextafter(1.f, 2.f));
    EXPECT_EQ(output.At(1, 0, 2), 0.75f);
    EXPECT_EQ(ref::BoundToInputRange(input, variance, 1, 0, &reference), 0u);
    EXPECT_EQ(0,
              std::memcmp(reference.data.data(), output.data.data(), output.data.size() * 4));
    // Twice the slack above: half the move stays, in every channel.
    Image beyond = input;
    const double slack = 1e-5;
    beyond.At(0, 0, 2) = float(1 + 2 * slack);
    beyond.At(1, 0, 2) = 0.75f;
    Image beyondReference = beyond;
    EXPECT_EQ(BoundToInputRange(input, variance, 1, 0, &beyond), 2u);
    const double t = slack / (float(1 + 2 * slack) - 1.0);
    EXPECT_NEAR(beyond.At(0, 0, 2), 1 + slack, 1e-7);
    EXPECT_NEAR(beyond.At(1, 0, 2), 1 + t * (0.75 - 1), 1e-6);
    EXPECT_NEAR(t, 0.5, 0.01);
    ref::BoundToInputRange(input, variance, 1, 0, &beyondReference);
    EXPECT_EQ(0, std::memcmp(beyondReference.data.data(), beyond.data.data(),
                             beyond.data.size() * 4));
}

// Lone spikes against the reference on the random inputs (NaN, Inf, zeros, negatives,
// spikes of 100 among values under 1): the same count and bits (both sum in double, round
// to float and pick the same medians), and the same when repeated.
TEST_P(LocalMeanMatches, CutSpikesMatchesReference) {
    Image input, unused;
    MakeImages(GetParam(), &input, &unused);
    Image expected = input, got = input, again = input;
    size_t count = ref::CutSpikes(&expected);
    EXPECT_EQ(CutSpikes(&got), count);
    ASSERT_EQ(0, std::memcmp(got.data.data(), expected.data.data(), got.data.size() * 4));
    {
        ForceParallelParts split(3);  // the rows among threads: the same bits
        CutSpikes(&again);
    }
    EXPECT_EQ(0, std::memcmp(again.data.data(), got.data.data(), got.data.size() * 4));
}

// The same with a variance (about a tenth of the pixels lights) and the top third of the
// rows black with spikes along its edge, where neighbours' medians are 0: the same count
// and bits.
TEST_P(LocalMeanMatches, CutSpikesOverBlackMatchesReference) {
    const LocalMeanCase &c = GetParam();
    Image input, variance;
    std::mt19937_64 rng = LightsCase(c, "spikes over black", &input, &variance);
    std::uniform_real_distribution<float> unit(0, 1);
    const int edge = c.h / 3;
    for (int ch = 0; ch < c.channels; ++ch)
        for (int y = 0; y < edge; ++y)
            for (int x = 0; x < c.w; ++x) input.At(ch, y, x) = 0;
    for (int x = 0; x < c.w; x += 3)
        for (int ch = 0; ch < c.channels; ++ch) input.At(ch, edge, x) = 1000 * unit(rng);
    Image expected = input, got = input, again = input;
    size_t count = ref::CutSpikes(&expected, &variance);
    EXPECT_EQ(CutSpikes(&got, &variance), count);
    ASSERT_EQ(0, std::memcmp(got.data.data(), expected.data.data(), got.data.size() * 4));
    {
        ForceParallelParts split(3);  // the rows among threads: the same bits
        CutSpikes(&again, &variance);
    }
    EXPECT_EQ(0, std::memcmp(again.data.data(), got.data.data(), got.data.size() * 4));
}

// A lone spike takes its neighbours' median per channel; a cluster of them (a light) and a
// value under 16 times its neighbours' median stay.
TEST(LocalMeanProperties, CutSpikesCutsOnlyLoneSpikes) {
    Image color(12, 8, 2);
    for (int c = 0; c < 2; ++c)
        for (int y = 0; y < 8; ++y)
            for (int x = 0; x < 12; ++x) color.At(c, y, x) = 0.5f + 0.1f * c;
    color.At(0, 2, 2) = color.At(1, 2, 2) = 50;  // lone
    for (int y = 4; y <= 5; ++y)
        for (int x = 7; x <= 8; ++x) color.At(0, y, x) = 50;  // a 2x2 light
    color.At(0, 6, 2) = 15;  // 15.6 over a median sum of 1.1: stays
    Image cut = color;
    EXPECT_EQ(CutSpikes(&cut), 1u);
    EXPECT_EQ(cut.At(0, 2, 2), 0.5f);
    EXPECT_EQ(cut.At(1, 2, 2), 0.6f);
    for (size_t i = 0; i < cut.data.size(); ++i)
        if (i % cut.PixelCount() != 2 * 12 + 2) {
            EXPECT_EQ(cut.data[i], color.data[i]) << i;
        }
}

// Over black (the neighbours' median 0) a spike is measured against its neighbours above 0:
// a firefly on a plane's edge beside black is cut though the plane's samples agree (lights
// by the variance); a point over 512 times a light beside it stays, and so does a spike
// with only black around it.
TEST(LocalMeanProperties, CutSpikesOverBlackReadsTheNeighboursAboveZero) {
    const int w = 12, h = 8;
    Image color(w, h, 3, 0.f), variance(w, h, 3, 0.f);
    for (int c = 0; c < 3; ++c)
        for (int y = 4; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                color.At(c, y, x) = 0.05f;
                variance.At(c, y, x) = 1e-8f;  // its samples agree: lights
            }
    for (int c = 0; c < 3; ++c) {
        color.At(c, 3, 2) = 10;  // firefly on the edge: 200x the plane beside it
        variance.At(c, 3, 2) = 25;
        color.At(c, 3, 8) = 100;  // 2000x the plane beside it: stays
        variance.At(c, 3, 8) = 2500;
        color.At(c, 1, 5) = 10;  // black all around: stays
        variance.At(c, 1, 5) = 25;
    }
    Image cut = color, expected = color;
    EXPECT_EQ(CutSpikes(&cut, &variance), 1u);
    EXPECT_EQ(ref::CutSpikes(&expected, &variance), 1u);
    for (int c = 0; c < 3; ++c) EXPECT_EQ(cut.At(c, 3, 2), 0.f);
    for (size_t i = 0; i < cut.data.size(); ++i) {
        if (i % cut.PixelCount() != size_t(3 * w + 2)) {
            EXPECT_EQ(cut.data[i], color.data[i]);
        }
    }
    EXPECT_EQ(0, std::memcmp(cut.data.data(), expected.data.data(), cut.data.size() * 4));
}

// Lights' rims against the reference on the random frames, with a variance that makes
// about a tenth of the pixels lights (0, or tiny against the value) and the rest noisy,
// and a bright light planted beside a rim and a lone spike: the same pixels and bits, and
// the same when repeated.
TEST_P(LocalMeanMatches, CutLightRimsMatchesReference) {
    const LocalMeanCase &c = GetParam();
    Image input, variance;
    LightsCase(c, "light rims", &input, &variance);
    if (c.w >= 3 && c.h >= 3)
        for (int ch = 0; ch < c.channels; ++ch) {
            input.At(ch, 1, 1) = 200;
            variance.At(ch, 1, 1) = 0;
            input.At(ch, 1, 2) = 20;
        }
    Image expected = input, got = input, again = input;
    std::vector<size_t> rims = ref::CutLightRims(&expected, variance);
    EXPECT_EQ(CutLightRims(&got, variance), rims);
    ASSERT_EQ(0, std::memcmp(got.data.data(), expected.data.data(), got.data.size() * 4));
    {
        ForceParallelParts split(3);  // the rows among threads: the same pixels, in order
        EXPECT_EQ(CutLightRims(&again, variance), rims);
    }
    EXPECT_EQ(0, std::memcmp(again.data.data(), got.data.data(), got.data.size() * 4));
    Image one(c.w, c.h, 1);
    for (size_t p = 0; p < one.data.size(); ++p) one.data[p] = variance.data[p];
    Image expectedOne = input, gotOne = input;
    EXPECT_EQ(CutLightRims(&gotOne, one), ref::CutLightRims(&expectedOne, one));
    EXPECT_EQ(0,
              std::memcmp(gotOne.data.data(), expectedOne.data.data(), gotOne.data.size() * 4));
}

// A bulb (3x3 of 240, its samples agreeing) on a wall of 0.1 with a rim pixel one sample saw
// (15) beside it: the rim takes the wall's median, the bulb and a lone spike away from
// any light stay (CutSpikes's), and a wrongly sized variance cuts nothing.
TEST(LocalMeanProperties, CutLightRimsCutsOnlyPixelsBesideALight) {
    const int w = 16, h = 12;
    Image color(w, h, 3, 0.1f), variance(w, h, 3, 0.01f);
    for (int c = 0; c < 3; ++c) {
        for (int y = 4; y <= 6; ++y)
            for (int x = 4; x <= 6; ++x) {
                color.At(c, y, x) = 240;
                variance.At(c, y, x) = 1e-4f;
            }
        color.At(c, 5, 7) = 15;  // rim
        variance.At(c, 5, 7) = 14;
        color.At(c, 2, 12) = 15;  // lone spike: no light beside it
        variance.At(c, 2, 12) = 14;
    }
    Image cut = color;
    std::vector<size_t> rims = CutLightRims(&cut, variance);
    ASSERT_EQ(rims.size(), 1u);
    EXPECT_EQ(rims[0], size_t(5 * w + 7));
    for (int c = 0; c < 3; ++c) EXPECT_EQ(cut.At(c, 5, 7), 0.1f);
    for (size_t i = 0; i < cut.data.size(); ++i)
        if (i % cut.PixelCount() != size_t(5 * w + 7)) {
            EXPECT_EQ(cut.data[i], color.data[i]);
        }
    Image other(w, h - 1, 3), same = color;
    EXPECT_TRUE(CutLightRims(&same, other).empty());
    EXPECT_EQ(0, std::memcmp(same.data.data(), color.data.data(), color.data.size() * 4));
}

// A bulb whose edge a wide pixel filter spread over two pixels: a column of 150 beside the
// bulb, its samples differing (no light), and outside it a rim pixel one sample saw (15),
// two pixels from the bulb. The rim is cut all the same; the pixel beyond it stays.
TEST(LocalMeanProperties, CutLightRimsReachesPastALightsInnerEdge) {
    const int w = 16, h = 12;
    Image color(w, h, 3, 0.1f), variance(w, h, 3, 0.01f);
    for (int c = 0; c < 3; ++c) {
        for (int y = 4; y <= 6; ++y) {
            for (int x = 4; x <= 6; ++x) {
                color.At(c, y, x) = 240;
                variance.At(c, y, x) = 1e-4f;
            }
            color.At(c, y, 7) = 150;  // inner edge: part of its samples saw the bulb
            variance.At(c, y, 7) = 1400;
        }
        color.At(c, 5, 8) = 15;  // outer rim
        variance.At(c, 5, 8) = 14;
        color.At(c, 5, 10) = 15;  // four pixels from the bulb: a lone spike, stays
        variance.At(c, 5, 10) = 14;
    }
    Image cut = color, expected = color;
    std::vector<size_t> rims = CutLightRims(&cut, variance);
    EXPECT_EQ(rims, ref::CutLightRims(&expected, variance));
    EXPECT_EQ(0, std::memcmp(cut.data.data(), expected.data.data(), cut.data.size() * 4));
    EXPECT_NE(std::find(rims.begin(), rims.end(), size_t(5 * w + 8)), rims.end());
    EXPECT_EQ(std::find(rims.begin(), rims.end(), size_t(5 * w + 10)), rims.end());
    for (int c = 0; c < 3; ++c) EXPECT_EQ(cut.At(c, 5, 8), 0.1f);
}

// Histograms of `bins` per colour for a w x h frame: 16 samples a pixel (none for about one
// in fifty), spread over the low bins, and about one pixel in two hundred with 1-3 samples
// above the range (the last colour bin).
Image RandomHistograms(int w, int h, int bins, std::mt19937_64 *rng) {
    std::uniform_real_distribution<float> unit(0, 1);
    Image hist(w, h, 3 * bins + 1);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const bool empty = unit(*rng) < 0.02f;
            hist.At(3 * bins, y, x) = empty ? 0.f : 16.f;
            if (empty) continue;
            const float bright = unit(*rng) < 0.005f ? float(1 + int(3 * unit(*rng))) : 0.f;
            for (int c = 0; c < 3; ++c) {
                const float low = unit(*rng) * (16 - bright);
                hist.At(c * bins + 1, y, x) = low;
                hist.At(c * bins + 2, y, x) = 16 - bright - low;
                hist.At(c * bins + bins - 1, y, x) = bright;
            }
        }
    return hist;
}

// Bright clusters against the reference on the random frames (NaN, Inf, zeros, negatives,
// spikes of 100), with random histograms and two planted clusters of one-sample pixels over
// a flat patch (no other bright sample in their search windows), and on the larger frame a
// caustic split at its middle: the same pixels (those given back and those bridged) and
// bits, the same when repeated over threads.
TEST_P(LocalMeanMatches, CutBrightClustersMatchesReference) {
    const LocalMeanCase &c = GetParam();
    Image input, output;
    MakeImages(c, &input, &output);
    std::mt19937_64 rng(
        SeedFromName("bright clusters " + std::to_string(c.w) + "x" + std::to_string(c.h)));
    const int bins = 20;
    Image hist = RandomHistograms(c.w, c.h, bins, &rng);
    for (auto [x0, y0] : {std::pair{c.w / 4, c.h / 4}, {3 * c.w / 4, 2 * c.h / 3}})
        for (int y = y0 - 8; y <= y0 + 8; ++y)
            for (int x = x0 - 7; x <= x0 + 7; ++x) {
                if (x < 0 || y < 0 || x >= c.w || y >= c.h) continue;
                const bool column = x == x0 && y >= y0 - 1 && y <= y0 + 1;
                if (std::abs(x - x0) <= 3 && std::abs(y - y0) <= 3)
                    for (int ch = 0; ch < c.channels; ++ch)
                        input.At(ch, y, x) = column ? 5 : 0.02f;
                for (int ch = 0; ch < 3; ++ch) {
                    hist.At(ch * bins + 1, y, x) = column ? 15.f : 16.f;
                    hist.At(ch * bins + 2, y, x) = 0;
                    hist.At(ch * bins + bins - 1, y, x) = column ? 1.f : 0.f;
                }
                hist.At(3 * bins, y, x) = 16;
            }
    // A column of 2 bright samples of 16 a pixel on the left edge from the corner, over a
    // flat corner (its window clipped by two borders).
    for (int y = 0; y <= std::min(c.h - 1, 8); ++y)
        for (int x = 0; x <= std::min(c.w - 1, 6); ++x) {
            const bool column = x == 0 && y <= 2;
            for (int ch = 0; ch < c.channels; ++ch) input.At(ch, y, x) = column ? 5 : 0.02f;
            for (int ch = 0; ch < 3; ++ch) {
                hist.At(ch * bins + 1, y, x) = column ? 14.f : 16.f;
                hist.At(ch * bins + 2, y, x) = 0;
                hist.At(ch * bins + bins - 1, y, x) = column ? 2.f : 0.f;
            }
            hist.At(3 * bins, y, x) = 16;
        }
    // A caustic split at its middle (the pixel at x0 + 1, y0 + 1 under 16 times its
    // neighbours' median), on a flat patch of frames large enough to hold a third.
    if (c.w >= 48 && c.h >= 48)
        for (int x0 = c.w / 4, y0 = 2 * c.h / 3, y = y0 - 7; y <= y0 + 9; ++y)
            for (int x = x0 - 6; x <= x0 + 8; ++x) {
                const int dx = x - x0, dy = y - y0;
                float sum = 0.04f, samples = 0;
                if (dy == 0 && dx == 1) sum = 0.30f;
                if (dy == 0 && dx == 2) sum = 2.38f, samples = 1;
                if (dy == 1 && dx >= 0 && dx <= 2)
                    sum = dx == 0 ? 7.37f : dx == 1 ? 3.87f : 3.10f, samples = 1;
                if (dy == 2 && dx == 0) sum = 3.60f, samples = 2;
                for (int ch = 0; ch < c.channels; ++ch) input.At(ch, y, x) = sum / 3;
                for (int ch = 0; ch < 3; ++ch) {
                    hist.At(ch * bins + 1, y, x) = 16 - samples;
                    hist.At(ch * bins + 2, y, x) = 0;
                    hist.At(ch * bins + bins - 1, y, x) = samples;
                }
                hist.At(3 * bins, y, x) = 16;
            }
    Image expected = input, got = input, again = input;
    std::vector<size_t> bridged, expectedBridged, bridgedAgain;
    const std::vector<size_t> cut =
        ref::CutBrightClusters(input, hist, 6, &expected, &expectedBridged);
    EXPECT_EQ(CutBrightClusters(input, hist, 6, &got, &bridged), cut);
    EXPECT_EQ(bridged, expectedBridged);
    ASSERT_EQ(0, std::memcmp(got.data.data(), expected.data.data(), got.data.size() * 4));
    {
        ForceParallelParts split(3);  // the rows among threads: the same pixels and bits
        EXPECT_EQ(CutBrightClusters(input, hist, 6, &again, &bridgedAgain), cut);
        EXPECT_EQ(bridgedAgain, bridged);
    }
    EXPECT_EQ(0, std::memcmp(again.data.data(), got.data.data(), got.data.size() * 4));
    if (c.w >= 16 && c.h >= 16) {
        EXPECT_GE(cut.size(), 9u);  // the planted columns
    }
    if (c.w >= 48 && c.h >= 48) {
        EXPECT_EQ(bridged.size(), 5u);  // the planted caustic
    }
    if (c.w >= 2 && c.h >= 4) {
        for (int y = 0; y <= 2; ++y)
            EXPECT_TRUE(std::binary_search(cut.begin(), cut.end(), size_t(y) * c.w)) << y;
    }
}

// A column of three pixels that one bright sample of 16 each saw, on a flat floor with no
// other bright sample within the search window, is cut whole (a light's reflection); the same
// column among
// many bright samples (noise the filter spreads), a column whose samples are all bright (the
// bright veto keeps such pixels apart) and a pair alone on the floor (chance makes pairs)
// stay.
TEST(LocalMeanProperties, CutBrightClustersCutsOnlyAClusterThatStandsOut) {
    const int w = 40, h = 20, bins = test::HistogramFloor::kBins;
    test::HistogramFloor wall(w, h);
    Image &color = wall.color, &hist = wall.hist;
    auto bright = [&](int x, int y, float samples, float value) {
        wall.Bright(x, y, samples, value);
    };
    for (int y = 9; y <= 11; ++y) bright(8, y, 1, 3.4f);   // the floor's column
    for (int y = 9; y <= 11; ++y) bright(24, y, 1, 3.4f);  // the same among others
    for (int y = 2; y < h; y += 3)
        for (int x = 18; x < 31; x += 3)
            if (x != 24) bright(x, y, 1, 1.5f);
    for (int y = 4; y <= 6; ++y) bright(36, y, 16, 80);  // a highlight every sample saw
    bright(4, 2, 1, 3.4f), bright(5, 2, 2, 6.8f);        // a pair alone on the floor
    Image cut = color;
    const std::vector<size_t> pixels = CutBrightClusters(color, hist, 6, &cut);
    ASSERT_EQ(pixels, (std::vector<size_t>{9 * w + 8, 10 * w + 8, 11 * w + 8}));
    for (size_t p : pixels)
        for (int c = 0; c < 3; ++c) EXPECT_EQ(cut.Plane(c)[p], 0.0133f);
    for (size_t i = 0; i < cut.data.size(); ++i)
        if (std::find(pixels.begin(), pixels.end(), i % cut.PixelCount()) == pixels.end()) {
            EXPECT_EQ(cut.data[i], color.data[i]) << i;
        }
    Image small(w, h - 1, 3 * bins + 1), same = color;
    EXPECT_TRUE(CutBrightClusters(color, small, 6, &same).empty());
}

// Each limit of a bright cluster on its accepting and rejecting side, on a wall of 16 samples
// a pixel (host and CPU twin, the same pixels and bits): cut are a column of 2 bright samples
// a pixel from the corner down the left edge, a row along the top edge with 3 and 4 of 16 in
// a pixel (4 <= 0.3 x 16), a 3x3 block of 9 pixels (corners dimmer, so that each is over its
// neighbours' median), a plus of 5, a row of 3 and a row of 3 pixels of 10 samples holding 3
// each (the tie, 3 = 0.3 x 10); left are the row along the top with 5 of 16 in a pixel, a row
// of 4 (x1 - x0 = 3) and the row of 10 samples with 4 in a pixel.
TEST(LocalMeanProperties, CutBrightClustersLimitsOnBothSides) {
    const int w = 80, h = 40, bins = 20;
    Image color(w, h, 3, 0.0133f), hist(w, h, 3 * bins + 1);
    auto samples = [&](int x, int y, float count, float bright) {
        for (int c = 0; c < 3; ++c) {
            hist.At(c * bins + 1, y, x) = count - bright;
            hist.At(c * bins + bins - 1, y, x) = bright;
        }
        hist.At(3 * bins, y, x) = count;
    };
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) samples(x, y, 16, 0);
    std::vector<size_t> want;
    auto bright = [&](int x, int y, float count, float b, float value, bool cut) {
        samples(x, y, count, b);
        for (int c = 0; c < 3; ++c) color.At(c, y, x) = value;
        if (cut) want.push_back(size_t(y) * w + x);
    };
    for (int y = 0; y <= 2; ++y) bright(0, y, 16, 2, 3.4f, true);  // the corner's column
    for (int x = 20; x <= 22; ++x) bright(x, 0, 16, x == 20 ? 3 : x == 21 ? 4 : 1, 3.4f, true);
    for (int y = 15; y <= 17; ++y)
        for (int x = 40; x <= 42; ++x)
            bright(x, y, 16, 1, (x == 41 || y == 16) ? 6.f : 0.3f, true);  // the block
    for (auto [x, y] : {std::pair{61, 15}, {60, 16}, {61, 16}, {62, 16}, {61, 17}})
        bright(x, y, 16, 2, 3.4f, true);                              // the plus
    for (int x = 60; x <= 62; ++x) bright(x, 30, 16, 1, 3.4f, true);  // a row of 3
    for (int x = 5; x <= 7; ++x) bright(x, 22, 10, 3, 3.4f, true);    // the tie
    for (int x = 20; x <= 22; ++x) bright(x, 30, 16, x == 21 ? 5 : 1, 3.4f, false);
    for (int x = 40; x <= 43; ++x) bright(x, 30, 16, 1, 3.4f, false);  // a row of 4
    for (int x = 72; x <= 74; ++x) bright(x, 5, 10, x == 73 ? 4 : 3, 3.4f, false);
    std::sort(want.begin(), want.end());
    Image got = color, expected = color;
    const std::vector<size_t> cut = CutBrightClusters(color, hist, 6, &got);
    EXPECT_EQ(cut, want);
    EXPECT_EQ(ref::CutBrightClusters(color, hist, 6, &expected), cut);
    EXPECT_EQ(0, std::memcmp(got.data.data(), expected.data.data(), got.data.size() * 4));
}

// The robust estimate reads Gaussian noise's variance (its mean over a frame within 5%),
// and a bright line the albedo does not show does not raise it beside the line, where a
// 3x3 sample variance of the same frame is many times the noise.
TEST(LocalMeanProperties, FrameNoiseReadsTheNoiseAndNotALine) {
    const int w = 192, h = 192;
    std::mt19937_64 rng(SeedFromName("frame noise gaussian"));
    std::normal_distribution<float> gauss(0, 1);
    Image color(w, h, 1), albedo(w, h, 1);
    const float sd = 0.05f;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            albedo.At(0, y, x) = 0.5f;
            color.At(0, y, x) = 0.25f + 0.5f * sd * gauss(rng);  // z's noise: sd
        }
    Image flat = FrameNoise(color, &albedo);
    double mean = 0;
    for (float v : flat.data) mean += v;
    mean /= double(flat.data.size());
    EXPECT_NEAR(mean, 0.25 * sd * sd, 0.05 * 0.25 * sd * sd);
    // A diagonal line of 20 times the level: beside it (one pixel off) the estimate stays.
    for (int i = 0; i < w; ++i) color.At(0, i, i) = 5;
    Image lined = FrameNoise(color, &albedo);
    double beside = 0;
    int n = 0;
    for (int i = 10; i + 10 < w; ++i, ++n) beside += lined.At(0, i, i + 1);
    EXPECT_LT(beside / n, 2 * 0.25 * sd * sd);
}

// A frame darkened uniformly by a combination (0.5 -> 0.3) whose restore brings back 0.5
// everywhere; half1 agrees with the restore on the left and with the unrestored combination
// on the right: the check keeps the restore on the left and none of it on the right, and
// with a floor lifts the rest just enough for that share of the input's mean.
TEST(LocalMeanProperties, RestoreCheckKeepsWhatHalfOneConfirms) {
    const int w = 96, h = 24, r = 2, s = 3;
    Image input(w, h, 3, 0.5f), half0(w, h, 3, 0.5f), half1(w, h, 3, 0.5f);
    Image combined(w, h, 3, 0.3f), combinedHalf(w, h, 3, 0.3f);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = w / 2; x < w; ++x) half1.At(c, y, x) = 0.3f;
    Image restored = combined, output;
    RestoreLocalMeansRebalanced(input, r, &restored, nullptr, kLocalMeanRebalanceAuto);
    RestoreCheck check =
        RestoreLocalMeansChecked(input, half0, half1, combined, combinedHalf, r, nullptr,
                                 kLocalMeanRebalanceAuto, s, 0, &output);
    EXPECT_EQ(check.lift, 0);
    EXPECT_NEAR(check.meanShare, 0.5, 0.1);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y) {
            for (int x = 0; x < w / 2 - 2 * s; ++x)
                EXPECT_NEAR(output.At(c, y, x), restored.At(c, y, x), 1e-6);
            for (int x = w / 2 + 2 * s; x < w; ++x) EXPECT_EQ(output.At(c, y, x), 0.3f);
        }
    EXPECT_NEAR(restored.At(0, h / 2, w / 4), 0.5, 0.01);

    RestoreCheck lifted =
        RestoreLocalMeansChecked(input, half0, half1, combined, combinedHalf, r, nullptr,
                                 kLocalMeanRebalanceAuto, s, kRestoreCheckFloor, &output);
    EXPECT_GT(lifted.lift, 0);
    EXPECT_LT(lifted.lift, 1);
    double mean = 0;
    for (float v : output.data) mean += v;
    mean /= double(output.Size());
    EXPECT_NEAR(mean, kRestoreCheckFloor * 0.5, 1e-5);

    // The gain lifts the checked output as a whole: every value times one gain, the mean
    // the same share of the input's, and the restore's share as it was.
    Image gained;
    RestoreCheck gain =
        RestoreLocalMeansChecked(input, half0, half1, combined, combinedHalf, r, nullptr,
                                 kLocalMeanRebalanceAuto, s, 0, &output);
    RestoreCheck raised =
        RestoreLocalMeansChecked(input, half0, half1, combined, combinedHalf, r, nullptr,
                                 kLocalMeanRebalanceAuto, s, kRestoreCheckFloor, &gained, 2);
    EXPECT_EQ(raised.lift, 0);
    EXPECT_EQ(raised.meanShare, gain.meanShare);
    EXPECT_GT(raised.gain, 1);
    double gainedMean = 0;
    for (size_t i = 0; i < gained.data.size(); ++i) {
        EXPECT_NEAR(gained.data[i], raised.gain * output.data[i], 1e-6);
        gainedMean += gained.data[i];
    }
    EXPECT_NEAR(gainedMean / double(gained.Size()), kRestoreCheckFloor * 0.5, 1e-5);
    // A gain that reaches the floor leaves no lift, whatever its last rounding step.
    for (int k = 0; k < 20; ++k) {
        RestoreCheck reached =
            RestoreLocalMeansChecked(input, half0, half1, combined, combinedHalf, r, nullptr,
                                     kLocalMeanRebalanceAuto, s, 0.9 + 0.005 * k, &gained, 2);
        EXPECT_GT(reached.gain, 1);
        EXPECT_EQ(reached.lift, 0) << 0.9 + 0.005 * k;
    }

    // A gain held to its cap: the rest of the way by the lift.
    RestoreCheck capped = RestoreLocalMeansChecked(input, half0, half1, combined, combinedHalf,
                                                   r, nullptr, kLocalMeanRebalanceAuto, s,
                                                   kRestoreCheckFloor, &gained, 1.001);
    EXPECT_EQ(capped.gain, 1.001);
    EXPECT_GT(capped.lift, 0);
    EXPECT_LT(capped.lift, lifted.lift);
    gainedMean = 0;
    for (float v : gained.data) gainedMean += v;
    EXPECT_NEAR(gainedMean / double(gained.Size()), kRestoreCheckFloor * 0.5, 1e-5);

    // A gain of 1: the lift alone, as before the gain, bit for bit where half1 keeps none
    // of the restore.
    RestoreCheck alone =
        RestoreLocalMeansChecked(input, half0, half1, combined, combinedHalf, r, nullptr,
                                 kLocalMeanRebalanceAuto, s, kRestoreCheckFloor, &gained, 1);
    EXPECT_EQ(alone.gain, 1);
    EXPECT_EQ(alone.lift, lifted.lift);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = w / 2 + 2 * s; x < w; ++x) {
                double a = combined.At(c, y, x), b = restored.At(c, y, x);
                EXPECT_EQ(gained.At(c, y, x), float(a + alone.lift * (b - a)));
            }
}

// A small light seen in a mirror that one sample of 16 hit, among neighbours whose samples
// all agree (ALightAmongExactPixelsIsKept): the sample lies in half0, so half1 sees the
// mirror alone there and would take the restore's highlight back off. The check keeps it
// whole: one half cannot confirm what a single sample saw, and the neighbours say it is
// coverage, not a rare path. Without a variance layer nothing marks it, and half1 decides.
TEST(LocalMeanProperties, RestoreCheckKeepsALightAmongExactPixels) {
    const int w = 48, h = 48, r = 2, s = 1, cx = 20, cy = 22;
    Image input(w, h, 3, 1.425f), half0(w, h, 3, 1.425f), half1(w, h, 3, 1.425f);
    Image variance(w, h, 3, 0.f), combined(w, h, 3, 1.5f), combinedHalf(w, h, 3, 1.5f);
    for (int c = 0; c < 3; ++c) {
        input.At(c, cy, cx) = 238.8f;
        half0.At(c, cy, cx) = 476.2f;
        variance.At(c, cy, cx) = 56364.f;
        combined.At(c, cy, cx) = combinedHalf.At(c, cy, cx) = 1.7f;
    }
    Image output, unmarked;
    RestoreLocalMeansChecked(input, half0, half1, combined, combinedHalf, r, &variance,
                             kLocalMeanRebalanceAuto, s, 0, &output);
    RestoreLocalMeansChecked(input, half0, half1, combined, combinedHalf, r, nullptr,
                             kLocalMeanRebalanceAuto, s, 0, &unmarked);
    for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(output.At(c, cy, cx), input.At(c, cy, cx)) << c;
        EXPECT_LT(unmarked.At(c, cy, cx), 10.f) << c;
    }
}

// A half of another shape is refused, not read past its end.
TEST(LocalMeanProperties, RestoreCheckRefusesHalvesOfAnotherShape) {
    Image input(8, 8, 3, 0.5f), small(8, 7, 3, 0.5f), output;
    EXPECT_THROW(RestoreLocalMeansChecked(input, input, small, input, input, 1, nullptr, 0.1, 1,
                                          0.99, &output),
                 Error);
}

}  // namespace
}  // namespace mcd
