// rhf on a frame with a small cluster of one-sample pixels over a flat floor (a light's
// reflection a few samples saw): the cluster's energy stays near it instead of lighting a
// square the size of the search window (host/common/local_mean.h, CutBrightClusters); which
// clusters are cut, against the CPU twin (cpu_reference/local_mean.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

#include "cpu_reference/local_mean.h"
#include "harness/frames.h"
#include "harness/gpu_fixture.h"
#include "harness/inputs.h"
#include "host/api/device.h"
#include "host/common/local_mean.h"
#include "host/io/accumulate.h"
#include "mcdenoise/mcdenoise.h"

namespace mcd::test {
namespace {

class RhfClusters : public GpuTest {};

// A 48x48 floor of about 0.013 a channel, 16 samples a pixel, with a column of 3 pixels at
// (20, 23-25) that one sample of 16 each saw (80 a channel), as glossy_lights' chrome sphere
// reflects a bulb on its floor. rhf used to spread the column over its 13x13 search window,
// lifting the floor there several times over; now the floor 3 to 6 pixels from the column stays
// within 1.5x of its mean, and the column's energy stays within 2 pixels of it.
TEST_F(RhfClusters, AClusterOnAFlatFloorDrawsNoSquare) {
    const int w = 48, h = 48, spp = 16, bins = 20, cx = 20;
    std::mt19937_64 rng(SeedFromName("rhf clusters floor"));
    std::uniform_real_distribution<double> floorSample(0.005, 0.0216);
    Image color(w, h, 3), variance(w, h, 3), hist(w, h, 3 * bins + 1);
    double floorMean = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const bool column = x == cx && y >= 23 && y <= 25;
            double sum[3] = {0, 0, 0}, squares[3] = {0, 0, 0};
            std::vector<float> pixelHist(3 * bins, 0.f);
            for (int s = 0; s < spp; ++s) {
                double sample[3];
                for (double &v : sample) v = column && s == 0 ? 80.0 : floorSample(rng);
                io::AddToRhfHistogram(sample, bins, pixelHist.data());
                for (int c = 0; c < 3; ++c)
                    sum[c] += sample[c], squares[c] += sample[c] * sample[c];
            }
            for (int c = 0; c < 3; ++c) {
                const double mean = sum[c] / spp;
                color.At(c, y, x) = float(mean);
                // The variance of the mean, as the renderer and accumulate write it.
                variance.At(c, y, x) = float((squares[c] / spp - mean * mean) / (spp - 1));
            }
            for (int i = 0; i < 3 * bins; ++i) hist.At(i, y, x) = pixelHist[i];
            hist.At(3 * bins, y, x) = spp;
            if (!column) floorMean += color.At(0, y, x) / (w * h - 3);
        }
    Frame frame(w, h);
    frame.SetLayer("color", color);
    frame.SetLayer("hist", hist);
    frame.SetLayer("variance", variance);
    Device device = api::BorrowDevice(Ctx());
    Result result = Method("rhf").Run(device, frame);
    const Image &out = result.image;
    double ring = 0, near = 0, input = 0;
    int ringCount = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const int d = std::max(std::abs(x - cx), std::abs(y - 24) - 1);
            if (d >= 3 && d <= 6) {
                ring += out.At(0, y, x), ++ringCount;
                EXPECT_LT(out.At(0, y, x), 1.5 * floorMean) << x << ", " << y;
            }
            if (d <= 2) near += out.At(0, y, x) - floorMean;
            if (x == cx && y >= 23 && y <= 25) input += color.At(0, y, x) - floorMean;
        }
    EXPECT_NEAR(ring / ringCount, floorMean, 0.2 * floorMean);
    EXPECT_NEAR(near, input, 0.1 * input);
}

// A light's reflection in chrome: 4 pixels on a dim wall of which 1, 2, 1 and 3 samples of
// 16 saw the light (300 a channel), as glossy_lights' sphere reflects a bulb. No pixel has
// more bright samples than the bright veto's share (0.3 of 16), so the filter used to spread
// the cluster over its search window (a lighter square); now the wall 3 to 6 pixels from it
// stays within 1.5x of its mean and the cluster's energy within 2 pixels of it.
TEST_F(RhfClusters, ALightsReflectionOfSeveralSamplesDrawsNoSquare) {
    const int w = 48, h = 48, cx = 24, cy = 24;
    std::mt19937_64 rng(SeedFromName("rhf clusters reflection"));
    std::uniform_real_distribution<double> wallSample(0.005, 0.0216);
    auto seen = [&](int x, int y) { return ReflectionSamplesAt(x - cx, y - cy); };
    Frame frame = SampledFrame(
        w, h, [&](int x, int y, int s) { return s < seen(x, y) ? 300.0 : wallSample(rng); });
    const Image &color = frame.Get("color");
    double wallMean = 0, input = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) (seen(x, y) ? input : wallMean) += color.At(0, y, x);
    wallMean /= w * h - 4;
    input -= 4 * wallMean;
    Device device = api::BorrowDevice(Ctx());
    Result result = Method("rhf").Run(device, frame);
    const Image &out = result.image;
    double near = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const int d =
                std::max(std::max(cx - 1 - x, x - cx - 1), std::max(cy - y, y - cy - 1));
            if (d >= 3 && d <= 6) {
                EXPECT_LT(out.At(0, y, x), 1.5 * wallMean) << x << ", " << y;
            }
            if (d <= 2) near += out.At(0, y, x) - wallMean;
        }
    EXPECT_NEAR(near, input, 0.1 * input);
}

// A highlight's line on a dim wall: a vertical band of 2 pixels whose samples each saw a
// light (200 a channel) with probability 1/8, so most of its pixels hold 1 to 3 bright
// samples of 16, as the gold ring's inner edge in glossy_lights. A bin of one sample adds no
// term to the distance, so without the pool the wall's patches take the line's pixels in and
// the filter draws a lighter block the width of its search window beside it. The limits:
// a bright sample counts 3 in the pool (one saturated bin per colour), and a wall centre
// (P = 0) keeps a candidate of Q counts iff Q^2 <= B Q, i.e. Q <= B. At bound 2 no box
// holding a line sample passes, so the wall 3 to 6 pixels away keeps its own noise: its
// samples' spread (uniform, sd 0.36 of the mean) over 16 samples stays far below half its
// mean, while one leaked sample of 200 among a window of candidates lifts a pixel by more
// than its mean. At bound 6 only boxes of at most 2 bright samples pass (the line's edge),
// where without the pool every box over the line's 1 to 3 a pixel did: the lift at most 0.6
// of that. The line keeps most of its light (it is averaged with itself).
TEST_F(RhfClusters, AHighlightsLineDrawsNoBlocks) {
    const int w = 48, h = 48, x0 = 23, y0 = 8, y1 = 40;
    std::mt19937_64 rng(SeedFromName("rhf clusters line"));
    std::uniform_real_distribution<double> wallSample(0.005, 0.0216);
    auto onLine = [&](int x, int y) { return (x == x0 || x == x0 + 1) && y >= y0 && y <= y1; };
    Frame frame = SampledFrame(w, h, [&](int x, int y, int) {
        return onLine(x, y) && rng() % 8 == 0 ? 200.0 : wallSample(rng);
    });
    const Image &color = frame.Get("color");
    double wallMean = 0, line = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) (onLine(x, y) ? line : wallMean) += color.At(0, y, x);
    wallMean /= w * h - 2 * (y1 - y0 + 1);
    Device device = api::BorrowDevice(Ctx());
    // The wall's largest lift 3 to 6 pixels from the line, and the line's light.
    auto measure = [&](const Image &out, double *lineOut) {
        double lift = 0;
        *lineOut = 0;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const int d = x < x0 ? x0 - x : x - x0 - 1;
                if (onLine(x, y)) *lineOut += out.At(0, y, x);
                if (y >= y0 + 6 && y <= y1 - 6 && d >= 3 && d <= 6)
                    lift = std::max(lift, out.At(0, y, x) - wallMean);
            }
        return lift;
    };
    Method off("rhf"), on("rhf"), tight("rhf");
    off.Set("bright-pool", 0.f);
    on.Set("bright-pool", 6.f);
    tight.Set("bright-pool", 2.f);
    double lineOn = 0, lineOff = 0, lineTight = 0;
    const double liftOn = measure(on.Run(device, frame).image, &lineOn);
    const double liftOff = measure(off.Run(device, frame).image, &lineOff);
    const double liftTight = measure(tight.Run(device, frame).image, &lineTight);
    EXPECT_GT(liftOff, 2 * wallMean) << "the line no longer lights a block without the pool";
    EXPECT_LT(liftOn, 0.6 * liftOff);
    EXPECT_LT(liftTight, 0.5 * wallMean);
    EXPECT_GT(lineOn, 0.5 * line);
    EXPECT_GT(lineTight, 0.5 * line);
}

// Hand-made histograms of 16 samples a pixel on a wall of 0.0133 a channel: 5 pixels in a
// 3x2 box one sample of 16 each saw (a highlight's reflection), a light's reflection of 4
// pixels with 3 bright samples in one, the same reflection with 5 of 16 in one (over the
// bright veto's share, which keeps it apart) and a row of 5 one-sample pixels (a highlight's
// line, longer than a patch): the first two are cut whole, the others stay; the host and the
// CPU twin cut the same pixels to the same bits.
TEST(RhfClusterCut, CutsReflectionsUnderTheVetosShare) {
    const int w = 48, h = 24;
    HistogramFloor wall(w, h);
    Image &color = wall.color, &hist = wall.hist;
    auto bright = [&](int x, int y, float samples, float value) {
        wall.Bright(x, y, samples, value);
    };
    for (int x = 8; x <= 10; ++x) bright(x, 10, 1, 3.4f);
    bright(8, 11, 1, 3.4f), bright(10, 11, 1, 3.4f);
    for (int x = 8; x <= 12; ++x) bright(x, 18, 1, 3.4f);
    for (int x0 : {25, 38}) {
        bright(x0, 10, 1, 18.75f), bright(x0 + 1, 10, 2, 37.5f), bright(x0 - 1, 11, 1, 18.75f);
        bright(x0, 11, x0 == 25 ? 3 : 5, x0 == 25 ? 56.25f : 93.75f);
    }
    Image got = color, expected = color;
    const std::vector<size_t> cut = CutBrightClusters(color, hist, 6, &got);
    const std::vector<size_t> want{10 * w + 8,  10 * w + 9,  10 * w + 10,
                                   10 * w + 25, 10 * w + 26, 11 * w + 8,
                                   11 * w + 10, 11 * w + 24, 11 * w + 25};
    EXPECT_EQ(cut, want);
    EXPECT_EQ(ref::CutBrightClusters(color, hist, 6, &expected), cut);
    EXPECT_EQ(0, std::memcmp(got.data.data(), expected.data.data(), got.data.size() * 4));
    for (size_t p : want) EXPECT_LT(got.Plane(0)[p], 0.2f) << p;
}

// The ring's caustic on glossy_lights' floor, 5 pixels with one or two bright samples of 16
// (channels summed); `lastSamples` is the bright samples of its lower pixel, 0 to take them
// away while its value stays.
void PlantCaustic(HistogramFloor &wall, float lastSamples) {
    auto bright = [&](int x, int y, float samples, float sum) {
        wall.Bright(x, y, samples, sum / 3);
    };
    bright(12, 10, 1, 2.38f), bright(11, 10, 0, 0.30f);
    bright(10, 11, 1, 7.37f), bright(11, 11, 1, 3.87f), bright(12, 11, 1, 3.10f);
    bright(10, 12, lastSamples, 3.60f);
}

// CutBrightClusters by the host and by the CPU twin on one frame (search half 6).
struct BothCuts {
    std::vector<size_t> cut, bridged, refCut, refBridged;
    Image image, refImage;
};
BothCuts CutBoth(const HistogramFloor &wall) {
    BothCuts b;
    b.image = b.refImage = wall.color;
    b.cut = CutBrightClusters(wall.color, wall.hist, 6, &b.image, &b.bridged);
    b.refCut = ref::CutBrightClusters(wall.color, wall.hist, 6, &b.refImage, &b.refBridged);
    return b;
}

// A caustic of 5 pixels as the ring casts on glossy_lights' floor: one or two bright samples
// of 16 in each, its middle pixel (3.87, channels summed) under 16 times its neighbours'
// median (0.30: a dim neighbour and its four bright ones lift it), so the over pixels form two
// pairs. The middle pixel joins them and the 5 are cut whole, set apart as bridged (their
// energy left to the restore). Two pairs beside a pixel with no
// bright sample, and a pair and a lone firefly with a bright pixel between them, stay; the
// host and the CPU twin cut the same pixels to the same bits.
TEST(RhfClusterCut, JoinsACausticSplitAtItsMiddle) {
    const int w = 48, h = 24;
    HistogramFloor wall(w, h);
    auto bright = [&](int x, int y, float samples, float sum) {
        wall.Bright(x, y, samples, sum / 3);
    };
    PlantCaustic(wall, 2);
    // Two pairs beside a dim pixel without a bright sample.
    bright(26, 10, 1, 10.2f), bright(26, 11, 1, 10.2f), bright(27, 10, 0, 0.6f);
    bright(28, 10, 1, 10.2f), bright(28, 11, 1, 10.2f);
    // A pair and a lone firefly, a bright pixel between them under 16 times its neighbours.
    bright(40, 10, 1, 10.2f), bright(40, 11, 1, 10.2f), bright(41, 11, 1, 0.6f);
    bright(42, 11, 1, 10.2f);
    const BothCuts b = CutBoth(wall);
    EXPECT_TRUE(b.cut.empty());
    const std::vector<size_t> want{10 * w + 12, 11 * w + 10, 11 * w + 11, 11 * w + 12,
                                   12 * w + 10};
    EXPECT_EQ(b.bridged, want);
    EXPECT_TRUE(b.refCut.empty());
    EXPECT_EQ(b.refBridged, b.bridged);
    EXPECT_EQ(
        0, std::memcmp(b.image.data.data(), b.refImage.data.data(), b.image.data.size() * 4));
    for (size_t p : want) EXPECT_LT(b.image.Plane(0)[p], 0.2f) << p;
}

// What a bright pixel does not bridge: the caustic above with one pixel of a pair over 16
// times by value but with no bright sample (the pairs stay apart, neither cut), and a line of
// 11 one-sample pixels beside a reflection of 2x2 two-sample pixels, a bright pixel under 16
// times between them (the line spans more than kClusterSpan: the reflection is cut alone, as
// a cluster given its input back); host and CPU twin alike.
TEST(RhfClusterCut, BridgesNeitherAPairMissingABrightSampleNorALongLine) {
    const int w = 48, h = 24;
    HistogramFloor wall(w, h);
    auto bright = [&](int x, int y, float samples, float sum) {
        wall.Bright(x, y, samples, sum / 3);
    };
    PlantCaustic(wall, 0);
    for (int x = 20; x <= 30; ++x) bright(x, 18, 1, 10.2f);
    bright(31, 18, 1, 0.6f);
    for (int y = 18; y <= 19; ++y) bright(32, y, 2, 10.2f), bright(33, y, 2, 10.2f);
    const BothCuts b = CutBoth(wall);
    const std::vector<size_t> want{18 * w + 32, 18 * w + 33, 19 * w + 32, 19 * w + 33};
    EXPECT_EQ(b.cut, want);
    EXPECT_TRUE(b.bridged.empty());
    EXPECT_EQ(b.refCut, want);
    EXPECT_TRUE(b.refBridged.empty());
    EXPECT_EQ(
        0, std::memcmp(b.image.data.data(), b.refImage.data.data(), b.image.data.size() * 4));
}

}  // namespace
}  // namespace mcd::test
