// auto's flat pixels (host/methods/auto_flat.h): nfor's output where no albedo, normal or
// shading edge lies within a pixel and nfor agrees, if it keeps the light there.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <vector>

#include "harness/frames.h"
#include "harness/gpu_fixture.h"
#include "host/api/device.h"
#include "host/error.h"
#include "host/methods/auto_flat.h"
#include "mcdenoise/mcdenoise.h"
#include "methods/auto_object_frames.h"
#include "tools/render/renderer.h"

namespace mcd {
namespace {

// A 12x10 frame: flat albedo and normals, the output 1 (RGBA, alpha 0.5), nfor `level`.
struct FlatFrame {
    Image albedo{12, 10, 3}, normal{12, 10, 3}, output{12, 10, 4}, nfor{12, 10, 3};
};

FlatFrame MakeFlat(float level) {
    FlatFrame f;
    for (int y = 0; y < 10; ++y)
        for (int x = 0; x < 12; ++x) {
            for (int c = 0; c < 3; ++c) {
                f.albedo.At(c, y, x) = 0.5f;
                f.normal.At(c, y, x) = c == 2 ? 1.f : 0.f;
                f.output.At(c, y, x) = 1.f;
                f.nfor.At(c, y, x) = level;
            }
            f.output.At(3, y, x) = 0.5f;
        }
    return f;
}

TEST(AutoFlat, TakesNforOnFlatPixelsThatAgreeAndKeepsAlpha) {
    FlatFrame f = MakeFlat(1.05f);
    Image out = f.output;
    AutoFlatResult r = AutoTakeNforWhereFlat(f.albedo, f.normal, f.nfor, {}, &out);
    EXPECT_TRUE(r.taken);
    EXPECT_EQ(r.pixels, 120u);
    EXPECT_NEAR(r.light, 1.05, 1e-6);
    for (int y = 0; y < 10; ++y)
        for (int x = 0; x < 12; ++x) {
            for (int c = 0; c < 3; ++c) ASSERT_EQ(out.At(c, y, x), 1.05f);
            ASSERT_EQ(out.At(3, y, x), 0.5f);
        }
}

TEST(AutoFlat, LeavesEdgesWithinAPixelAndWhereNforDisagrees) {
    FlatFrame f = MakeFlat(1.05f);
    // An albedo step between columns 3 and 4 (0.06 on each channel, over the step summed),
    // a normal step between rows 2 and 3 (0.2 on one channel), a shading step between rows
    // 7 and 8 (the output and nfor 1.5 from row 8 on) and nfor 1.2 (outside 0.1) at (6, 0).
    for (int y = 0; y < 10; ++y)
        for (int x = 0; x < 12; ++x) {
            for (int c = 0; c < 3; ++c) {
                if (x >= 4) f.albedo.At(c, y, x) = 0.56f;
                if (y >= 8) f.output.At(c, y, x) = f.nfor.At(c, y, x) = 1.5f;
            }
            if (y >= 3) f.normal.At(0, y, x) = 0.2f;
        }
    for (int c = 0; c < 3; ++c) f.nfor.At(c, 0, 6) = 1.2f;
    Image out = f.output;
    AutoFlatResult r = AutoTakeNforWhereFlat(f.albedo, f.normal, f.nfor, {}, &out);
    ASSERT_TRUE(r.taken);
    size_t taken = 0;
    for (int y = 0; y < 10; ++y)
        for (int x = 0; x < 12; ++x) {
            // An edge is the pixel before its step; it and its 3x3 neighbours are not flat.
            const bool edge = (x >= 2 && x <= 4) || (y >= 1 && y <= 3) || (y >= 6 && y <= 8);
            const bool kept = edge || (y == 0 && x == 6);
            taken += !kept;
            EXPECT_EQ(out.At(1, y, x), kept ? f.output.At(1, y, x) : f.nfor.At(1, y, x))
                << "at " << x << ", " << y;
        }
    EXPECT_EQ(r.pixels, taken);
}

TEST(AutoFlat, KeepsTheOutputWhereNforHoldsLessLight) {
    // Within the agreement everywhere, but 0.99 of the light: the output's bits.
    FlatFrame f = MakeFlat(0.99f);
    Image out = f.output;
    AutoFlatResult r = AutoTakeNforWhereFlat(f.albedo, f.normal, f.nfor, {}, &out);
    EXPECT_FALSE(r.taken);
    EXPECT_EQ(r.pixels, 120u);
    EXPECT_NEAR(r.light, 0.99, 1e-6);
    EXPECT_EQ(out.data, f.output.data);
    // At keep 0.98 it is taken.
    AutoFlatSettings lower;
    lower.keep = 0.98f;
    EXPECT_TRUE(AutoTakeNforWhereFlat(f.albedo, f.normal, f.nfor, lower, &out).taken);
    EXPECT_EQ(out.At(0, 2, 2), 0.99f);
}

TEST(AutoFlat, RefusesLayersOfAnotherSize) {
    FlatFrame f = MakeFlat(1.f);
    Image small(4, 4, 3);
    EXPECT_THROW(AutoTakeNforWhereFlat(small, f.normal, f.nfor, {}, &f.output), Error);
}

// The front end: beside the half-buffers the plan says what the flat step found and the
// output moves only where it took nfor's; without halves, or at 0, it does not run.
class AutoFlatMethod : public test::GpuTest {};

TEST_F(AutoFlatMethod, RunsBesideTheHalvesAlone) {
    Device device = api::BorrowDevice(Ctx());
    render::RenderOptions options;
    options.width = 32, options.height = 24, options.spp = 8;
    options.layers = render::kLayersAll | render::kLayersHalves;
    const Frame halves = test::RenderedFrame("cornell", options);
    Method on("auto"), off("auto");
    off.Set("auto-flat-nfor", 0.0);
    Result flat = on.Run(device, halves), unflat = off.Run(device, halves);
    ASSERT_TRUE(test::PlanHas(flat, "auto: flat: "))
        << fmt::format("{}", fmt::join(flat.plan, "\n"));
    EXPECT_FALSE(test::PlanHas(unflat, "auto: flat: "));
    if (test::PlanHas(flat, "nfor's output taken"))
        EXPECT_NE(flat.image.data, unflat.image.data);
    else
        EXPECT_EQ(flat.image.data, unflat.image.data);
    // A variance layer and no halves: no nfor candidate, no flat step.
    const Frame plain = test::RenderCornell(true);
    Result noHalves = on.Run(device, plain);
    EXPECT_FALSE(test::PlanHas(noHalves, "auto: flat: "));
    EXPECT_EQ(noHalves.image.data, off.Run(device, plain).image.data);
}

}  // namespace
}  // namespace mcd
