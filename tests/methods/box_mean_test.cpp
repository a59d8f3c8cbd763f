// Box means down columns and along rows (host/common/box_mean.h) against each window summed on
// its own, in order, in double: the same bits, whether the sums slide or not.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "harness/inputs.h"
#include "host/common/box_mean.h"
#include "host/common/parallel.h"

namespace mcd {
namespace {

using test::SeedFromName;
using test::Transposed;

// The definition: each window summed in order from its top.
std::vector<float> WindowsOneByOne(const std::vector<float> &in, int w, int h, int r) {
    std::vector<float> out(in.size());
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            int a = std::max(0, y - r), b = std::min(h - 1, y + r);
            double sum = 0;
            for (int j = a; j <= b; ++j) sum += in[size_t(j) * w + x];
            out[size_t(y) * w + x] = float(sum / (b - a + 1));
        }
    return out;
}

// Sums slid down every column without a test of exactness: what the function must not do
// where a column's sums round.
std::vector<float> NaiveSlide(const std::vector<float> &in, int w, int h, int r) {
    std::vector<float> out(in.size());
    for (int x = 0; x < w; ++x) {
        double sum = 0;
        for (int j = 0; j <= std::min(h - 1, r); ++j) sum += in[size_t(j) * w + x];
        for (int y = 0; y < h; ++y) {
            int a = std::max(0, y - r), b = std::min(h - 1, y + r);
            if (y > 0 && y + r < h) sum += in[size_t(y + r) * w + x];
            if (y > 0 && y - r - 1 >= 0) sum -= in[size_t(y - r - 1) * w + x];
            out[size_t(y) * w + x] = float(sum / (b - a + 1));
        }
    }
    return out;
}

enum class Kind {
    Plain,
    FewWideRange,
    ManyWideRange,
    NonFinite,
    Spikes,
    Cancelling,
    NearBound,
    OverBound,
    Subnormal
};

// Values in [0, 1) with zeros and negatives; `kind` adds columns whose sums round (a few or
// many: the slide with or without its fallback), NaN/Inf, or lone large values over small
// ones (windows with sums that round beside windows without), or pairs of large values of
// opposite signs (their sum in order loses what lies between them), or lines whose absolute
// sums lie about the exactness test's bound (2^51 units of the smallest value: the test's own
// rounding may fall either way, and both ways must give the same bits), or far over it
// (where sliding rounds), or subnormal values beside normal ones.
std::vector<float> MakePlane(int w, int h, Kind kind) {
    std::mt19937_64 rng(SeedFromName("box mean " + std::to_string(w) + "x" + std::to_string(h) +
                                     " " + std::to_string(int(kind))));
    std::uniform_real_distribution<float> unit(0, 1);
    std::vector<float> plane(size_t(w) * h);
    for (float &v : plane) {
        float u = unit(rng);
        v = u < 0.05f ? 0.f : u < 0.1f ? -unit(rng) : unit(rng);
    }
    for (int x = 0; x < w; ++x) {
        bool wide = (kind == Kind::FewWideRange && x % 11 == 3) ||
                    (kind == Kind::ManyWideRange && x % 2 == 0);
        for (int y = 0; y < h; ++y) {
            float &v = plane[size_t(y) * w + x];
            // Large values above small ones: a slid sum keeps the large ones' rounding.
            if (wide) v = y < h / 2 ? 3e7f * (1 + unit(rng)) : 1e-3f * unit(rng);
        }
    }
    if (kind == Kind::NonFinite)
        for (size_t i = 0; i < plane.size(); i += 97)
            plane[i] = i % 2 ? std::numeric_limits<float>::infinity()
                             : std::numeric_limits<float>::quiet_NaN();
    if (kind == Kind::Spikes)
        for (size_t i = 0; i < plane.size(); ++i)
            plane[i] = i % 37 == 5 ? 3e7f * (1 + unit(rng)) : 1e-3f * unit(rng);
    if (kind == Kind::Cancelling)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                if ((x + y) % 7 == 2 || (x + y) % 7 == 4)
                    plane[size_t(y) * w + x] = (x + y) % 7 == 2 ? 1e18f : -1e18f;
    if (kind == Kind::NearBound || kind == Kind::OverBound) {
        // Small values with every bit of a float's mantissa (units of 2^-23) among large ones
        // (four in five) whose absolute values sum along the longest lines to about 2^28 =
        // 2^51 units (at the bound; shorter lines and bands under it); or, over it, large
        // values in a column's top half only, summing to 2^35 = 2^58 units, above small ones
        // (sums that pass the large values round when slid, and means below show it).
        const int n = std::max(w, h);
        const bool over = kind == Kind::OverBound;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                float scale = over ? std::ldexp(1.f, 35) / float(std::max(1, h / 2))
                                   : std::ldexp(1.f, 28) / (0.8f * float(n));
                float target = scale * (0.999f + 0.002f * unit(rng));
                float small = 1.f + std::ldexp(float(2 * (x + y) + 1), -23);
                const bool large = over ? y < h / 2 : (x + y) % 5 != 0;
                const bool negative = !over && (x + y) % 3 == 0;
                plane[size_t(y) * w + x] = !large ? small : negative ? -target : target;
            }
    }
    if (kind == Kind::Subnormal)
        for (size_t i = 0; i < plane.size(); ++i)
            if (i % 3 == 1) plane[i] = std::numeric_limits<float>::denorm_min() * float(i % 17);
    return plane;
}

TEST(BoxMeanColumns, SameBitsAsWindowsSummedOneByOne) {
    struct Case {
        int w, h, r;
    };
    for (Case c : {Case{1, 1, 1}, Case{1, 1, 5}, Case{3, 7, 2}, Case{5, 9, 3}, Case{33, 41, 4},
                   Case{64, 37, 8}, Case{23, 130, 32}, Case{40, 20, 30}, Case{17, 300, 3},
                   Case{9, 200, 20}, Case{7, 7, 3}, Case{6, 9, 9}, Case{11, 2000, 64}})
        for (Kind kind : {Kind::Plain, Kind::FewWideRange, Kind::ManyWideRange, Kind::NonFinite,
                          Kind::Spikes, Kind::Cancelling, Kind::NearBound, Kind::OverBound,
                          Kind::Subnormal})
            for (int parts : {1, 3}) {
                SCOPED_TRACE(std::to_string(c.w) + "x" + std::to_string(c.h) + " r" +
                             std::to_string(c.r) + " kind " + std::to_string(int(kind)) + ", " +
                             std::to_string(parts) + " part(s)");
                ForceParallelParts force(parts);
                std::vector<float> in = MakePlane(c.w, c.h, kind);
                std::vector<float> expected = WindowsOneByOne(in, c.w, c.h, c.r);
                std::vector<float> got(in.size(), -7.f);
                BoxMeanColumns(in.data(), got.data(), c.w, c.h, c.r);
                EXPECT_EQ(0,
                          std::memcmp(got.data(), expected.data(), got.size() * sizeof(float)));
                // Along the rows of the transposed plane: the same means, transposed.
                std::vector<float> flipped = Transposed(in, c.w, c.h), rows(in.size(), -7.f);
                BoxMeanRows(flipped.data(), rows.data(), c.h, c.w, c.r);
                EXPECT_EQ(0, std::memcmp(rows.data(), Transposed(expected, c.w, c.h).data(),
                                         rows.size() * sizeof(float)));
            }
}

// The wide-range columns are ones where sliding without the test gives other bits: the
// comparison above would catch a slide there.
TEST(BoxMeanColumns, WideRangeColumnsRoundWhenSlid) {
    std::vector<float> in = MakePlane(64, 37, Kind::FewWideRange);
    std::vector<float> expected = WindowsOneByOne(in, 64, 37, 8);
    std::vector<float> slid = NaiveSlide(in, 64, 37, 8);
    EXPECT_NE(0, std::memcmp(slid.data(), expected.data(), slid.size() * sizeof(float)));
    std::vector<float> plain = MakePlane(64, 37, Kind::Plain);
    expected = WindowsOneByOne(plain, 64, 37, 8);
    slid = NaiveSlide(plain, 64, 37, 8);
    EXPECT_EQ(0, std::memcmp(slid.data(), expected.data(), slid.size() * sizeof(float)))
        << "plain values in [0, 1) are exact when slid";
}

// Lines over the bound round when slid, so the comparison above fails for a bound set too
// loose; lines at the bound slide exactly, so either side of the test gives the same bits.
TEST(BoxMeanColumns, LinesOverTheBoundRoundWhenSlid) {
    for (int r : {4, 16}) {
        std::vector<float> over = MakePlane(64, 37, Kind::OverBound);
        std::vector<float> slid = NaiveSlide(over, 64, 37, r);
        std::vector<float> expected = WindowsOneByOne(over, 64, 37, r);
        EXPECT_NE(0, std::memcmp(slid.data(), expected.data(), slid.size() * sizeof(float)))
            << "radius " << r;
        std::vector<float> near = MakePlane(64, 37, Kind::NearBound);
        slid = NaiveSlide(near, 64, 37, r);
        expected = WindowsOneByOne(near, 64, 37, r);
        EXPECT_EQ(0, std::memcmp(slid.data(), expected.data(), slid.size() * sizeof(float)))
            << "radius " << r;
    }
}

// A row whose sums round (large values among small ones) is split into segments, each
// tested on the values its windows read, its halo included: a segment whose halo holds the
// large values must sum in order too (as differences of prefix sums that pass them, the
// windows after them would keep the large values' rounding); the plain segments further
// off may take differences of prefix sums. Every way, the same bits as each window in order.
TEST(BoxMeanRows, SegmentsOfRowsWhoseSumsRound) {
    for (int r : {8, 40}) {
        const int segment = std::max(256, 8 * r), w = 4 * segment + 77, h = 5;
        std::vector<float> in = MakePlane(w, h, Kind::Plain);
        // Large values in the second segment's last columns, within the third's halo.
        for (int y = 0; y < h; ++y)
            for (int x = 2 * segment - r / 2; x < 2 * segment; ++x)
                in[size_t(y) * w + x] = 1e13f * (1.f + float(x % 5));
        // A cancelling pair in the first segment's right halo alone: its test must read it.
        for (int y = 0; y < h; ++y) {
            in[size_t(y) * w + segment + 1] = 1e18f;
            in[size_t(y) * w + segment + r / 2] = -1e18f;
        }
        const std::vector<float> expected =
            Transposed(WindowsOneByOne(Transposed(in, w, h), h, w, r), h, w);
        for (int parts : {1, 3}) {
            SCOPED_TRACE("radius " + std::to_string(r) + ", " + std::to_string(parts) +
                         " part(s)");
            ForceParallelParts force(parts);
            std::vector<float> got(in.size(), -7.f);
            BoxMeanRows(in.data(), got.data(), w, h, r);
            EXPECT_EQ(0, std::memcmp(got.data(), expected.data(), got.size() * sizeof(float)));
        }
    }
}

}  // namespace
}  // namespace mcd
