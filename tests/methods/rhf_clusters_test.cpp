// rhf on a frame with a small cluster of one-sample pixels over a flat floor (a light's
// reflection a few samples saw): the cluster's energy stays near it instead of lighting a
// square the size of the search window (host/common/local_mean.h, CutBrightClusters).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "harness/gpu_fixture.h"
#include "harness/inputs.h"
#include "host/api/device.h"
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

}  // namespace
}  // namespace mcd::test
