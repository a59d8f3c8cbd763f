// Tests of the CPU wavelet reference alone (no GPU): filter taps against AWR appendix A,
// perfect reconstruction, closed forms for constant images and variances, propagation of
// non-finite values, and a cross-check against PyWavelets when it is installed.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "cpu_reference/wavelet_analyze.h"
#include "cpu_reference/wavelet_filters.h"
#include "cpu_reference/wavelet_sqanalyze.h"
#include "cpu_reference/wavelet_synthesize.h"
#include "harness/errors.h"
#include "host/error.h"
#include "host/image.h"
#include "host/wavelet.h"

namespace mcd::ref {
namespace {

const double kSqrt2 = std::sqrt(2.0);
const WaveletBasis kBases[] = {WaveletBasis::Haar, WaveletBasis::LeGall53, WaveletBasis::Cdf97};
const std::pair<int, int> kSizes[] = {{1, 1}, {1, 7}, {7, 1},   {2, 2},
                                      {3, 3}, {5, 9}, {17, 13}, {64, 64}};

std::vector<double> RandomValues(size_t count, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> uniform(-1.0, 1.0);
    std::vector<double> values(count);
    for (double &v : values) v = uniform(rng);
    return values;
}

Image RandomImage(int width, int height, int channels, unsigned seed) {
    Image image(width, height, channels);
    std::vector<double> values = RandomValues(image.Size(), seed);
    std::copy(values.begin(), values.end(), image.data.begin());
    return image;
}

// Expands a half filter (index 0 = centre) to the full symmetric filter.
std::vector<double> FullFilter(const std::vector<double> &half) {
    std::vector<double> full(half.rbegin(), half.rend());
    full.insert(full.end(), half.begin() + 1, half.end());
    return full;
}

std::vector<double> FullTaps(const std::vector<double> &taps, WaveletBasis basis) {
    return basis == WaveletBasis::Haar ? taps : FullFilter(taps);
}

double Sum(const std::vector<double> &v) {
    double sum = 0;
    for (double t : v) sum += t;
    return sum;
}

double SumOfSquares(const std::vector<double> &v) {
    double sum = 0;
    for (double t : v) sum += t * t;
    return sum;
}

// Each case is a test of its own, named by its parameters, so a failing one re-runs alone.
class WaveletReferenceBasis : public testing::TestWithParam<WaveletBasis> {};

std::string BasisName(const testing::TestParamInfo<WaveletBasis> &info) {
    return WaveletName(info.param);
}

// A basis, an image size and a level count.
struct LevelsCase {
    WaveletBasis basis;
    int width, height, levels;
};

// Every level count from `firstLevel` up to the most each size allows.
std::vector<LevelsCase> LevelsCases(const std::vector<std::pair<int, int>> &sizes,
                                    int firstLevel) {
    std::vector<LevelsCase> cases;
    for (WaveletBasis basis : kBases)
        for (auto [width, height] : sizes)
            for (int levels = firstLevel; levels <= MaxWaveletLevels(width, height); ++levels)
                cases.push_back({basis, width, height, levels});
    return cases;
}

std::string LevelsCaseName(const testing::TestParamInfo<LevelsCase> &info) {
    const LevelsCase &c = info.param;
    return fmt::format("{}_{}x{}_L{}", WaveletName(c.basis), c.width, c.height, c.levels);
}

TEST(WaveletReferenceFilters, Cdf97MatchesPaperDigits) {
    // AWR appendix A, printed to 6 digits, before the sqrt2 factors.
    const double low[] = {0.602949, 0.266864, -0.078223, -0.016864, 0.026749};
    const double high[] = {1.115087, -0.591272, -0.057544, 0.091272};
    const double synthesisLow[] = {1.115087, 0.591272, -0.057544, -0.091272};
    const double synthesisHigh[] = {0.602949, -0.266864, -0.078223, 0.016864, 0.026749};
    const FilterBank &bank = GetFilterBank(WaveletBasis::Cdf97);
    ASSERT_EQ(bank.analysisLow.size(), 5u);
    ASSERT_EQ(bank.analysisHigh.size(), 4u);
    ASSERT_EQ(bank.synthesisLow.size(), 4u);
    ASSERT_EQ(bank.synthesisHigh.size(), 5u);
    // Rounding to 6 decimals is off by at most 5e-7.
    const double tolerance = 5.0e-7 + 1e-12;
    for (int k = 0; k < 5; ++k) {
        EXPECT_NEAR(bank.analysisLow[k] / kSqrt2, low[k], tolerance) << k;
        EXPECT_NEAR(bank.synthesisHigh[k] / kSqrt2, synthesisHigh[k], tolerance) << k;
    }
    for (int k = 0; k < 4; ++k) {
        EXPECT_NEAR(bank.analysisHigh[k] * kSqrt2, high[k], tolerance) << k;
        EXPECT_NEAR(bank.synthesisLow[k] * kSqrt2, synthesisLow[k], tolerance) << k;
    }
}

TEST(WaveletReferenceFilters, Cdf97MatchesJpeg2000Values) {
    // The usual 16-digit JPEG2000 values; ours are the closed form, within a few ulps.
    const double low[] = {0.6029490182363579, 0.2668641184428723, -0.07822326652898785,
                          -0.01686411844287495, 0.02674875741080976};
    const double high[] = {1.115087052456994, -0.5912717631142470, -0.05754352622849957,
                           0.09127176311424948};
    const FilterBank &bank = GetFilterBank(WaveletBasis::Cdf97);
    for (int k = 0; k < 5; ++k) EXPECT_NEAR(bank.analysisLow[k] / kSqrt2, low[k], 1e-14);
    for (int k = 0; k < 4; ++k) EXPECT_NEAR(bank.analysisHigh[k] * kSqrt2, high[k], 1e-14);
}

TEST(WaveletReferenceFilters, LeGall53MatchesPaper) {
    const FilterBank &bank = GetFilterBank(WaveletBasis::LeGall53);
    const std::vector<double> low = {6 * kSqrt2 / 8, 2 * kSqrt2 / 8, -1 * kSqrt2 / 8};
    const std::vector<double> high = {-2 / kSqrt2 / 2, 1 / kSqrt2 / 2};
    const std::vector<double> synthesisLow = {2 / kSqrt2 / 2, 1 / kSqrt2 / 2};
    const std::vector<double> synthesisHigh = {-6 * kSqrt2 / 8, 2 * kSqrt2 / 8, 1 * kSqrt2 / 8};
    auto expectNear = [](const std::vector<double> &a, const std::vector<double> &b) {
        ASSERT_EQ(a.size(), b.size());
        for (size_t k = 0; k < a.size(); ++k) EXPECT_NEAR(a[k], b[k], 1e-15) << k;
    };
    expectNear(bank.analysisLow, low);
    expectNear(bank.analysisHigh, high);
    expectNear(bank.synthesisLow, synthesisLow);
    expectNear(bank.synthesisHigh, synthesisHigh);
}

TEST_P(WaveletReferenceBasis, DcGains) {
    WaveletBasis basis = GetParam();
    const FilterBank &bank = GetFilterBank(basis);
    EXPECT_NEAR(Sum(FullTaps(bank.analysisLow, basis)), kSqrt2, 1e-15);
    EXPECT_NEAR(Sum(FullTaps(bank.analysisHigh, basis)), 0, 1e-15);
    EXPECT_NEAR(Sum(FullTaps(bank.synthesisLow, basis)), kSqrt2, 1e-15);
    EXPECT_NEAR(Sum(FullTaps(bank.synthesisHigh, basis)), 0, 1e-15);
    EXPECT_NEAR(FullFilterSum(bank.analysisLow, basis), kSqrt2, 1e-15);
}

TEST(WaveletReferenceFilters, MirrorIndex) {
    // n = 5: ... 2 1 | 0 1 2 3 4 | 3 2 1 0 1 ...
    const int expected[] = {2, 1, 0, 1, 2, 3, 4, 3, 2, 1, 0, 1};
    for (int p = -2; p <= 9; ++p) EXPECT_EQ(MirrorIndex(p, 5), expected[p + 2]) << p;
    // n = 2 has period 2; n = 1 maps everything to 0.
    for (int p = -5; p <= 5; ++p) EXPECT_EQ(MirrorIndex(p, 2), std::abs(p) % 2) << p;
    EXPECT_EQ(MirrorIndex(3, 1), 0);
}

TEST(WaveletReferenceAnalyze, HandComputedLeGall) {
    // x = {0, 1, 2, 3}: Ext(-1) = 1, Ext(-2) = 2, Ext(4) = 2.
    std::vector<double> x = {0, 1, 2, 3};
    std::vector<double> c = Analyze1D(x, WaveletBasis::LeGall53);
    ASSERT_EQ(c.size(), 4u);
    EXPECT_NEAR(c[0], kSqrt2 / 8 * (6 * 0 + 2 * (1 + 1) - (2 + 2)), 1e-15);
    EXPECT_NEAR(c[1], kSqrt2 / 8 * (6 * 2 + 2 * (1 + 3) - (0 + 2)), 1e-15);
    EXPECT_NEAR(c[2], 1 / kSqrt2 / 2 * (-2 * 1 + 0 + 2), 1e-15);
    EXPECT_NEAR(c[3], 1 / kSqrt2 / 2 * (-2 * 3 + 2 + 2), 1e-15);
}

TEST(WaveletReferenceAnalyze, HandComputedHaarOddLength) {
    std::vector<double> x = {1, 2, 4, 8, 16};
    std::vector<double> c = Analyze1D(x, WaveletBasis::Haar);
    const std::vector<double> expected = {3 / kSqrt2, 12 / kSqrt2, 16 * kSqrt2, 1 / kSqrt2,
                                          4 / kSqrt2};
    ASSERT_EQ(c.size(), expected.size());
    for (size_t i = 0; i < c.size(); ++i) EXPECT_NEAR(c[i], expected[i], 1e-14) << i;
    std::vector<double> back = Synthesize1D(c, WaveletBasis::Haar);
    for (size_t i = 0; i < x.size(); ++i) EXPECT_NEAR(back[i], x[i], 1e-14) << i;
}

class WaveletReferenceRoundTrip : public testing::TestWithParam<LevelsCase> {};

TEST_P(WaveletReferenceRoundTrip, PerfectReconstructionInDouble) {
    const auto [basis, width, height, levels] = GetParam();
    std::vector<double> x = RandomValues(size_t(width) * height, width * 131 + height);
    double scale = 0;
    for (double v : x) scale = std::max(scale, std::abs(v));
    std::vector<double> c = AnalyzePlane(x, width, height, basis, levels);
    std::vector<double> back = SynthesizePlane(c, width, height, basis, levels);
    double error = 0;
    for (size_t i = 0; i < x.size(); ++i) error = std::max(error, std::abs(back[i] - x[i]));
    EXPECT_LE(error, 1e-12 * scale);
    if (levels == 0) {
        EXPECT_EQ(c, x);
    }
}

INSTANTIATE_TEST_SUITE_P(Cases, WaveletReferenceRoundTrip,
                         testing::ValuesIn(LevelsCases({std::begin(kSizes), std::end(kSizes)},
                                                       0)),
                         LevelsCaseName);

TEST_P(WaveletReferenceBasis, ImageRoundTripAndChannelsIndependent) {
    WaveletBasis basis = GetParam();
    const int width = 13, height = 10, levels = MaxWaveletLevels(width, height);
    Image image = RandomImage(width, height, 3, 7);
    Image c = WaveletAnalyze(image, basis, levels);
    ASSERT_TRUE(c.SameShape(image));
    Image back = WaveletSynthesize(c, basis, levels);
    ASSERT_TRUE(back.SameShape(image));
    for (size_t i = 0; i < image.Size(); ++i)
        EXPECT_NEAR(back.data[i], image.data[i], 1e-5) << i;
    // Channel 1 alone gives the same coefficients as channel 1 of the three.
    Image one(width, height, 1);
    std::copy(image.Plane(1), image.Plane(1) + image.PixelCount(), one.Plane(0));
    Image cOne = WaveletAnalyze(one, basis, levels);
    EXPECT_TRUE(std::equal(cOne.data.begin(), cOne.data.end(), c.Plane(1)));
}

TEST(WaveletReferenceAnalyze, LevelsOutOfRangeThrow) {
    Image image(5, 3, 1);
    int maxLevels = MaxWaveletLevels(5, 3);
    for (int levels : {-1, maxLevels + 1}) {
        for (WaveletBasis basis : kBases) {
            EXPECT_TRUE(test::ThrowsError(ErrorKind::InvalidArgument,
                                          [&] { WaveletAnalyze(image, basis, levels); }));
            EXPECT_TRUE(test::ThrowsError(ErrorKind::InvalidArgument,
                                          [&] { WaveletSynthesize(image, basis, levels); }));
            EXPECT_TRUE(test::ThrowsError(ErrorKind::InvalidArgument,
                                          [&] { WaveletSqAnalyze(image, basis, levels); }));
            EXPECT_TRUE(test::ThrowsError(ErrorKind::InvalidArgument, [&] {
                WaveletAnalyzeMagnitude(image, basis, levels);
            }));
            EXPECT_TRUE(test::ThrowsError(ErrorKind::InvalidArgument, [&] {
                WaveletSynthesizeMagnitude(image, basis, levels);
            }));
        }
    }
    EXPECT_NO_THROW(WaveletAnalyze(image, WaveletBasis::Cdf97, maxLevels));
    EXPECT_NO_THROW(WaveletAnalyze(Image(1, 1, 1), WaveletBasis::Cdf97, 0));
}

// Value of coefficient (x, y) after `levels` levels of a transform whose 1D low (high)
// filter maps a constant k to lowGain * k (highGain * k), on a constant image of 1. The
// coefficient was last written at the deepest level whose region holds it; before that
// level the region was constant, so every transformed axis of every earlier level gave
// lowGain, and that level gave lowGain or highGain by the half the coordinate is in. An
// axis of length 1 is not transformed.
double ConstantImageGain(int width, int height, int levels, int x, int y, double lowGain,
                         double highGain) {
    if (levels == 0) return 1;
    int last = 0;
    while (last + 1 < levels && x < LevelExtent(width, last + 1) &&
           y < LevelExtent(height, last + 1))
        ++last;
    double gain = 1;
    for (int k = 0; k <= last; ++k) {
        int w = LevelExtent(width, k), h = LevelExtent(height, k);
        bool xHigh = k == last && x >= (w + 1) / 2;
        bool yHigh = k == last && y >= (h + 1) / 2;
        if (w > 1) gain *= xHigh ? highGain : lowGain;
        if (h > 1) gain *= yHigh ? highGain : lowGain;
    }
    return gain;
}

class WaveletReferenceConstantImage : public testing::TestWithParam<LevelsCase> {};

TEST_P(WaveletReferenceConstantImage, HasNoDetail) {
    const auto [basis, width, height, levels] = GetParam();
    const float constants[] = {1.f, -2.5f};
    Image image(width, height, 2);
    for (int ch = 0; ch < 2; ++ch)
        std::fill(image.Plane(ch), image.Plane(ch) + image.PixelCount(), constants[ch]);
    Image c = WaveletAnalyze(image, basis, levels);
    for (int ch = 0; ch < 2; ++ch) {
        for (int y = 0; y < height; ++y) {
            for (int x = 0; x < width; ++x) {
                double expected =
                    constants[ch] * ConstantImageGain(width, height, levels, x, y, kSqrt2, 0.0);
                double tolerance = 1e-6 * std::abs(expected) + 1e-12;
                EXPECT_NEAR(c.At(ch, y, x), expected, tolerance)
                    << "c " << ch << " x " << x << " y " << y;
            }
        }
    }
    // Square images: LL = c (sum h0)^(2 levels), the rest is zero.
    if (width == height) {
        EXPECT_NEAR(c.At(0, 0, 0), std::pow(2.0, levels), 1e-6 * std::pow(2.0, levels));
    }
}

INSTANTIATE_TEST_SUITE_P(
    Cases, WaveletReferenceConstantImage,
    testing::ValuesIn(
        LevelsCases({{1, 7}, {7, 1}, {2, 2}, {3, 3}, {5, 9}, {17, 13}, {16, 16}, {64, 64}}, 1)),
    LevelsCaseName);

// The natural gains (the sums of the squared taps) where they are simple fractions.
TEST(WaveletReferenceSqAnalyze, NaturalGains) {
    for (WaveletBasis basis : kBases) {
        const FilterBank &bank = GetFilterBank(basis);
        double naturalLow = SumOfSquares(FullTaps(bank.analysisLow, basis));
        double naturalHigh = SumOfSquares(FullTaps(bank.analysisHigh, basis));
        if (basis == WaveletBasis::Haar) {
            EXPECT_NEAR(naturalLow, 1.0, 1e-15);
            EXPECT_NEAR(naturalHigh, 1.0, 1e-15);
        }
        if (basis == WaveletBasis::LeGall53) {
            EXPECT_NEAR(naturalLow, 2.0 / 64 * (36 + 2 * 4 + 2 * 1), 1e-15);
            EXPECT_NEAR(naturalHigh, 1.0 / 8 * (4 + 2 * 1), 1e-15);
        }
    }
}

// A level case with the low and high sums the squared analysis renormalises to (0: the
// natural ones).
struct SumsCase {
    LevelsCase level;
    double lowSum, highSum;
};

class WaveletReferenceConstantVariance : public testing::TestWithParam<SumsCase> {};

TEST_P(WaveletReferenceConstantVariance, MatchesClosedForm) {
    const auto [level, lowSum, highSum] = GetParam();
    const auto [basis, width, height, levels] = level;
    const float variances[] = {1.f, 0.375f};
    const FilterBank &bank = GetFilterBank(basis);
    double naturalLow = SumOfSquares(FullTaps(bank.analysisLow, basis));
    double naturalHigh = SumOfSquares(FullTaps(bank.analysisHigh, basis));
    double lowGain = lowSum > 0 ? lowSum : naturalLow;
    double highGain = highSum > 0 ? highSum : naturalHigh;
    Image variance(width, height, 2);
    for (int ch = 0; ch < 2; ++ch)
        std::fill(variance.Plane(ch), variance.Plane(ch) + variance.PixelCount(),
                  variances[ch]);
    Image c = WaveletSqAnalyze(variance, basis, levels, lowSum, highSum);
    for (int ch = 0; ch < 2; ++ch) {
        for (int y = 0; y < height; ++y) {
            for (int x = 0; x < width; ++x) {
                double expected = variances[ch] * ConstantImageGain(width, height, levels, x, y,
                                                                    lowGain, highGain);
                EXPECT_NEAR(c.At(ch, y, x), expected, 1e-6 * expected)
                    << "c " << ch << " x " << x << " y " << y;
            }
        }
    }
}

std::vector<SumsCase> SumsCases() {
    const std::pair<int, int> sizes[] = {{1, 7}, {7, 1},   {2, 2},  {3, 3},
                                         {5, 9}, {17, 13}, {16, 16}};
    const std::pair<double, double> sums[] = {{0, 0},
                                              {1.05, 0},
                                              {1.05, 1.05},
                                              {std::sqrt(0.5), std::sqrt(0.5)},
                                              {1.05, std::sqrt(0.5)}};
    std::vector<SumsCase> cases;
    for (WaveletBasis basis : kBases)
        for (auto [lowSum, highSum] : sums)
            for (auto [width, height] : sizes)
                for (int levels = 1; levels <= MaxWaveletLevels(width, height); ++levels)
                    cases.push_back({{basis, width, height, levels}, lowSum, highSum});
    return cases;
}

// A sum in a name: 3 digits, the point as "p" (gtest names take [A-Za-z0-9_] only).
std::string SumName(double sum) {
    std::string name = fmt::format("{:.3g}", sum);
    std::replace(name.begin(), name.end(), '.', 'p');
    return name;
}

INSTANTIATE_TEST_SUITE_P(Cases, WaveletReferenceConstantVariance,
                         testing::ValuesIn(SumsCases()),
                         [](const testing::TestParamInfo<SumsCase> &info) {
                             const SumsCase &c = info.param;
                             return fmt::format("{}_{}x{}_L{}_sums{}_{}",
                                                WaveletName(c.level.basis), c.level.width,
                                                c.level.height, c.level.levels,
                                                SumName(c.lowSum), SumName(c.highSum));
                         });

// One level along a row of 17 with an impulse v at sample 8: s[n] = h0[|2n-8|]^2 v and
// d[n] = h1[|2n+1-8|]^2 v (no reflection reaches sample 8 again).
class WaveletReferenceImpulse : public testing::TestWithParam<WaveletBasis> {};

TEST_P(WaveletReferenceImpulse, SqAnalyzeGivesSquaredTaps) {
    WaveletBasis basis = GetParam();
    const FilterBank &bank = GetFilterBank(basis);
    Image variance(17, 1, 1);
    variance.At(0, 0, 8) = 2.f;
    Image c = WaveletSqAnalyze(variance, basis, 1);
    auto squaredTap = [](const std::vector<double> &taps, int k) {
        k = std::abs(k);
        return k < int(taps.size()) ? taps[k] * taps[k] : 0.0;
    };
    for (int n = 0; n < 9; ++n)
        EXPECT_NEAR(c.At(0, 0, n), 2 * squaredTap(bank.analysisLow, 2 * n - 8), 1e-6) << n;
    for (int n = 0; n < 8; ++n)
        EXPECT_NEAR(c.At(0, 0, 9 + n), 2 * squaredTap(bank.analysisHigh, 2 * n + 1 - 8), 1e-6)
            << n;
}

INSTANTIATE_TEST_SUITE_P(Cases, WaveletReferenceImpulse,
                         testing::Values(WaveletBasis::LeGall53, WaveletBasis::Cdf97),
                         BasisName);

std::set<int> NonFiniteIndices(const std::vector<double> &c) {
    std::set<int> result;
    for (size_t i = 0; i < c.size(); ++i)
        if (!std::isfinite(c[i])) result.insert(int(i));
    return result;
}

TEST(WaveletReferenceAnalyze, NaNStaysInsideSupport1D) {
    const double nan = std::nan("");
    // LeGall, N = 8, NaN at 1: s0 (-2..2, Ext(-1) = 1), s1 (0..4), d0 (0..2).
    std::vector<double> x(8, 1.0);
    x[1] = nan;
    EXPECT_EQ(NonFiniteIndices(Analyze1D(x, WaveletBasis::LeGall53)), (std::set<int>{0, 1, 4}));
    // CDF 9/7, N = 10, NaN at 0: s[n] reaches 2n-4..2n+4 (n <= 2), d[n] 2n-2..2n+4 (n <= 1).
    x.assign(10, 1.0);
    x[0] = nan;
    EXPECT_EQ(NonFiniteIndices(Analyze1D(x, WaveletBasis::Cdf97)),
              (std::set<int>{0, 1, 2, 5, 6}));
    // Haar, N = 7: NaN at 4 hits the pair (4, 5): s2, d2; at 6 (unpaired) only s3.
    x.assign(7, 1.0);
    x[4] = nan;
    EXPECT_EQ(NonFiniteIndices(Analyze1D(x, WaveletBasis::Haar)), (std::set<int>{2, 6}));
    x[4] = 1.0;
    x[6] = std::numeric_limits<double>::infinity();
    EXPECT_EQ(NonFiniteIndices(Analyze1D(x, WaveletBasis::Haar)), (std::set<int>{3}));
}

TEST(WaveletReferenceAnalyze, NaNStaysInsideSupport2D) {
    // LeGall, 8x8, one level, NaN at (x 3, y 4). Rows: row 4 gets NaN in s1, s2, d1, i.e.
    // columns 1, 2, 5. Columns 1, 2, 5: NaN at y 4 reaches s1, s2, s3 and d1, d2, i.e.
    // rows 1, 2, 3, 5, 6.
    Image image(8, 8, 2, 0.5f);
    image.At(1, 4, 3) = std::nanf("");
    Image c = WaveletAnalyze(image, WaveletBasis::LeGall53, 1);
    std::set<int> columns = {1, 2, 5}, rows = {1, 2, 3, 5, 6};
    for (int ch = 0; ch < 2; ++ch) {
        for (int y = 0; y < 8; ++y) {
            for (int x = 0; x < 8; ++x) {
                bool expected = ch == 1 && columns.count(x) && rows.count(y);
                EXPECT_EQ(!std::isfinite(c.At(ch, y, x)), expected)
                    << "c " << ch << " x " << x << " y " << y;
            }
        }
    }
}

TEST(WaveletReferenceMagnitude, HandValues) {
    // A constant -1 row, LeGall: every s is sum |h0| = 1.5 sqrt2, every d sum |h1| = sqrt2.
    Image row(16, 1, 1, -1.f);
    Image m = WaveletAnalyzeMagnitude(row, WaveletBasis::LeGall53, 1);
    for (int x = 0; x < 16; ++x)
        EXPECT_NEAR(m.At(0, 0, x), x < 8 ? 1.5 * kSqrt2 : kSqrt2, 1e-6) << x;
}

// The magnitude bounds the coefficient, level after level.
TEST_P(WaveletReferenceBasis, MagnitudeBoundsTheTransform) {
    WaveletBasis basis = GetParam();
    Image image = RandomImage(17, 13, 2, 3);
    int levels = MaxWaveletLevels(17, 13);
    Image c = WaveletAnalyze(image, basis, levels);
    Image cm = WaveletAnalyzeMagnitude(image, basis, levels);
    Image x = WaveletSynthesize(c, basis, levels);
    Image xm = WaveletSynthesizeMagnitude(c, basis, levels);
    for (size_t i = 0; i < c.Size(); ++i) {
        EXPECT_GE(cm.data[i] * (1 + 1e-6f), std::abs(c.data[i])) << i;
        EXPECT_GE(xm.data[i] * (1 + 1e-6f), std::abs(x.data[i])) << i;
    }
}

INSTANTIATE_TEST_SUITE_P(Cases, WaveletReferenceBasis, testing::ValuesIn(kBases), BasisName);

// Runs pywt.dwt on each signal; returns false when python3-pywt is missing. pywt's result
// per signal: cA then cD, each of length floor((N + F - 1) / 2) for filter length F.
bool RunPywt(const std::vector<std::pair<std::string, std::vector<double>>> &cases,
             std::vector<std::pair<std::vector<double>, std::vector<double>>> *results) {
    if (std::system("/usr/bin/python3 -c 'import pywt' >/dev/null 2>&1") != 0) return false;
    // Arguments: "wavelet:mode:x0,x1,...". Output: two lines per case, cA and cD.
    std::string command =
        "/usr/bin/python3 -c 'import sys, pywt\n"
        "for arg in sys.argv[1:]:\n"
        "    name, mode, data = arg.split(\":\")\n"
        "    a, d = pywt.dwt([float(v) for v in data.split(\",\")], name, mode=mode)\n"
        "    print(\" \".join(repr(float(v)) for v in a))\n"
        "    print(\" \".join(repr(float(v)) for v in d))\n"
        "'";
    for (const auto &[spec, x] : cases) {
        command += " " + spec + ":";
        char buffer[64];
        for (size_t i = 0; i < x.size(); ++i) {
            std::snprintf(buffer, sizeof(buffer), "%s%.17g", i ? "," : "", x[i]);
            command += buffer;
        }
    }
    FILE *pipe = popen(command.c_str(), "r");
    if (!pipe) return false;
    std::string output;
    char buffer[4096];
    while (size_t n = std::fread(buffer, 1, sizeof(buffer), pipe)) output.append(buffer, n);
    int status = pclose(pipe);
    EXPECT_EQ(status, 0) << "python3 failed";
    std::istringstream lines(output);
    auto parse = [&lines]() {
        std::string line;
        std::getline(lines, line);
        std::istringstream values(line);
        std::vector<double> v;
        double t;
        while (values >> t) v.push_back(t);
        return v;
    };
    for (size_t i = 0; i < cases.size(); ++i) {
        std::vector<double> a = parse();
        std::vector<double> d = parse();
        results->emplace_back(std::move(a), std::move(d));
    }
    return true;
}

// pywt computes out[i] = sum_j f[j] x[2i+1-j] over the extended signal, and its filters
// are zero-padded to even length F: bior4.4 F = 10, centres of dec_lo / dec_hi at 5 / 4,
// so out[i] is centred on 2i-4 / 2i-3: our s[i-2], d[i-2]. bior2.2 F = 6, centres 3 / 2:
// s[i-1], d[i-1]. haar F = 2: s[i], d[i]. Offsets: 2, 1, 0 (= F / 4 rounded down).
// pywt's bior4.4 dec_hi is the negative of the paper's 9/7 high-pass, its bior2.2 dec_hi
// equals the paper's LeGall high-pass, and its haar cD = (x[2i] - x[2i+1]) / sqrt2 is
// the negative of ours. Its 'reflect' mode is our whole-sample symmetric extension (even
// with several reflections, N = 2), 'symmetric' the half-sample one Haar uses; for odd
// N pywt's haar gives one more (zero) cD.
struct PywtBasis {
    WaveletBasis basis;
    const char *spec;
    int offset;
    double highSign;
    double tolerance;
};
// pywt tabulates bior4.4 to about 12 digits (its taps are off by up to 6e-13).
const PywtBasis kPywtBases[] = {{WaveletBasis::Cdf97, "bior4.4:reflect", 2, -1.0, 1e-11},
                                {WaveletBasis::LeGall53, "bior2.2:reflect", 1, 1.0, 1e-14},
                                {WaveletBasis::Haar, "haar:symmetric", 0, -1.0, 1e-14}};
const int kPywtLengths[] = {2, 3, 4, 5, 8, 9, 16, 17, 31};

// Every case's signal and pywt's result, from one python3 run for all cases (started
// once per process, not once per case).
struct PywtRun {
    std::vector<std::pair<std::string, std::vector<double>>> cases;
    std::vector<std::pair<std::vector<double>, std::vector<double>>> results;
    bool ran = false;
};

const PywtRun &Pywt() {
    static const PywtRun run = [] {
        PywtRun r;
        for (const PywtBasis &b : kPywtBases)
            for (int n : kPywtLengths) r.cases.emplace_back(b.spec, RandomValues(n, 1000 + n));
        r.ran = RunPywt(r.cases, &r.results);
        return r;
    }();
    return run;
}

// A basis and a signal length; `index` is the case's place in the python3 run.
struct PywtCase {
    const PywtBasis *basis;
    int n;
    size_t index;
};

std::vector<PywtCase> PywtCases() {
    std::vector<PywtCase> cases;
    for (const PywtBasis &b : kPywtBases)
        for (int n : kPywtLengths) cases.push_back({&b, n, cases.size()});
    return cases;
}

class WaveletReferencePywt : public testing::TestWithParam<PywtCase> {};

TEST_P(WaveletReferencePywt, SingleLevelMatchesPywt) {
    const PywtBasis &b = *GetParam().basis;
    const int n = GetParam().n;
    const PywtRun &run = Pywt();
    if (!run.ran) GTEST_SKIP() << "python3-pywt not installed";
    ASSERT_EQ(run.results.size(), run.cases.size());
    const std::vector<double> &x = run.cases[GetParam().index].second;
    const auto &[a, d] = run.results[GetParam().index];
    std::vector<double> c = Analyze1D(x, b.basis);
    int nLow = (n + 1) / 2, nHigh = n / 2;
    ASSERT_GE(int(a.size()), b.offset + nLow);
    ASSERT_GE(int(d.size()), b.offset + nHigh);
    for (int i = 0; i < nLow; ++i) EXPECT_NEAR(c[i], a[b.offset + i], b.tolerance) << i;
    for (int i = 0; i < nHigh; ++i)
        EXPECT_NEAR(c[nLow + i], b.highSign * d[b.offset + i], b.tolerance) << i;
}

INSTANTIATE_TEST_SUITE_P(Cases, WaveletReferencePywt, testing::ValuesIn(PywtCases()),
                         [](const testing::TestParamInfo<PywtCase> &info) {
                             return fmt::format("{}_N{}", WaveletName(info.param.basis->basis),
                                                info.param.n);
                         });

}  // namespace
}  // namespace mcd::ref
