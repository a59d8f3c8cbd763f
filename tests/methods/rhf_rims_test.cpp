// rhf beside a small light whose edge a wide pixel filter spreads over two pixels: a rim two
// pixels from the light keeps its input only where it holds one of its samples' share of
// that light (host/api/method_rhf.cpp, HoldsALightSample); a dimmer caustic sample there is
// filtered as any other pixel.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "harness/frames.h"
#include "harness/gpu_fixture.h"
#include "harness/inputs.h"
#include "host/api/device.h"
#include "mcdenoise/mcdenoise.h"

namespace mcd::test {
namespace {

class RhfRims : public GpuTest {};

// A 40x40 wall of about 0.013 a channel, 16 samples a pixel, with a 3x3 light of 10 a
// channel (every sample alike) at x 18-20, y 18-20 and, beside its left and right edges,
// columns of pixels half of whose samples saw it (the edge spread over two pixels). Two
// pixels from the light, beyond each column: on the left a pixel one sample of which saw the
// light (10), on the right one whose bright sample is a dimmer caustic (5): one sample's
// share of the light is 10 / 16 a channel, which the left pixel holds and the right one does
// not. Both are rims (over 16x their neighbours' median, no lone spikes beside the
// column); the left keeps its input, the right is filtered (kept, it was its input to the
// bit).
TEST_F(RhfRims, ARimKeepsItsInputOnlyWithOneSamplesShareOfItsLight) {
    const int w = 40, h = 40, spp = 16, left = 16, right = 22;
    std::mt19937_64 rng(SeedFromName("rhf rims share"));
    std::uniform_real_distribution<double> wallSample(0.005, 0.0216);
    auto sample = [&](int x, int y, int s) {
        const bool rows = y >= 18 && y <= 20;
        if (rows && x >= 18 && x <= 20) return 10.0;
        if (rows && (x == 17 || x == 21) && s < spp / 2) return 10.0;
        if (y == 19 && x == left && s == 0) return 10.0;
        if (y == 19 && x == right && s == 0) return 5.0;
        return wallSample(rng);
    };
    const Frame frame = SampledFrame(w, h, sample, spp);
    const Image &color = frame.Get("color");
    Device device = api::BorrowDevice(Ctx());
    Result result = Method("rhf").Run(device, frame);
    const Image &out = result.image;
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(out.At(c, 19, left), color.At(c, 19, left), 0.02 * color.At(c, 19, left));
        EXPECT_LT(out.At(c, 19, right), 0.8 * color.At(c, 19, right));
    }
}

}  // namespace
}  // namespace mcd::test
