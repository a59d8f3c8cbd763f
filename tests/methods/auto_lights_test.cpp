// Method auto's lights' spread (issue 30): last, each emitter pixel gives --auto-light-share
// of nfor's lights' spread to its 4 neighbours that are no emitter; a frame without emitters
// keeps its bits.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <cmath>
#include <string>

#include "harness/gpu_fixture.h"
#include "host/api/device.h"
#include "host/methods/nfor_lights.h"
#include "mcdenoise/mcdenoise.h"
#include "methods/auto_object_frames.h"

namespace mcd::test {
namespace {

class AutoLights : public GpuTest {};

// The frame's alpha layer, or null where it has none (as auto's last passes read it).
const Image *AlphaOf(const Frame &frame) {
    return frame.layers.count("alpha") ? &frame.layers.at("alpha") : nullptr;
}

// The light moves, none is made or lost: each colour channel's sum over the frame kept.
void ExpectLightKept(const Image &before, const Image &after) {
    const size_t pixels = before.PixelCount();
    for (int c = 0; c < 3; ++c) {
        double sumBefore = 0, sumAfter = 0;
        for (size_t i = 0; i < pixels; ++i) {
            sumBefore += before.data[c * pixels + i];
            sumAfter += after.data[c * pixels + i];
        }
        EXPECT_NEAR(sumAfter, sumBefore, 1e-5 * sumBefore) << "channel " << c;
    }
}

TEST_F(AutoLights, AFrameWithoutEmittersKeepsItsBits) {
    Device device = api::BorrowDevice(Ctx());
    Method on("auto"), off("auto");
    off.Set("auto-light-share", 0.0);
    const Frame frame = RenderCornell(true);
    Result spread = on.Run(device, frame);
    EXPECT_EQ(spread.image.data, off.Run(device, frame).image.data);
    EXPECT_FALSE(PlanHas(spread, "auto: lights: "))
        << fmt::format("{}", fmt::join(spread.plan, "\n"));
}

TEST_F(AutoLights, EmittersGiveTheirRimsHalfOfNforsShares) {
    Device device = api::BorrowDevice(Ctx());
    // A 2x3 light in the frame (albedo 10, a strong emitter) and a weak one-pixel light
    // (albedo 4) at the border.
    Frame frame = RenderCornell(true);
    Image &albedo = frame.layers.at("albedo");
    const Image &color = frame.layers.at("color");
    const int w = color.width, h = color.height;
    for (int y = 10; y < 12; ++y)
        for (int x = 14; x < 17; ++x)
            for (int c = 0; c < albedo.channels; ++c) albedo.At(c, y, x) = 10.f;
    for (int c = 0; c < albedo.channels; ++c) albedo.At(c, 0, w - 1) = 4.f;

    Method on("auto"), off("auto");
    off.Set("auto-light-share", 0.0);
    Result spread = on.Run(device, frame);
    const Image unspread = off.Run(device, frame).image;
    EXPECT_TRUE(PlanHas(spread, "auto: lights: 7 emitter pixels"))
        << fmt::format("{}", fmt::join(spread.plan, "\n"));

    // The same as nfor's spread at half its shares on the output without it, bit for bit.
    NforLightSettings half;
    half.weakShare *= 0.5f;
    half.strongShare *= 0.5f;
    Image expected = unspread;
    ASSERT_EQ(NforSpreadLights(albedo, AlphaOf(frame), half, &expected), 7u);
    EXPECT_EQ(spread.image.data, expected.data);

    // A rim pixel took the light's share of each emitter beside it; the light kept the rest.
    for (int c = 0; c < 3; ++c) {
        const float light = unspread.At(c, 10, 14);
        EXPECT_FLOAT_EQ(spread.image.At(c, 10, 13), unspread.At(c, 10, 13) + 0.002f * light);
        EXPECT_LT(spread.image.At(c, 10, 14), light);
    }
    ExpectLightKept(unspread, spread.image);
    // The weak light gives 0.04 to its two neighbours inside the frame.
    EXPECT_NE(spread.image.At(0, 1, w - 1), unspread.At(0, 1, w - 1));
    EXPECT_NE(spread.image.At(0, 0, w - 2), unspread.At(0, 0, w - 2));
    EXPECT_EQ(spread.image.At(0, h - 1, 0), unspread.At(0, h - 1, 0));
}

// auto's rim hits, last: a 3x3 light (albedo and colour 320) with a pixel one of 16 samples
// hit beside it (20) in an 8-spp cornell frame (the spp layer set to 16): the output is auto's
// without the pass (--auto-rim-hits 0) with nfor's rim hits at ratio 16 / 2, bit for bit;
// the frame's light stays.
TEST_F(AutoLights, ARimHitComesDownLast) {
    Device device = api::BorrowDevice(Ctx());
    Frame frame = RenderCornell(true);
    Image &albedo = frame.layers.at("albedo"), &color = frame.layers.at("color");
    for (int y = 10; y < 13; ++y)
        for (int x = 14; x < 17; ++x)
            for (int c = 0; c < 3; ++c) albedo.At(c, y, x) = color.At(c, y, x) = 320.f;
    for (int c = 0; c < 3; ++c) albedo.At(c, 11, 17) = color.At(c, 11, 17) = 20.f;
    frame.layers["spp"] = Image(color.width, color.height, 1, 16.f);

    Method on("auto"), off("auto");
    off.Set("auto-rim-hits", 0);
    Result folded = on.Run(device, frame);
    const Image unfolded = off.Run(device, frame).image;
    EXPECT_TRUE(PlanHas(folded, "auto: rim hits: 1 emitter pixels"))
        << fmt::format("{}", fmt::join(folded.plan, "\n"));
    NforRimSettings s;
    s.coreRatio = NforRimRatio(16, kNforRimHits);
    Image expected = unfolded;
    ASSERT_EQ(NforFoldRimHits(color, albedo, AlphaOf(frame), s, &expected), 1u);
    EXPECT_EQ(folded.image.data, expected.data);
    EXPECT_LT(folded.image.At(0, 11, 17), 0.5f * unfolded.At(0, 11, 17));
    ExpectLightKept(unfolded, folded.image);
}

}  // namespace
}  // namespace mcd::test
