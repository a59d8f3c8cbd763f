// auto's probe of rhf (FrontEnd::ForProbe): it cuts the pixels the run cut (lights' rims,
// bright clusters, and on half0 the lone spikes), each from the probe's own colour, and gives
// the rims and clusters the probe's input back; a perturbation that would flip a cut does not,
// and on the run's own colour the probe is the run, bit for bit, whole and in tiles.
#include <gtest/gtest.h>

#include <memory>
#include <random>
#include <string>
#include <vector>

#include "harness/compare.h"
#include "harness/frames.h"
#include "harness/gpu_fixture.h"
#include "harness/inputs.h"
#include "host/api/front_end.h"
#include "host/api/registry.h"
#include "host/api/tiled_run.h"
#include "mcdenoise/mcdenoise.h"

namespace mcd::test {
namespace {

class RhfProbe : public GpuTest {};

// The count a plan's line starting with `prefix` states ("bright clusters: N pixels"), or -1.
int CountIn(const Result &result, const std::string &prefix) {
    for (const std::string &line : result.plan)
        if (line.rfind(prefix, 0) == 0) return std::stoi(line.substr(prefix.size()));
    return -1;
}

// The stage `name` of `result` (empty if none).
Image StageOf(const Result &result, const std::string &name) {
    for (const Stage &stage : result.stages)
        if (stage.name == name) return stage.image;
    return Image();
}

// A wall of 16 samples a pixel with a light's reflection of 4 pixels (1, 2, 1 and 3 samples
// of 16 at 300 a channel, cut whole as a bright cluster) and a 3x3 light whose edge a wide
// pixel filter spread, with a rim one sample saw beyond it (cut as a light's rim), and a
// firefly one sample of 16 saw at 40 (cut as a lone spike).
Frame ReflectionFrame() {
    const int w = 48, h = 40;
    std::mt19937_64 rng(SeedFromName("rhf probe cuts"));
    std::uniform_real_distribution<double> wallSample(0.005, 0.0216);
    auto reflection = [](int x, int y) {
        const int dx = x - 12, dy = y - 12;
        return dy == 0   ? (dx == 0   ? 1
                            : dx == 1 ? 2
                                      : 0)
               : dy == 1 ? (dx == -1  ? 1
                            : dx == 0 ? 3
                                      : 0)
                         : 0;
    };
    auto sample = [&](int x, int y, int s) {
        if (s < reflection(x, y)) return 300.0;
        if (x == 6 && y == 30 && s == 0) return 40.0;
        const bool rows = y >= 26 && y <= 28;
        if (rows && x >= 30 && x <= 32) return 10.0;
        if (rows && (x == 29 || x == 33) && s < 8) return 10.0;
        if (y == 27 && x == 28 && s == 0) return 10.0;
        return wallSample(rng);
    };
    return SampledFrame(w, h, sample);
}

// The run's colour with two of the reflection's pixels and the firefly at their wall's level:
// the probe's noise there would leave a cluster of 2, which is not cut, and no firefly.
Image FlippedColour(const Frame &frame) {
    Image color = frame.Get("color");
    for (int c = 0; c < 3; ++c)
        color.At(c, 12, 12) = color.At(c, 13, 11) = color.At(c, 30, 6) = 0.0133f;
    return color;
}

TEST_F(RhfProbe, KeepsTheRunsCutsWhereThePerturbationWouldFlipThem) {
    const Frame frame = ReflectionFrame();
    std::unique_ptr<api::FrontEnd> rhf = api::FindMethod("rhf")->make();
    api::Inputs inputs(frame, false, "rhf");
    RunOptions keep;
    keep.keepStages = true;
    const Result run = api::RunTiled(Ctx(), *rhf, inputs, keep);
    const int clusters = CountIn(run, "bright clusters: "),
              rims = CountIn(run, "lights' rims: ");
    ASSERT_EQ(clusters, 4);
    ASSERT_GT(rims, 0);
    ASSERT_EQ(CountIn(run, "spikes: "), 1);
    std::unique_ptr<api::FrontEnd> onHalf = rhf->ForProbe(Ctx(), inputs, true),
                                   onPerturbed = rhf->ForProbe(Ctx(), inputs, false);
    ASSERT_NE(onHalf, nullptr);
    ASSERT_NE(onPerturbed, nullptr);

    const Image flipped = FlippedColour(frame);
    inputs.Override("color", flipped);
    // Alone the flipped colour cuts no cluster, and the reflection's other two pixels as
    // spikes: the test tells the probe's cuts apart.
    const Result alone = api::RunTiled(Ctx(), *rhf, inputs, keep);
    EXPECT_EQ(CountIn(alone, "bright clusters: "), 0);
    const int ownSpikes = CountIn(alone, "spikes: ");
    EXPECT_EQ(ownSpikes, 2);
    for (const auto *probe : {onHalf.get(), onPerturbed.get()}) {
        const bool half = probe == onHalf.get();
        SCOPED_TRACE(half ? "on half0" : "on the perturbed colour");
        const Result probed = api::RunTiled(Ctx(), *probe, inputs, keep);
        EXPECT_EQ(CountIn(probed, "bright clusters: "), clusters);
        EXPECT_EQ(CountIn(probed, "lights' rims: "), rims);
        EXPECT_EQ(CountIn(probed, "spikes: "), half ? 1 : ownSpikes);
        // Each of the run's cluster pixels takes the probe's input back after the filter.
        const Image given = StageOf(probed, "exact pixels");
        ASSERT_TRUE(given.SameShape(flipped));
        for (auto [x, y] : {std::pair{12, 12}, {13, 12}, {11, 13}, {12, 13}})
            for (int c = 0; c < 3; ++c)
                EXPECT_EQ(given.At(c, y, x), flipped.At(c, y, x))
                    << x << ", " << y << " c" << c;
    }
}

// On the run's own colour the probe cuts what the run cuts, to the same bits, untiled and
// in tiles of 20 whose seams cross the cuts (the sets are the frame's, mapped per window).
TEST_F(RhfProbe, OnTheRunsColourIsTheRunBitForBit) {
    const Frame frame = ReflectionFrame();
    std::unique_ptr<api::FrontEnd> rhf = api::FindMethod("rhf")->make();
    api::Inputs inputs(frame, false, "rhf");
    const Result run = api::RunTiled(Ctx(), *rhf, inputs, RunOptions());
    RunOptions tiles;
    tiles.tileSize = 20;
    for (bool onHalf : {true, false}) {
        SCOPED_TRACE(onHalf ? "on half0" : "on the perturbed colour");
        std::unique_ptr<api::FrontEnd> probe = rhf->ForProbe(Ctx(), inputs, onHalf);
        ASSERT_NE(probe, nullptr);
        EXPECT_TRUE(
            BitIdentical(run.image, api::RunTiled(Ctx(), *probe, inputs, RunOptions()).image));
        const Result tiled = api::RunTiled(Ctx(), *probe, inputs, tiles);
        ASSERT_FALSE(tiled.plan.empty());
        EXPECT_NE(tiled.plan[0].find("tiled:"), std::string::npos) << tiled.plan[0];
        EXPECT_TRUE(BitIdentical(run.image, tiled.image)) << "in tiles of 20";
    }
}

// Without the cuts (--rhf-mean-radius 0) the probe runs as the run does.
TEST_F(RhfProbe, NoneWithoutCuts) {
    const Frame frame = ReflectionFrame();
    std::unique_ptr<api::FrontEnd> rhf = api::FindMethod("rhf")->make();
    rhf->Set("rhf-mean-radius", 0);
    api::Inputs inputs(frame, false, "rhf");
    EXPECT_EQ(rhf->ForProbe(Ctx(), inputs, true), nullptr);
    EXPECT_EQ(rhf->ForProbe(Ctx(), inputs, false), nullptr);
}

}  // namespace
}  // namespace mcd::test
