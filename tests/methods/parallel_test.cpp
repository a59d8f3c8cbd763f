// Host loops split over threads (host/common/parallel.h): every index once, and the same
// bits as the serial loop for each function that uses the split, on odd sizes, 1x1 and
// NaN/Inf inputs.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <random>
#include <string>

#include "harness/inputs.h"
#include "host/common/cycle_spin.h"
#include "host/common/highlights.h"
#include "host/common/local_mean.h"
#include "host/common/non_finite.h"
#include "host/common/parallel.h"
#include "host/kernels/pivot_gather.h"
#include "host/methods/run_memo.h"

namespace mcd {
namespace {

using test::SeedFromName;

TEST(ParallelFor, CoversEachIndexOnce) {
    for (int n : {0, 1, 2, 7, 1000})
        for (int parts : {1, 2, 3, 7, 16}) {
            ForceParallelParts force(parts);
            std::vector<int> seen(size_t(n), 0);
            std::mutex lock;
            int calls = 0;
            ParallelFor(n, 0, [&](int begin, int end) {
                for (int i = begin; i < end; ++i) ++seen[size_t(i)];
                std::lock_guard<std::mutex> guard(lock);
                ++calls;
            });
            for (int i = 0; i < n; ++i) EXPECT_EQ(seen[size_t(i)], 1) << n << " " << parts;
            EXPECT_EQ(calls, n == 0 ? 0 : std::min(n, parts)) << n << " " << parts;
        }
    std::vector<int> values(10001, 0);
    ForceParallelParts force(3);
    ParallelValues(values.size(), 1, [&](size_t begin, size_t end) {
        for (size_t i = begin; i < end; ++i) ++values[i];
    });
    for (int v : values) EXPECT_EQ(v, 1);
}

// ParallelCopy against std::memcpy: every byte, at sizes around its 1 MiB blocks and
// odd offsets, whole or split among threads; the bytes beside the region untouched.
TEST(ParallelFor, CopyGivesEveryByte) {
    constexpr size_t kBlock = size_t(1) << 20;
    std::mt19937_64 rng(SeedFromName("parallel copy"));
    std::vector<unsigned char> source(3 * kBlock + 64);
    for (unsigned char &b : source) b = static_cast<unsigned char>(rng());
    for (size_t bytes : {size_t(0), size_t(1), size_t(17), kBlock - 1, kBlock, kBlock + 1,
                         2 * kBlock + 13, 3 * kBlock + 7})
        for (int parts : {0, 1, 2, 3, 7}) {
            SCOPED_TRACE(std::to_string(bytes) + " bytes, " + std::to_string(parts) + " parts");
            ForceParallelParts force(parts);
            std::vector<unsigned char> got(source.size() + 16, 0xa5), expected = got;
            ParallelCopy(got.data() + 5, source.data() + 3, bytes);
            std::memcpy(expected.data() + 5, source.data() + 3, bytes);
            EXPECT_TRUE(got == expected);
        }
}

// Random values with zeros, negatives, fireflies, bright blocks, NaN and Inf (unless
// `finite`).
Image RandomImage(int w, int h, int channels, const std::string &name, bool finite) {
    std::mt19937_64 rng(SeedFromName(name + " " + std::to_string(w) + "x" + std::to_string(h)));
    std::uniform_real_distribution<float> unit(0, 1);
    Image image(w, h, channels);
    for (float &v : image.data) {
        float u = unit(rng);
        v = u < 0.05f              ? 0.f
            : u < 0.08f            ? -unit(rng)
            : u < 0.09f && !finite ? std::numeric_limits<float>::quiet_NaN()
            : u < 0.10f && !finite ? std::numeric_limits<float>::infinity()
            : u > 0.97f            ? 300 * unit(rng)
                                   : unit(rng);
    }
    for (int c = 0; c < channels; ++c)
        for (int y = h / 3; y < std::min(h, h / 3 + 3); ++y)
            for (int x = w / 4; x < std::min(w, w / 4 + 4); ++x)
                image.At(c, y, x) = 100 + 300 * unit(rng);
    return image;
}

bool SameBits(const Image &a, const Image &b) {
    return a.SameShape(b) &&
           std::memcmp(a.data.data(), b.data.data(), a.data.size() * sizeof(float)) == 0;
}

struct Results {
    Image padded, spun, tileOrder, tent, restored, restoredWithVariance, restoredLeft, bounded,
        base, baseVariance;
    LocalMeanFactors factors, factorsWithVariance, factorsLeft;
    std::vector<bool> left;
    size_t moved = 0, highlights = 0;
    int reach = 0;
    std::vector<char> highlight;
};

// Each threaded function on one frame, under a split into `parts`.
Results RunAll(int w, int h, bool finite, int parts) {
    ForceParallelParts force(parts);
    Image input = RandomImage(w, h, 3, "parallel input", finite);
    Image output = RandomImage(w, h, 3, "parallel output", true);
    Image variance = RandomImage(w, h, 3, "parallel variance", finite);
    for (float &v : output.data) v = std::fabs(v);
    Results r;
    r.padded = MirrorPad(input, 3, 2);
    r.spun = CycleSpin(w, h, 3, 3, [&](int dx, int dy) { return MirrorPad(input, dx, dy); });
    Image radii = RandomImage(w, h, 3, "parallel radii", true);
    for (float &v : radii.data) v = v < 0 ? -1.f : std::min(30.f, std::floor(v));
    r.tileOrder = PivotTileOrder(radii, &r.reach);
    r.tent = TentMean(input, 2);
    r.restored = output;
    r.factors = RestoreLocalMeans(input, 2, &r.restored);
    r.restoredWithVariance = output;
    r.factorsWithVariance = RestoreLocalMeans(input, 2, &r.restoredWithVariance, &variance);
    // The method's own kept values, and on return those with the highlights.
    r.left.assign(output.data.size(), false);
    for (size_t i = 0; i < r.left.size(); i += 7) r.left[i] = true;
    r.restoredLeft = output;
    r.factorsLeft = RestoreLocalMeans(input, 2, &r.restoredLeft, &variance, 0.5, true, &r.left);
    r.bounded = output;
    r.moved = BoundToNoise(input, variance, 2, &r.bounded);
    Image color = RandomImage(w, h, 3, "parallel color", true);
    Image colorVariance = RandomImage(w, h, 3, "parallel color variance", true);
    for (float &v : color.data) v = std::fabs(v);
    for (float &v : colorVariance.data) v = std::fabs(v) * 1e-3f;
    HighlightSplit split = SplitHighlights(color, &colorVariance, 16, 2);
    r.base = split.base;
    r.baseVariance = split.baseVariance;
    r.highlights = split.count;
    r.highlight = split.highlight;
    return r;
}

TEST(ParallelFor, SameBitsAsTheSerialLoop) {
    struct Case {
        int w, h;
        bool finite;
    };
    for (Case c :
         {Case{1, 1, false}, Case{1, 1, true}, Case{3, 1, false}, Case{1, 5, true},
          Case{37, 23, false}, Case{37, 23, true}, Case{64, 9, false}, Case{9, 70, true},
          // Values over several blocks of ParallelValues (4096) and 64-value groups.
          Case{131, 67, false}, Case{131, 67, true}}) {
        SCOPED_TRACE(std::to_string(c.w) + "x" + std::to_string(c.h) +
                     (c.finite ? "" : " with NaN/Inf"));
        Results serial = RunAll(c.w, c.h, c.finite, 1);
        for (int parts : {2, 3, 7}) {
            SCOPED_TRACE(std::to_string(parts) + " parts");
            Results split = RunAll(c.w, c.h, c.finite, parts);
            EXPECT_TRUE(SameBits(serial.padded, split.padded));
            EXPECT_TRUE(SameBits(serial.spun, split.spun));
            EXPECT_TRUE(SameBits(serial.tileOrder, split.tileOrder));
            EXPECT_EQ(serial.reach, split.reach);
            EXPECT_TRUE(SameBits(serial.tent, split.tent));
            EXPECT_TRUE(SameBits(serial.restored, split.restored));
            EXPECT_TRUE(SameBits(serial.restoredWithVariance, split.restoredWithVariance));
            EXPECT_TRUE(SameBits(serial.restoredLeft, split.restoredLeft));
            EXPECT_EQ(serial.left, split.left);
            EXPECT_EQ(serial.factorsLeft.lo, split.factorsLeft.lo);
            EXPECT_EQ(serial.factorsLeft.hi, split.factorsLeft.hi);
            EXPECT_TRUE(SameBits(serial.bounded, split.bounded));
            EXPECT_TRUE(SameBits(serial.base, split.base));
            EXPECT_TRUE(SameBits(serial.baseVariance, split.baseVariance));
            EXPECT_EQ(serial.factors.lo, split.factors.lo);
            EXPECT_EQ(serial.factors.hi, split.factors.hi);
            EXPECT_EQ(serial.factorsWithVariance.lo, split.factorsWithVariance.lo);
            EXPECT_EQ(serial.factorsWithVariance.hi, split.factorsWithVariance.hi);
            EXPECT_EQ(serial.moved, split.moved);
            EXPECT_EQ(serial.highlights, split.highlights);
            EXPECT_EQ(serial.highlight, split.highlight);
        }
    }
}

// The split finds what it is meant to: otherwise the comparison above proves little.
TEST(ParallelFor, TheFramesExerciseEachPath) {
    Results r = RunAll(37, 23, true, 3);
    EXPECT_GT(r.moved, 0u);
    EXPECT_GT(r.reach, 0);
    EXPECT_GT(r.highlights, 0u);
    EXPECT_TRUE(r.factors.lo != 1 || r.factors.hi != 1);
}

// The count of NaN/Inf values and the first in raster order (pixel, then channel) are the
// same for every split, the first lying in a later block's plane than another one.
TEST(ParallelFor, CountNonFiniteIsTheSameForEverySplit) {
    Image image(131, 67, 3, 1.f);  // 26331 values: 7 blocks of ParallelValues
    for (int parts : {1, 2, 3, 7}) {
        ForceParallelParts force(parts);
        EXPECT_EQ(CountNonFinite(image).count, 0u) << parts << " parts";
    }
    image.At(0, 60, 100) = std::numeric_limits<float>::quiet_NaN();
    image.At(2, 10, 5) = std::numeric_limits<float>::infinity();
    image.At(1, 10, 5) = -std::numeric_limits<float>::infinity();
    image.At(2, 66, 130) = std::numeric_limits<float>::quiet_NaN();
    for (int parts : {1, 2, 3, 7}) {
        ForceParallelParts force(parts);
        const NonFiniteCount bad = CountNonFinite(image);
        EXPECT_EQ(bad.count, 4u) << parts << " parts";
        EXPECT_EQ(bad.x, 5) << parts << " parts";
        EXPECT_EQ(bad.y, 10) << parts << " parts";
        EXPECT_EQ(bad.channel, 1) << parts << " parts";
    }
    const NonFiniteCount one =
        CountNonFinite(Image(1, 1, 1, -std::numeric_limits<float>::infinity()));
    EXPECT_EQ(one.count, 1u);
    EXPECT_EQ(one.x + one.y + one.channel, 0);
    EXPECT_EQ(CountNonFinite(Image()).count, 0u);
}

// An image's memo key is the same however its blocks are split among threads, and moves
// when one word changes in any lane of any block or when two blocks trade places.
TEST(ParallelFor, MemoImageIdIsTheSameForEverySplit) {
    const size_t block = size_t(1) << 16;
    Image image(257, 1021, 1);  // 4 blocks and a partial one
    std::mt19937_64 rng(SeedFromName("memo image id"));
    std::uniform_real_distribution<float> unit(0.f, 1.f);
    for (float &v : image.data) v = unit(rng);
    ASSERT_GT(image.data.size(), 3 * block);
    std::string serial;
    {
        ForceParallelParts force(1);
        serial = MemoImageId(image);
    }
    for (int parts : {2, 3, 7}) {
        ForceParallelParts force(parts);
        EXPECT_EQ(MemoImageId(image), serial) << parts << " parts";
    }
    for (size_t i : {size_t(0), size_t(1), size_t(2), size_t(3), block + 5, 4 * block + 9}) {
        Image changed = image;
        changed.data[i] = std::nextafter(changed.data[i], 2.f);
        EXPECT_NE(MemoImageId(changed), serial) << "word " << i;
    }
    Image swapped = image;
    std::swap_ranges(swapped.data.begin(), swapped.data.begin() + block,
                     swapped.data.begin() + block);
    EXPECT_NE(MemoImageId(swapped), serial) << "the first two blocks swapped";
}

}  // namespace
}  // namespace mcd
