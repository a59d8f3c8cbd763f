// Method auto's glint bands (issue 30): beside the half-buffers, last, near a glint (an albedo
// channel above 8) nfor's glint bands' pass smooths the output along each pixel's line; a
// frame without half-buffers is left to the combination.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <cmath>
#include <string>

#include "harness/frames.h"
#include "harness/gpu_fixture.h"
#include "host/api/device.h"
#include "host/methods/nfor.h"
#include "host/methods/nfor_band.h"
#include "mcdenoise/mcdenoise.h"
#include "methods/auto_object_frames.h"
#include "tools/render/renderer.h"

namespace mcd::test {
namespace {

class AutoGlintBands : public GpuTest {};

// A 32x24 cornell frame with half-buffers, a glint (albedo 20) at (16, 8) and a highlight's
// band broken by its samples' hits and misses along row 12, in the colour and both halves.
Frame GlintFrame() {
    render::RenderOptions options;
    options.width = 32, options.height = 24, options.spp = 8;
    options.layers = render::kLayersAll | render::kLayersHalves;
    Frame frame = RenderedFrame("cornell", options);
    for (int c = 0; c < 3; ++c) frame.layers.at("albedo").At(c, 8, 16) = 20.f;
    for (const char *layer : {"color", "half0.color", "half1.color"})
        for (int x = 4; x < 28; ++x)
            for (int c = 0; c < 3; ++c) frame.layers.at(layer).At(c, 12, x) = x % 2 ? 3.f : 1.f;
    return frame;
}

// The green channel's steps along the band.
double Unevenness(const Image &image) {
    double sum = 0;
    for (int x = 8; x < 24; ++x) sum += std::abs(image.At(1, 12, x + 1) - image.At(1, 12, x));
    return sum;
}

TEST_F(AutoGlintBands, BesideHalvesTheBandIsSmoothed) {
    Device device = api::BorrowDevice(Ctx());
    const Frame frame = GlintFrame();
    Method on("auto"), off("auto");
    off.Set("auto-glint-band-radius", 0);
    const Result smoothed = on.Run(device, frame);
    const Image unsmoothed = off.Run(device, frame).image;
    EXPECT_TRUE(PlanHas(smoothed, "auto: glint bands: "))
        << fmt::format("{}", fmt::join(smoothed.plan, "\n"));

    // nfor's pass at radius 3 on the output without it, bit for bit.
    NforGlintBandSettings s;
    s.radius = 3;
    s.glintAlbedo = kNforGlintAlbedo;
    s.reach = kNforGlintReach;
    Image expected = unsmoothed;
    ASSERT_GT(NforSmoothGlintBands(frame.layers.at("albedo"), nullptr, s, &expected), 0u);
    EXPECT_EQ(smoothed.image.data, expected.data);
    EXPECT_LT(Unevenness(smoothed.image), Unevenness(unsmoothed));
}

TEST_F(AutoGlintBands, AFrameWithoutHalvesIsLeft) {
    Device device = api::BorrowDevice(Ctx());
    Frame frame = GlintFrame();
    for (auto it = frame.layers.begin(); it != frame.layers.end();)
        it = it->first.rfind("half", 0) == 0 ? frame.layers.erase(it) : std::next(it);
    const Result result = Method("auto").Run(device, frame);
    EXPECT_FALSE(PlanHas(result, "auto: glint bands: "))
        << fmt::format("{}", fmt::join(result.plan, "\n"));
}

}  // namespace
}  // namespace mcd::test
