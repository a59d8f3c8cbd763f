// The tinted fits' mend (host/common/pivot_chroma.h) against its CPU reference on random
// frames, and its behaviour on made frames: a fit with one channel fallen is given its
// window's chroma at its own brightness; a fit the window cannot vouch for stays.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <utility>

#include "cpu_reference/pivot_chroma.h"
#include "harness/compare.h"
#include "harness/inputs.h"
#include "host/common/pivot_chroma.h"
#include "host/error.h"

namespace mcd::test {
namespace {

// One random frame of MatchesReference.
void MatchOnce(int n, int w, int h, int pivotChannels, int varianceChannels, bool ids) {
    const std::string name = fmt::format("pivot chroma {} {}x{} {} {} {}", n, w, h,
                                         pivotChannels, varianceChannels, ids);
    SCOPED_TRACE(name);
    std::mt19937_64 rng(SeedFromName(name));
    std::uniform_real_distribution<float> unit(0, 1);
    Image color(w, h, n), output(w, h, n), pivot(w, h, pivotChannels),
        variance(w, h, varianceChannels), objectId(w, h, 1), partId(w, h, 1);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            for (int c = 0; c < pivotChannels; ++c)
                pivot.At(c, y, x) = unit(rng) < 0.05f ? 0 : 0.2f + unit(rng);
            const float u = unit(rng), kind = unit(rng);
            for (int c = 0; c < n; ++c) {
                const float p = pivot.At(pivotChannels == 1 ? 0 : c, y, x);
                const float truth = p * (0.5f + 0.1f * float(c));
                color.At(c, y, x) = truth * (0.6f + 0.8f * unit(rng));
                output.At(c, y, x) = u < 0.15f            ? color.At(c, y, x)
                                     : u < 0.5f && c == 0 ? 0.1f * truth
                                                          : truth;
                // A negative input or fit; an input, or a fit, of channels summing to 0.
                if (kind < 0.03f && c == 1) color.At(c, y, x) = -0.05f;
                if (kind > 0.97f && c == 1) output.At(c, y, x) = -0.05f;
                if (kind > 0.02f && kind < 0.04f) color.At(c, y, x) = 0;
                if (kind > 0.04f && kind < 0.06f) output.At(c, y, x) = 0;
            }
            for (int c = 0; c < varianceChannels; ++c)
                variance.At(c, y, x) = kind > 0.9f ? 0 : 0.02f * unit(rng);
            objectId.At(0, y, x) = float((x / 4 + y / 3) % 2);
            partId.At(0, y, x) = float(x > 2 * y);
        }
    if (w * h > 6) pivot.data[7] = std::numeric_limits<float>::quiet_NaN();
    if (w * h > 60) variance.data[50] = -1;
    if (w * h > 100) {
        color.data[90] = std::numeric_limits<float>::infinity();
        output.data[120] = std::numeric_limits<float>::quiet_NaN();
    }
    // Held to 3 standard deviations (as the bound) with per-channel variances.
    const double bound = varianceChannels == n ? 3 : 0;
    const Image *object = ids ? &objectId : nullptr;
    const Image *part = ids ? &partId : nullptr;
    Image expected = output, got = output, again = output;
    size_t want = ref::KeepWindowChroma(color, pivot, variance, object, part, bound, &expected);
    size_t moved = KeepWindowChroma(color, pivot, variance, object, part, bound, &got);
    EXPECT_EQ(moved, want);
    EXPECT_TRUE(BitIdentical(got, expected));
    EXPECT_EQ(KeepWindowChroma(color, pivot, variance, object, part, bound, &again), moved);
    EXPECT_TRUE(BitIdentical(again, got)) << "two runs differ";
    if (w >= 17) {
        EXPECT_GT(want, 0u) << "the case moves nothing";
    }
}

// Random frames against the CPU reference (bit for bit), of 2, 3 and 4 colour channels, with
// pivots and variances of 1 or the colour's channels (three-channel variances held to 3
// standard deviations), ids or none, outputs of which some are kept at their input and some
// have a channel fallen to a tenth, variances of 0, negative values, pixels whose channels
// sum to 0, pivots of 0, NaN, Inf and a negative variance; two runs bit-identical.
TEST(PivotChroma, MatchesReference) {
    for (int n : {2, 3, 4})
        for (auto [w, h] : {std::pair{1, 1}, {3, 2}, {17, 13}, {40, 31}})
            for (int pivotChannels : {1, n})
                for (int varianceChannels : {1, n})
                    for (bool ids : {false, true})
                        MatchOnce(n, w, h, pivotChannels, varianceChannels, ids);
}

// A flat lit wall (pivot 0.8, 0.6, 0.4; z 0.5 in every channel), its input the wall's
// colour and its variance layer v: the window's expected colour is the wall's, exactly.
struct Wall {
    Wall(int w, int h, float v) : color(w, h, 3), pivot(w, h, 3), variance(w, h, 3, v) {
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                for (int c = 0; c < 3; ++c) {
                    pivot.At(c, y, x) = 0.8f - 0.2f * float(c);
                    color.At(c, y, x) = 0.5f * pivot.At(c, y, x);
                }
        // Fitted right, and not kept at the input.
        output = color;
        for (float &v : output.data) v *= 1.001f;
    }
    Image color, pivot, variance, output;
};

// A fit whose red channel fell to a tenth on the wall takes the wall's chroma at its own
// sum; its neighbours, fitted right, and a pixel kept at its input stay.
TEST(PivotChroma, MendsAFallenChannelAtItsBrightness) {
    Wall wall(9, 9, 1e-4f);
    Image out = wall.output;
    out.At(0, 4, 4) *= 0.1f;
    const float sum = out.At(0, 4, 4) + out.At(1, 4, 4) + out.At(2, 4, 4);
    out.At(1, 2, 2) = wall.color.At(1, 2, 2) * 0.1f;                       // moved below
    for (int c = 0; c < 3; ++c) out.At(c, 6, 6) = wall.color.At(c, 6, 6);  // kept
    Image before = out;
    EXPECT_EQ(
        KeepWindowChroma(wall.color, wall.pivot, wall.variance, nullptr, nullptr, 0, &out), 2u);
    const float mended = out.At(0, 4, 4) + out.At(1, 4, 4) + out.At(2, 4, 4);
    EXPECT_NEAR(mended, sum, 1e-6f * sum);
    for (int c = 0; c < 3; ++c) {
        // The wall's chroma: 0.8, 0.6, 0.4 over 1.8.
        EXPECT_NEAR(out.At(c, 4, 4) / mended, (0.8f - 0.2f * float(c)) / 1.8f, 1e-6f) << c;
        EXPECT_EQ(out.At(c, 6, 6), before.At(c, 6, 6));
        EXPECT_EQ(out.At(c, 3, 4), before.At(c, 3, 4));
    }
    EXPECT_NE(out.At(1, 2, 2), before.At(1, 2, 2));
    // Held to 3 standard deviations of its input (0.01 here), the mend moves neither.
    out = before;
    EXPECT_EQ(
        KeepWindowChroma(wall.color, wall.pivot, wall.variance, nullptr, nullptr, 3, &out), 0u);
    EXPECT_TRUE(BitIdentical(out, before));
}

// The fit stands where the window cannot vouch for the pixel: its input's chroma differs
// (a red spot the pivot does not show), or its brightness (a highlight, its fit tinted), or
// the window's own noise allows the fit's chroma; and where the pivot's channels change, the
// window's expected colour follows them (a pivot edge is not a tint). Each on a wall of its
// own: the wall's pixels whose windows hold a spot or a highlight may move by its share.
TEST(PivotChroma, LeavesFitsTheWindowCannotVouchFor) {
    auto moved = [](Wall &wall, Image &out) {
        const Image before = out;
        KeepWindowChroma(wall.color, wall.pivot, wall.variance, nullptr, nullptr, 0, &out);
        bool changed = false;
        for (int c = 0; c < 3; ++c) changed |= out.At(c, 4, 4) != before.At(c, 4, 4);
        return changed;
    };
    Wall spot(9, 9, 1e-4f);
    Image out = spot.output;
    spot.color.At(0, 4, 4) *= 3, spot.color.At(1, 4, 4) *= 0.2f, spot.color.At(2, 4, 4) *= 0.2f;
    out.At(0, 4, 4) *= 3, out.At(1, 4, 4) *= 0.2f, out.At(2, 4, 4) *= 0.2f;
    EXPECT_FALSE(moved(spot, out)) << "a red spot";

    Wall highlight(9, 9, 1e-4f);
    out = highlight.output;
    for (int c = 0; c < 3; ++c) highlight.color.At(c, 4, 4) *= 5;
    out.At(0, 4, 4) *= 2;
    EXPECT_FALSE(moved(highlight, out)) << "a highlight";

    // The columns from x = 4 on blue in the pivot, the input and the fit.
    Wall edge(9, 9, 1e-4f);
    for (int y = 0; y < 9; ++y)
        for (int x = 4; x < 9; ++x) {
            edge.pivot.At(0, y, x) = 0.1f, edge.pivot.At(2, y, x) = 1.f;
            for (int c = 0; c < 3; ++c) edge.color.At(c, y, x) = 0.5f * edge.pivot.At(c, y, x);
        }
    out = edge.color;
    for (float &v : out.data) v *= 1.001f;
    const Image before = out;
    EXPECT_EQ(
        KeepWindowChroma(edge.color, edge.pivot, edge.variance, nullptr, nullptr, 0, &out), 0u);
    EXPECT_TRUE(BitIdentical(out, before)) << "a pivot edge";

    Wall noisy(9, 9, 0.2f);
    out = noisy.output;
    out.At(0, 4, 4) *= 0.5f;
    EXPECT_FALSE(moved(noisy, out)) << "a noisy wall";
    // Without the noise, the same fit is mended.
    Wall clean(9, 9, 1e-4f);
    out = clean.output;
    out.At(0, 4, 4) *= 0.5f;
    EXPECT_TRUE(moved(clean, out)) << "a clean wall";
}

// Shapes it refuses (an internal error): 5 colour channels, a pivot or variance of 2 channels
// for 3, ids of 2 channels, an output of another size; one channel is left as it is.
TEST(PivotChroma, RefusesShapesAndLeavesOneChannel) {
    Wall wall(6, 5, 1e-4f);
    Image five(6, 5, 5), out5(6, 5, 5), out = wall.output, two(6, 5, 2), small(5, 5, 3);
    EXPECT_THROW(KeepWindowChroma(five, wall.pivot, wall.variance, nullptr, nullptr, 0, &out5),
                 Error);
    EXPECT_THROW(KeepWindowChroma(wall.color, two, wall.variance, nullptr, nullptr, 0, &out),
                 Error);
    EXPECT_THROW(KeepWindowChroma(wall.color, wall.pivot, two, nullptr, nullptr, 0, &out),
                 Error);
    EXPECT_THROW(
        KeepWindowChroma(wall.color, wall.pivot, wall.variance, &two, nullptr, 0, &out), Error);
    EXPECT_THROW(
        KeepWindowChroma(wall.color, wall.pivot, wall.variance, nullptr, nullptr, 0, &small),
        Error);
    Image one(6, 5, 1, 0.5f), oneOut(6, 5, 1, 0.1f), onePivot(6, 5, 1, 1.f);
    EXPECT_EQ(KeepWindowChroma(one, onePivot, onePivot, nullptr, nullptr, 0, &oneOut), 0u);
    for (float v : oneOut.data) EXPECT_EQ(v, 0.1f);
}

// A wall of variance 0: the fit's allowance is 0, so any tint is mended where the input's
// chroma is the window's exactly (a fallen red channel; the wall's other pixels, off it by
// rounding, may take it too), and none where it differs at all (a red spot); the sum's test
// is not read.
TEST(PivotChroma, ZeroVarianceMendsOnlyWhereTheInputIsTheWindows) {
    Wall wall(9, 9, 0);
    Image out = wall.output;
    out.At(0, 4, 4) *= 0.9f;
    EXPECT_GT(
        KeepWindowChroma(wall.color, wall.pivot, wall.variance, nullptr, nullptr, 0, &out), 0u);
    const float sum = out.At(0, 4, 4) + out.At(1, 4, 4) + out.At(2, 4, 4);
    EXPECT_NEAR(out.At(0, 4, 4) / sum, 0.8f / 1.8f, 1e-6f);
    Wall spot(9, 9, 0);
    spot.color.At(0, 4, 4) *= 1.01f;
    out = spot.output;
    out.At(0, 4, 4) *= 0.9f;
    const Image before = out;
    KeepWindowChroma(spot.color, spot.pivot, spot.variance, nullptr, nullptr, 0, &out);
    for (int c = 0; c < 3; ++c) EXPECT_EQ(out.At(c, 4, 4), before.At(c, 4, 4)) << c;
}

// The mend blends in: as a fit's red channel falls step by step through the thresholds, its
// output moves by no more than a few steps at a time (a switch jumped by the whole mend, some
// 30 steps, where the fit crossed 1.5 allowances); unmoved at the start, its full mend well
// past 2 allowances.
TEST(PivotChroma, BlendsInWithoutAJump) {
    Wall wall(9, 9, 1e-4f);
    const float step = 0.0005f * wall.output.At(0, 4, 4);
    double last = 0, largest = 0;
    Image out;
    for (int i = 0; i <= 200; ++i) {
        out = wall.output;
        out.At(0, 4, 4) -= float(i) * step;
        const float fit = out.At(0, 4, 4);
        KeepWindowChroma(wall.color, wall.pivot, wall.variance, nullptr, nullptr, 0, &out);
        const double moved = out.At(0, 4, 4) - fit;
        if (i == 0) {
            EXPECT_EQ(moved, 0);
        }
        if (i > 0) largest = std::max(largest, std::fabs(moved - last));
        last = moved;
    }
    EXPECT_LT(largest, 4 * step);
    const float sum = out.At(0, 4, 4) + out.At(1, 4, 4) + out.At(2, 4, 4);
    EXPECT_NEAR(out.At(0, 4, 4) / sum, 0.8f / 1.8f, 1e-6f);
}

}  // namespace
}  // namespace mcd::test
