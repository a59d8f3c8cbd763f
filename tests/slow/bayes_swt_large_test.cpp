// Method bayes with --bayes-transform swt on a frame whose coefficients exceed one binding
// (lavapipe: 128 MiB), so the channels run in groups. Label `slow`: not run in CI.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

#include "harness/bayes_paper.h"
#include "harness/gpu_fixture.h"
#include "harness/inputs.h"
#include "host/methods/bayes.h"
#include "host/wavelet/swt.h"

namespace mcd::test {
namespace {

class BayesSwtLarge : public GpuTest {};

// Above one binding the channels run in groups: 1200 x 1024 x 3 at 3 levels is 30 planes,
// 141 MiB, so groups of 2 and 1 channels. Bands, fits and (fixed or variance) noise are per
// channel, so each channel must come out bit-identical to that channel denoised alone.
TEST_F(BayesSwtLarge, ChannelGroupsAboveOneBinding) {
    const int w = 1200, h = 1024;
    Image color = NoisyPicture(w, h, SeedFromName("swt groups"), 0.3);
    Image variance(w, h, 3);
    for (size_t i = 0; i < color.Size(); ++i)
        variance.data[i] = 0.05f * color.data[i] * color.data[i];
    if (SwtChannelsPerBinding(Ctx(), w, h, 3) >= 3)
        GTEST_SKIP() << "this device binds all three channels' coefficients: no groups";
    for (bool useVariance : {false, true}) {
        SCOPED_TRACE(useVariance ? "--noise variance" : "fixed noise");
        BayesParams options = PaperBayesParams();
        options.transform = BayesTransform::Swt;
        if (useVariance) options.noise = BayesNoise::Variance;
        BayesResult all = BayesDenoise(Ctx(), color, options, {}, &variance);
        for (int c = 0; c < 3; ++c) {
            Image one(w, h, 1), oneVariance(w, h, 1);
            std::copy_n(color.Plane(c), color.PixelCount(), one.Plane(0));
            std::copy_n(variance.Plane(c), variance.PixelCount(), oneVariance.Plane(0));
            BayesResult alone = BayesDenoise(Ctx(), one, options, {}, &oneVariance);
            EXPECT_EQ(std::memcmp(alone.image.Plane(0), all.image.Plane(c),
                                  color.PixelCount() * sizeof(float)),
                      0)
                << "channel " << c;
            for (int b = 0; b < 9; ++b)
                EXPECT_EQ(alone.fits[b].params, all.fits[c * 9 + b].params) << c << " " << b;
        }
    }
}

}  // namespace
}  // namespace mcd::test
