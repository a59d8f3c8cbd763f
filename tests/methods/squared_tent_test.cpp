// Squared tent means (host/common/squared_tent.h) against each window summed on its own: the
// same bits as the exact sum where the window allows it and as the sum in double from its
// first value where not, on random, wide-range, subnormal and non-finite planes, edge sizes
// and radii wider than the plane; a crop gives the whole plane's values; and the means are
// within rounding of the direct sums with the tent's weights in double.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "harness/inputs.h"
#include "host/common/parallel.h"
#include "host/common/squared_tent.h"

namespace mcd {
namespace {

using test::SeedFromName;
using test::Transposed;

// The definition along each row: the window's weighted sum, exact where SquaredTentExact
// allows (an integer in units of the last place of its smallest non-zero magnitude, from
// ldexp and a cast, not from the values' bits), else in double from its first value; over
// the clipped weights' sum.
std::vector<float> RowsByDefinition(const std::vector<float> &in, int w, int h, int s) {
    const int n = 2 * s + 1, reach = 2 * s;
    auto weight = [n](int d) { return double(n - std::abs(d)) * double(n - std::abs(d)); };
    std::vector<float> out(in.size());
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const float *row = in.data() + size_t(y) * w;
            const int a = std::max(0, x - reach), b = std::min(w - 1, x + reach);
            double total = 0, value = 0;
            for (int j = a; j <= b; ++j) total += weight(j - x);
            if (SquaredTentExact(row + a, b - a + 1, s)) {
                float smallest = std::numeric_limits<float>::infinity();
                for (int j = a; j <= b; ++j)
                    if (row[j] != 0) smallest = std::min(smallest, std::fabs(row[j]));
                int e = 0;
                std::frexp(smallest, &e);
                const int q = std::isfinite(smallest) ? std::max(e - 24, -149) : 0;
                __int128 sum = 0;
                for (int j = a; j <= b; ++j)
                    sum += __int128(weight(j - x)) * __int128(std::ldexp(double(row[j]), -q));
                value = std::ldexp(double(sum), q);
            } else {
                for (int j = a; j <= b; ++j) value += weight(j - x) * double(row[j]);
            }
            out[size_t(y) * w + x] = float(value / total);
        }
    return out;
}

// The previous definition: the tent's squared weights in double, each window summed from
// its first value.
std::vector<float> RowsInDouble(const std::vector<float> &in, int w, int h, int s) {
    const int n = 2 * s + 1, reach = 2 * s;
    std::vector<float> out(in.size());
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            double sum = 0, total = 0;
            for (int j = std::max(0, x - reach); j <= std::min(w - 1, x + reach); ++j) {
                const double t = double(n - std::abs(j - x)) / (double(n) * n);
                sum += t * t * in[size_t(y) * w + j];
                total += t * t;
            }
            out[size_t(y) * w + x] = float(sum / total);
        }
    return out;
}

enum class Kind { Plain, Squares, Signed, WideRange, Subnormal, NonFinite, Constant };

// Seeded planes: uniform with zeros; squares of log-normal values with fireflies (the
// restore's squared differences); signed; a few values 2^100 apart (windows summed in
// double); subnormals beside small values; NaN, Inf and -Inf; one constant.
std::vector<float> MakePlane(Kind kind, int w, int h, const std::string &name) {
    std::mt19937_64 rng(SeedFromName(name));
    std::uniform_real_distribution<float> unit(0, 1);
    std::normal_distribution<float> gauss(0, 2);
    std::vector<float> plane(size_t(w) * h);
    for (float &v : plane) {
        const float u = unit(rng);
        switch (kind) {
            case Kind::Plain:
                v = u < 0.1f ? 0.f : unit(rng);
                break;
            case Kind::Squares: {
                float e = std::exp(gauss(rng)) * (u > 0.99f ? 1000.f : 1.f);
                v = u < 0.05f ? 0.f : e * e;
                break;
            }
            case Kind::Signed:
                v = u < 0.05f ? -0.f : 100 * (unit(rng) - 0.5f);
                break;
            case Kind::WideRange:
                v = u < 0.01f ? 1e30f : u < 0.02f ? 1e-30f : unit(rng);
                break;
            case Kind::Subnormal:
                v = u < 0.3f ? 1e-40f * unit(rng) : u < 0.6f ? 0.f : 1e-30f * unit(rng);
                break;
            case Kind::NonFinite:
                v = u < 0.01f   ? std::numeric_limits<float>::quiet_NaN()
                    : u < 0.02f ? std::numeric_limits<float>::infinity()
                    : u < 0.03f ? -std::numeric_limits<float>::infinity()
                                : unit(rng);
                break;
            case Kind::Constant:
                v = 0.3f;
                break;
        }
    }
    return plane;
}

void ExpectSameBits(const std::vector<float> &got, const std::vector<float> &expected,
                    const std::string &what) {
    ASSERT_EQ(got.size(), expected.size()) << what;
    for (size_t i = 0; i < got.size(); ++i) {
        uint32_t a, b;
        std::memcpy(&a, &got[i], 4);
        std::memcpy(&b, &expected[i], 4);
        ASSERT_EQ(a, b) << what << " at " << i << ": " << got[i] << " against " << expected[i];
    }
}

struct Size {
    int w, h, s;
};

const Size kSizes[] = {{1, 1, 1},  {1, 9, 2},   {7, 5, 1},     {5, 3, 4},
                       {37, 3, 2}, {61, 23, 8}, {301, 67, 16}, {517, 9, 64}};
const Kind kKinds[] = {Kind::Plain,     Kind::Squares,   Kind::Signed,  Kind::WideRange,
                       Kind::Subnormal, Kind::NonFinite, Kind::Constant};

TEST(SquaredTent, SameBitsAsEachWindowByDefinition) {
    for (Size z : kSizes)
        for (Kind kind : kKinds) {
            const std::string what = std::to_string(z.w) + "x" + std::to_string(z.h) + " s" +
                                     std::to_string(z.s) + " kind " + std::to_string(int(kind));
            std::vector<float> in = MakePlane(kind, z.w, z.h, what), rows(in.size()),
                               columns(in.size());
            SquaredTentMeanRows(in.data(), rows.data(), z.w, z.h, z.s);
            ExpectSameBits(rows, RowsByDefinition(in, z.w, z.h, z.s), "rows " + what);
            SquaredTentMeanColumns(in.data(), columns.data(), z.w, z.h, z.s);
            ExpectSameBits(Transposed(columns, z.w, z.h),
                           RowsByDefinition(Transposed(in, z.w, z.h), z.h, z.w, z.s),
                           "columns " + what);
        }
}

// Non-finite values give what the sum in double gives: NaN where it does, and Inf of its
// sign; a constant gives itself; a plane of one column gives its values.
TEST(SquaredTent, NonFiniteConstantAndOneValueWindows) {
    const int w = 41, h = 5, s = 3;
    std::vector<float> in = MakePlane(Kind::NonFinite, w, h, "non-finite"), out(in.size());
    SquaredTentMeanRows(in.data(), out.data(), w, h, s);
    std::vector<float> direct = RowsInDouble(in, w, h, s);
    for (size_t i = 0; i < out.size(); ++i) {
        EXPECT_EQ(std::isnan(out[i]), std::isnan(direct[i])) << i;
        if (std::isinf(direct[i])) {
            EXPECT_EQ(out[i], direct[i]) << i;
        }
    }
    std::vector<float> constant = MakePlane(Kind::Constant, w, h, "constant");
    SquaredTentMeanColumns(constant.data(), out.data(), w, h, 20);
    for (float v : out) ASSERT_EQ(v, 0.3f);
    std::vector<float> column = MakePlane(Kind::Squares, 1, 17, "column"), one(17);
    SquaredTentMeanRows(column.data(), one.data(), 1, 17, 50);
    ExpectSameBits(one, column, "one value a window");
}

// The exact sums are within rounding of the previous sums in double with the tent's
// weights, and the plain and squared planes take the exact path.
TEST(SquaredTent, WithinRoundingOfTheTentWeightsInDouble) {
    for (Kind kind : {Kind::Plain, Kind::Squares}) {
        const int w = 301, h = 7, s = 16;
        std::vector<float> in = MakePlane(kind, w, h, "rounding"), out(in.size());
        for (int y = 0; y < h; ++y)
            EXPECT_TRUE(SquaredTentExact(in.data() + size_t(y) * w, w, s)) << y;
        SquaredTentMeanRows(in.data(), out.data(), w, h, s);
        std::vector<float> direct = RowsInDouble(in, w, h, s);
        for (size_t i = 0; i < out.size(); ++i)
            ASSERT_NEAR(out[i], direct[i], 2e-7 * std::fabs(direct[i])) << i;
    }
}

// A crop (a tile and its halo) gives the whole plane's values wherever its window lies in
// the crop, also where some windows are summed in double and where the lines split among
// threads.
TEST(SquaredTent, ACropGivesTheWholePlanesValues) {
    const int w = 203, h = 151, s = 5, reach = 2 * s;
    for (Kind kind : {Kind::Squares, Kind::WideRange, Kind::NonFinite})
        for (int parts : {1, 3}) {
            ForceParallelParts force(parts);
            std::vector<float> in = MakePlane(kind, w, h, "crop"), whole(in.size());
            SquaredTentMeanRows(in.data(), whole.data(), w, h, s);
            std::vector<float> wholeColumns(in.size());
            SquaredTentMeanColumns(whole.data(), wholeColumns.data(), w, h, s);
            const int x0 = 37, y0 = 29, cw = 101, ch = 77;
            std::vector<float> crop(size_t(cw) * ch), rows(crop.size()), both(crop.size());
            for (int y = 0; y < ch; ++y)
                for (int x = 0; x < cw; ++x)
                    crop[size_t(y) * cw + x] = in[size_t(y + y0) * w + x + x0];
            SquaredTentMeanRows(crop.data(), rows.data(), cw, ch, s);
            SquaredTentMeanColumns(rows.data(), both.data(), cw, ch, s);
            for (int y = 2 * reach; y < ch - 2 * reach; ++y)
                for (int x = 2 * reach; x < cw - 2 * reach; ++x) {
                    float a = both[size_t(y) * cw + x],
                          b = wholeColumns[size_t(y + y0) * w + x + x0];
                    ASSERT_EQ(0, std::memcmp(&a, &b, 4))
                        << int(kind) << " parts " << parts << " at " << x << "," << y << ": "
                        << a << " against " << b;
                }
        }
}

}  // namespace
}  // namespace mcd
