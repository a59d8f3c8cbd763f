// Tiled runs (host/api/tiled_run.h): a method that declares itself tile-local gives, in
// tiles of a forced small size with its halo, the untiled result bit for bit, on rendered
// and on random frames of odd sizes; the wavelet methods, which are not tile-local, still
// complete in tiles; the tile planner cuts only what does not fit.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <random>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "harness/frames.h"
#include "harness/gpu_fixture.h"
#include "harness/inputs.h"
#include "host/api/device.h"
#include "host/api/front_end.h"
#include "host/api/registry.h"
#include "host/api/tiled_run.h"
#include "host/methods/nfor.h"
#include "host/methods/nfor_band.h"
#include "host/methods/nfor_line.h"
#include "host/methods/nfor_specks.h"
#include "host/methods/run_memo.h"
#include "mcdenoise/mcdenoise.h"
#include "pivot/pivot.h"
#include "tools/render/renderer.h"

namespace mcd::test {
namespace {

using Params = std::vector<std::pair<std::string, ParamValue>>;

Frame RenderedFrame(int width, int height, int layers) {
    render::RenderOptions o;
    o.width = width, o.height = height, o.spp = 4;
    o.layers = layers;
    render::RenderResult r = render::Render(render::BuildScene("cornell"), o);
    Frame frame;
    frame.path = fmt::format("cornell {}x{}", width, height);
    frame.width = width, frame.height = height;
    for (auto &[name, image] : r.layers) frame.layers[name] = std::move(image);
    return frame;
}

// Seeded random layers: colour, variance and pivot positive with fireflies, histograms of
// 4 bins per colour with counts, normals and ids.
Frame RandomFrame(int width, int height, uint64_t seed) {
    Frame frame;
    frame.path = fmt::format("random {}x{}", width, height);
    frame.width = width, frame.height = height;
    frame.layers["color"] =
        MakeVarianceInput(InputKind::LogNormalFireflies, width, height, 3, seed);
    frame.layers["variance"] =
        MakeVarianceInput(InputKind::Uniform, width, height, 3, seed + 1);
    Image pivot = MakeVarianceInput(InputKind::Uniform, width, height, 3, seed + 2);
    for (float &v : pivot.data) v += 0.05f;
    frame.layers["pivot"] = pivot;
    Image hist = MakeVarianceInput(InputKind::Uniform, width, height, 13, seed + 3);
    for (float &v : hist.data) v = std::floor(v * 4);
    frame.layers["hist"] = hist;
    frame.layers["normal"] = MakeInput(InputKind::Uniform, width, height, 3, seed + 4);
    Image ids = MakeVarianceInput(InputKind::Uniform, width, height, 1, seed + 5);
    for (float &v : ids.data) v = std::floor(v * 3);
    frame.layers["objectId"] = ids;
    return frame;
}

Result RunWith(Device &device, const std::string &name, const Params &params,
               const Frame &frame, int tile, std::vector<std::string> stages = {}) {
    Method method(name);
    for (const auto &[param, value] : params) method.Set(param, value);
    RunOptions run;
    run.tileSize = tile;
    run.stages = std::move(stages);
    return method.Run(device, frame, run);
}

// nfor on `frame` whole and in tiles of `tile` columns, the tiled plan checked for two tiles.
struct WholeAndTiled {
    Result whole, tiled;
};

WholeAndTiled RunNforInTwoTiles(Device &device, const Params &params, const Frame &frame,
                                int tile) {
    WholeAndTiled runs{RunWith(device, "nfor", params, frame, 0),
                       RunWith(device, "nfor", params, frame, tile)};
    if (runs.tiled.plan.empty())
        ADD_FAILURE() << "the tiled run printed no plan";
    else
        EXPECT_NE(runs.tiled.plan[0].find("2 tile(s)"), std::string::npos)
            << runs.tiled.plan[0];
    return runs;
}

// What method `name` with `params` asks of tiles on `frame` (its halo, its binding).
api::TileNeeds NeedsWith(const std::string &name, const Params &params, const Frame &frame) {
    std::unique_ptr<api::FrontEnd> method = api::FindMethod(name)->make();
    for (const auto &[param, value] : params) method->Set(param, value);
    api::Inputs inputs(frame, false, name);
    return method->Tiling(TestContext(), inputs);
}

// Bit for bit, NaN included.
void ExpectSameBits(const Image &a, const Image &b, const std::string &what) {
    ASSERT_TRUE(a.SameShape(b)) << what;
    for (size_t i = 0; i < a.data.size(); ++i) {
        uint32_t x, y;
        std::memcpy(&x, &a.data[i], 4);
        std::memcpy(&y, &b.data[i], 4);
        if (x != y) {
            size_t pixel = i % a.PixelCount();
            FAIL() << what << ": first difference at pixel (" << pixel % a.width << ", "
                   << pixel / a.width << "), channel " << i / a.PixelCount() << ": "
                   << a.data[i] << " untiled, " << b.data[i] << " tiled";
        }
    }
}

// The halo a tiled run's plan states ("a halo of N pixels"), or -1.
int HaloOf(const Result &tiled) {
    const std::string key = "a halo of ";
    const size_t at = tiled.plan.empty() ? std::string::npos : tiled.plan[0].find(key);
    return at == std::string::npos ? -1 : std::stoi(tiled.plan[0].substr(at + key.size()));
}

struct LocalCase {
    std::string name, method;
    Params params;
    int tile, width, height;
};

class TiledRunLocal : public GpuTestWithParam<LocalCase> {};

TEST_P(TiledRunLocal, BitIdenticalToUntiled) {
    const LocalCase &c = GetParam();
    Device device = api::BorrowDevice(Ctx());
    // Frames several halos wide, so that tiles inside have halos on every side.
    std::vector<std::pair<std::string, Frame>> frames = {
        {"rendered", RenderedFrame(c.width, c.height, render::kLayersAll)},
        {"random", RandomFrame(c.width - 8, c.height - 6, SeedFromName(c.name))}};
    if (c.method == "pivot") {
        frames.push_back(
            {"partials", RenderedFrame(45, 39, render::kLayersAll | render::kLayersPartials)});
        // Without a variance layer pivot's fits read the frame's own noise estimate.
        Frame plain = frames[0].second;
        plain.layers.erase("variance");
        frames.push_back({"plain", plain});
        // Lone spikes of the pivot that few samples saw, across the tiles' seams
        // (--pivot-spikes).
        Frame spikes = frames[1].second;
        Image &pivot = spikes.layers["pivot"], &color = spikes.layers["color"];
        Image &variance = spikes.layers["variance"];
        for (size_t p = 0; p < pivot.PixelCount(); p += 37)
            for (int c = 0; c < 3; ++c) {
                pivot.Plane(c)[p] *= 100, color.Plane(c)[p] *= 100;
                variance.Plane(c)[p] = color.Plane(c)[p] * color.Plane(c)[p];
            }
        frames.push_back({"spikes", spikes});
    }
    size_t chromaMoved = 0;
    for (const auto &[kind, frame] : frames) {
        Params params = c.params;
        if (kind == "spikes") params.push_back({"pivot-spikes", true});
        Result whole = RunWith(device, c.method, params, frame, 0);
        Result tiled = RunWith(device, c.method, params, frame, c.tile);
        if (c.method == "pivot") {
            // The chroma's last step names itself: it runs with a variance layer and ids,
            // its pixels across the seams the tiles' (same bits, below).
            std::string line;
            for (const std::string &l : whole.plan)
                if (l.rfind("chroma: ", 0) == 0) line = l;
            ASSERT_FALSE(line.empty()) << kind;
            const bool looked =
                frame.layers.count("variance") && frame.layers.count("objectId");
            EXPECT_EQ(line.find("not looked at") == std::string::npos, looked) << line;
            if (looked) chromaMoved += std::stoul(line.substr(8));
        }
        ASSERT_FALSE(tiled.plan.empty());
        EXPECT_NE(tiled.plan[0].find("tiled:"), std::string::npos) << tiled.plan[0];
        EXPECT_NE(tiled.plan[0].find("bit for bit"), std::string::npos) << tiled.plan[0];
        ExpectSameBits(whole.image, tiled.image, c.name + " on the " + kind + " frame");
        // The last step, made once on the assembled frame, leaves the halo (FrontEnd::
        // Finish); with --pivot-spikes it restores from the tiles' scaled pixels and stays.
        const api::TileNeeds needs = NeedsWith(c.method, params, frame);
        EXPECT_EQ(HaloOf(tiled), needs.reach - needs.finishReach) << tiled.plan[0];
        EXPECT_EQ(needs.finishReach > 0, kind != "spikes") << kind;
        if (kind == "spikes") {
            // The spikes' 3x3 window adds exactly 1 to the reach.
            EXPECT_EQ(needs.reach, NeedsWith(c.method, c.params, frame).reach + 1);
            bool scaled = false;
            for (const std::string &line : whole.plan)
                scaled |= line.rfind("pivot spikes: ", 0) == 0 &&
                          line.rfind("pivot spikes: 0 ", 0) != 0;
            EXPECT_TRUE(scaled) << "the spikes frame scales no spike";
        }
    }
    if (c.method == "pivot") {
        EXPECT_GT(chromaMoved, 0u) << "no chroma pixel moved";
    }
}

class TiledRunShared : public GpuTest {};

// rhf in tiles of 40 on a frame's inputs that share one memo (as auto's runs do); returns
// how many selections the memo kept.
struct SharedRhfRuns {
    explicit SharedRhfRuns(const Frame &frame) : shared(frame, false, "rhf") {
        run.tileSize = 40;
        shared.SetMemo(&memo);
    }
    Result Run(const api::FrontEnd &rhf) {
        return api::RunTiled(TestContext(), rhf, shared, run);
    }
    size_t Selections() const { return memo.CountWithPrefix("rhf.mask"); }
    RunOptions run;
    RunMemo memo;
    api::Inputs shared;
};

// auto's runs share rhf's selections through the inputs' memo, tile by tile: a second run in
// tiles on another colour takes the first's and gives what it gives alone.
TEST_F(TiledRunShared, RhfSelectionsTakenFromAnEarlierRunAreBitIdentical) {
    Frame frame = RenderedFrame(97, 83, render::kLayersAll), other = frame;
    for (float &v : other.layers["color"].data) v *= 1.25f;
    std::unique_ptr<api::FrontEnd> rhf = api::FindMethod("rhf")->make();
    rhf->Set("nscales", 2);
    SharedRhfRuns runs(frame);
    const RunOptions &run = runs.run;
    runs.Run(*rhf);
    const size_t kept = runs.Selections();
    EXPECT_GT(kept, 0u);
    runs.shared.Override("color", other.layers["color"]);
    Result second = runs.Run(*rhf);
    EXPECT_EQ(runs.Selections(), kept) << "the second run made selections of its own";
    api::Inputs alone(other, false, "rhf");
    ExpectSameBits(api::RunTiled(Ctx(), *rhf, alone, run).image, second.image,
                   "rhf at 2 scales in tiles, selections shared");
}

// The windows' histograms are keyed by the frame's layer and the window (Inputs::LayerId):
// after the frame's histograms are replaced a tiled run selects anew, window by window, and
// gives what it gives alone on them.
TEST_F(TiledRunShared, RhfReplacedHistogramsSelectAnew) {
    Frame frame = RenderedFrame(97, 83, render::kLayersAll), other = frame;
    // Each colour's bins in reverse order: the same counts, other distances.
    Image &hist = other.layers["hist"];
    const int bins = (hist.channels - 1) / 3;
    const Image before = hist;
    for (int c = 0; c < 3 * bins; ++c)
        std::copy_n(before.Plane(c / bins * bins + bins - 1 - c % bins), hist.PixelCount(),
                    hist.Plane(c));
    std::unique_ptr<api::FrontEnd> rhf = api::FindMethod("rhf")->make();
    SharedRhfRuns runs(frame);
    const RunOptions &run = runs.run;
    runs.Run(*rhf);
    const size_t kept = runs.Selections();
    ASSERT_EQ(kept, 9u) << "one selection a tile";
    runs.shared.Override("hist", other.layers["hist"]);
    Result second = runs.Run(*rhf);
    EXPECT_EQ(runs.Selections(), 2 * kept) << "new histograms, new selections";
    api::Inputs alone(other, false, "rhf");
    const Image expected = api::RunTiled(Ctx(), *rhf, alone, run).image;
    ExpectSameBits(expected, second.image, "rhf in tiles on replaced histograms");
    api::Inputs first(frame, false, "rhf");
    const Image firstImage = api::RunTiled(Ctx(), *rhf, first, run).image;
    EXPECT_NE(0, std::memcmp(firstImage.data.data(), expected.data.data(),
                             expected.data.size() * sizeof(float)))
        << "the reversed bins select as the frame's do: the test tells nothing";
}

// auto's rhf at one scale and at two cut a frame alike where both run in tiles (their needs
// widened together, WidestNeeds): the second takes the first's finest selections window by
// window and gives what it gives alone; planned on its own needs it selects anew.
TEST_F(TiledRunShared, RhfScalesPlannedAlikeShareTheFinestSelections) {
    const Frame frame = RenderedFrame(133, 101, render::kLayersAll);
    std::unique_ptr<api::FrontEnd> one = api::FindMethod("rhf")->make(),
                                   two = api::FindMethod("rhf")->make();
    two->Set("nscales", 2);
    RunOptions run;
    run.tileSize = 40;
    api::Inputs alone(frame, false, "rhf");
    const Image twoAlone = api::RunTiled(Ctx(), *two, alone, run).image;
    size_t made[2] = {};
    for (bool widened : {false, true}) {
        SCOPED_TRACE(widened ? "widened" : "each its own");
        RunMemo memo;
        api::Inputs shared(frame, false, "rhf");
        shared.SetMemo(&memo);
        const api::TileNeeds needs =
            api::WidestNeeds(one->Tiling(Ctx(), shared), two->Tiling(Ctx(), shared));
        const api::TileNeeds *plan = widened ? &needs : nullptr;
        api::RunTiled(Ctx(), *one, shared, run, plan);
        const size_t first = memo.CountWithPrefix("rhf.mask");
        ASSERT_EQ(first, 12u) << "one selection a tile";
        const Result second = api::RunTiled(Ctx(), *two, shared, run, plan);
        made[widened] = memo.CountWithPrefix("rhf.mask") - first;
        ExpectSameBits(twoAlone, second.image, "rhf at 2 scales after rhf at 1");
    }
    EXPECT_EQ(made[1], 12u) << "the coarser scale's alone";
    EXPECT_GT(made[0], 12u) << "the test tells shared windows from their own";
    // auto widens the plans of rhf's variants alone: pivot's share nothing window by window.
    api::Inputs inputs(frame, false, "rhf");
    EXPECT_TRUE(one->Tiling(Ctx(), inputs).sharesByWindow);
    EXPECT_FALSE(api::FindMethod("pivot")->make()->Tiling(Ctx(), inputs).sharesByWindow);
}

// auto's rhf candidates in tiles on the plan they share (WidestNeeds), both probed on a
// perturbed colour: the second run takes the first's cuts tile by tile, ForProbe keeps no
// cuts of the whole frame (no tile reads them), the second probe takes the first's decided
// cuts tile by tile; each bit for bit as alone.
TEST_F(TiledRunShared, RhfScalesAndTheirProbesShareTheCutsByTile) {
    const Frame frame = RenderedFrame(133, 101, render::kLayersAll);
    Image perturbed = frame.Get("color");
    std::mt19937_64 rng(SeedFromName("tiled rhf probes"));
    std::normal_distribution<float> noise(0.f, 0.2f);
    for (float &v : perturbed.data) v = std::max(0.f, v * (1.f + noise(rng)));
    std::unique_ptr<api::FrontEnd> one = api::FindMethod("rhf")->make(),
                                   two = api::FindMethod("rhf")->make();
    two->Set("nscales", 2);
    RunMemo memo;
    api::Inputs shared(frame, false, "rhf"), alone(frame, false, "rhf");
    shared.SetMemo(&memo);
    RunOptions run;
    run.tileSize = 40;
    const api::TileNeeds needs =
        api::WidestNeeds(one->Tiling(Ctx(), shared), two->Tiling(Ctx(), shared));
    auto tiled = [&](const api::FrontEnd &method, api::Inputs &inputs) {
        return api::RunTiled(Ctx(), method, inputs, run, &needs).image;
    };
    auto count = [&](const char *prefix) { return memo.CountWithPrefix(prefix); };
    tiled(*one, shared);
    ASSERT_EQ(count("rhf.own cuts"), 12u) << "one entry a tile";
    ExpectSameBits(tiled(*two, alone), tiled(*two, shared), "rhf at 2 scales, cuts shared");
    EXPECT_EQ(count("rhf.own cuts"), 12u) << "the second run cut anew";
    std::unique_ptr<api::FrontEnd> probes[2] = {one->ForProbe(Ctx(), shared, false),
                                                two->ForProbe(Ctx(), shared, false)},
                                   ownProbes[2] = {one->ForProbe(Ctx(), alone, false),
                                                   two->ForProbe(Ctx(), alone, false)};
    EXPECT_EQ(count("rhf.own cuts"), 12u) << "ForProbe kept the whole frame's cuts";
    shared.Override("color", perturbed);
    alone.Override("color", perturbed);
    for (int i = 0; i < 2; ++i) {
        SCOPED_TRACE(i ? "rhf at 2 scales' probe" : "rhf's probe");
        ExpectSameBits(tiled(*ownProbes[i], alone), tiled(*probes[i], shared), "probe");
        EXPECT_EQ(count("rhf.decided cuts"), 12u) << "one entry a tile, made once";
    }
}

// rhf's plan counts the pooled bright veto's counts, a float a pixel, only when it is on
// (off, its buffer is one float).
TEST_F(GpuTest, TiledRunPlanRhfCountsThePoolWhenOn) {
    std::unique_ptr<api::FrontEnd> rhf = api::FindMethod("rhf")->make();
    Frame frame = RenderedFrame(17, 13, render::kLayersAll);
    api::Inputs inputs(frame, false, "rhf");
    const double off = rhf->Tiling(Ctx(), inputs).bytesPerPixel;
    rhf->Set("bright-pool", 6.f);
    EXPECT_EQ(rhf->Tiling(Ctx(), inputs).bytesPerPixel, off + 4);
}

TEST(TiledRunPlan, WidestNeedsHoldBoth) {
    api::TileNeeds a, b;
    a.reach = 50, a.finishReach = 30, a.align = 2, a.bytesPerPixel = 10, a.fixedBytes = 7;
    b.reach = 40, b.finishReach = 0, b.align = 8, b.bindingBytesPerPixel = 3, b.maxWidth = 90;
    const api::TileNeeds w = api::WidestNeeds(a, b);
    EXPECT_EQ(w.reach - w.finishReach, 40) << "the larger halo";
    EXPECT_EQ(w.finishReach, 30) << "its own last step";
    EXPECT_EQ(w.align, 8);
    EXPECT_EQ(w.bytesPerPixel, 10);
    EXPECT_EQ(w.bindingBytesPerPixel, 3);
    EXPECT_EQ(w.fixedBytes, 7);
    EXPECT_EQ(w.maxWidth, 90);
    a.maxWidth = 60;
    EXPECT_EQ(api::WidestNeeds(a, b).maxWidth, 60);
}

// The count a plan's line starting with `prefix` states ("bright clusters: N pixels"), or -1.
int CountIn(const Result &result, const std::string &prefix) {
    for (const std::string &line : result.plan)
        if (line.rfind(prefix, 0) == 0) return std::stoi(line.substr(prefix.size()));
    return -1;
}

// rhf's cuts across the tiles' seams: a wall of 16 samples a pixel with, every 16 pixels, a
// light's reflection of 4 pixels a few samples saw (cut whole as a bright cluster) and small
// lights whose edges a wide pixel filter spread (their rims cut), shifted row by row so that
// some straddle each seam of tiles of 40; the tiled result is the untiled one, bit for bit,
// at the default search window, at 2 and at 0 (the cuts' reach then the rims' window of
// lights over the clusters' pixels and their neighbours).
TEST_F(GpuTest, TiledRunRhfCutsAcrossTheSeamAreBitIdentical) {
    const int w = 133, h = 101;
    std::mt19937_64 rng(SeedFromName("tiled rhf cuts"));
    std::uniform_real_distribution<double> wallSample(0.005, 0.0216);
    // Bright samples of the reflection at (dx, dy) from its corner, of 16.
    auto reflection = [](int dx, int dy) {
        return dy == 0   ? (dx == 1   ? 1
                            : dx == 2 ? 2
                                      : 0)
               : dy == 1 ? (dx <= 1 ? 1 + 2 * dx : 0)
                         : 0;
    };
    auto sample = [&](int x, int y, int s) {
        const int row = y / 16, dy = y % 16, dx = (x + 5 * row) % 16;
        if (row % 2 == 0) return s < reflection(dx - 6, dy - 6) ? 300.0 : wallSample(rng);
        // A 3x3 light with half-lit columns beside it and a rim one sample saw beyond.
        const bool rows = dy >= 6 && dy <= 8;
        if (rows && dx >= 6 && dx <= 8) return 10.0;
        if (rows && (dx == 5 || dx == 9) && s < 8) return 10.0;
        if (dy == 7 && (dx == 4 || dx == 10) && s == 0) return 10.0;
        return wallSample(rng);
    };
    const Frame frame = SampledFrame(w, h, sample);
    Device device = api::BorrowDevice(Ctx());
    // At --search-half 1 or 0 a cluster's window outside its box grown by 1 is empty: no
    // cluster is cut, the rims are.
    const std::vector<std::pair<std::string, Params>> cases = {
        {"rhf", {}},
        {"rhf --search-half 2", {{"search-half", 2}}},
        {"rhf --search-half 0 --knn 1", {{"search-half", 0}, {"knn", 1}}}};
    for (const auto &[what, params] : cases) {
        Result whole = RunWith(device, "rhf", params, frame, 0);
        if (what != cases.back().first) {
            EXPECT_GT(CountIn(whole, "bright clusters: "), 0) << what;
        }
        EXPECT_GT(CountIn(whole, "lights' rims: "), 0) << what;
        Result tiled = RunWith(device, "rhf", params, frame, 40);
        ASSERT_FALSE(tiled.plan.empty());
        EXPECT_NE(tiled.plan[0].find("tiled:"), std::string::npos) << tiled.plan[0];
        ExpectSameBits(whole.image, tiled.image, what + " with cuts across the seams");
    }
}

// The bright pixels a caustic of 5 pixels on a dim floor holds at (dx, dy) from its corner
// (its samples of 16 at `value` a channel, the others at `dim`, 0 for the floor's): two
// pairs over 16 times their neighbours' median and the pixel between them under it (a dim
// neighbour and its four bright ones lift its median), which joins them.
struct CausticPixel {
    int samples;
    double value, dim;
};
CausticPixel CausticAt(int dx, int dy) {
    if (dy == 0 && dx == 1) return {0, 0, 0.1};
    if (dy == 0 && dx == 2) return {1, 12.7, 0};
    if (dy == 1 && dx == 0) return {1, 39.3, 0};
    if (dy == 1 && dx == 1) return {1, 20.6, 0};
    if (dy == 1 && dx == 2) return {1, 16.5, 0};
    if (dy == 2 && dx == 0) return {2, 9.6, 0};
    return {0, 0, 0};
}

// rhf's joins across the tiles' seams: caustics split at their middle (cut whole, their energy
// left to the restore) straddling the seams of tiles of 40, and a light's reflection of 4
// pixels with a bright pixel beside it that also touches the end of a line of one-sample
// pixels 197 long, whose far end holds no bright sample (a tile's window sees only the
// line's bright part): the line cannot be bridged, whole or in tiles, and the reflection is
// cut alone; the tiled result is the untiled one, bit for bit, at the default search window
// and at 2 (the cuts' reach then the joins').
TEST_F(GpuTest, TiledRunRhfJoinsAcrossTheSeamAreBitIdentical) {
    const int w = 240, h = 40, lineY = 21;
    std::mt19937_64 rng(SeedFromName("tiled rhf joins"));
    std::uniform_real_distribution<double> floorSample(0.005, 0.0216);
    const std::vector<std::pair<int, int>> caustics = {{38, 6}, {78, 30}, {119, 5}, {158, 34}};
    auto sample = [&](int x, int y, int s) {
        for (auto [cx, cy] : caustics)
            if (x >= cx && x <= cx + 2 && y >= cy && y <= cy + 2) {
                const CausticPixel c = CausticAt(x - cx, y - cy);
                if (s < c.samples) return c.value;
                if (c.dim > 0) return c.dim;
            }
        // The reflection at x 200-201, its bridge at 199 in a dim glow (which keeps it
        // under 16 times its neighbours' median), the line up to 198.
        const int reflection = y == lineY - 1 ? (x == 200   ? 1
                                                 : x == 201 ? 2
                                                            : 0)
                               : y == lineY   ? (x == 200   ? 1
                                                 : x == 201 ? 3
                                                            : 0)
                                              : 0;
        if (reflection) return s < reflection ? 300.0 : floorSample(rng);
        if (x == 199 && y == lineY) return s == 0 ? 9.0 : 0.1;
        if (x >= 198 && x <= 199 && std::abs(y - lineY) == 1) return 0.1;
        if (y == lineY && x == 2) return 5.0;
        if (y == lineY && x > 2 && x <= 198) return s == 0 ? 300.0 : floorSample(rng);
        return floorSample(rng);
    };
    const Frame frame = SampledFrame(w, h, sample);
    Device device = api::BorrowDevice(Ctx());
    const std::vector<std::pair<std::string, Params>> cases = {
        {"rhf", {}}, {"rhf --search-half 2", {{"search-half", 2}}}};
    for (const auto &[what, params] : cases) {
        Result whole = RunWith(device, "rhf", params, frame, 0);
        std::string plan;
        for (const std::string &line : whole.plan) plan += line + "\n";
        EXPECT_EQ(CountIn(whole, "bright clusters: "), 4) << what << "\n" << plan;
        EXPECT_NE(plan.find("; 20 more in clusters joined"), std::string::npos) << what << "\n"
                                                                                << plan;
        Result tiled = RunWith(device, "rhf", params, frame, 40);
        ASSERT_FALSE(tiled.plan.empty());
        EXPECT_NE(tiled.plan[0].find("tiled:"), std::string::npos) << tiled.plan[0];
        ExpectSameBits(whole.image, tiled.image, what + " with joins across the seams");
    }
}

INSTANTIATE_TEST_SUITE_P(
    Cases, TiledRunLocal,
    ::testing::Values(
        LocalCase{"rhf_defaults", "rhf", {}, 40, 133, 101},
        LocalCase{"rhf_patch_2_one_scale",
                  "rhf",
                  {{"nscales", 1}, {"patch-half", 2}, {"search-half", 4}},
                  7,
                  61,
                  47},
        // Three scales: the upsampler maps through the whole frame's sizes (odd here, so a
        // window's own sizes would interpolate elsewhere).
        LocalCase{
            "rhf_three_scales", "rhf", {{"nscales", 3}, {"search-half", 2}}, 44, 133, 101},
        // The pooled bright veto: its counts cut at a window's edge lie beyond the halo's
        // reach.
        LocalCase{
            "rhf_bright_pool", "rhf", {{"bright-pool", 6.f}, {"search-half", 4}}, 9, 61, 47},
        LocalCase{"pivot_planefit", "pivot", {{"max-radius", 5}}, 13, 61, 47},
        LocalCase{
            "pivot_bilateral", "pivot", {{"filter", std::string("bilateral")}}, 9, 61, 47}),
    [](const auto &info) { return info.param.name; });

// A frame whose light on the left is in rare bright samples (one pixel in 8 saw a caustic
// through 4 of its 16 paths; the clamp against the frame's own estimate would take much of
// it off) and whose right is plain noise with two fireflies the variance layer hides (their
// own samples report their variance): the left tile alone would clamp against the layer,
// the right alone against the estimate, the whole frame against the layer.
Frame RareBrightLeftFrame(int width, int height, int brightColumns) {
    Frame frame;
    frame.path = fmt::format("rare bright left {}x{}", width, height);
    frame.width = width, frame.height = height;
    Image color(width, height, 3), variance(width, height, 3), albedo(width, height, 3);
    std::mt19937_64 rng(SeedFromName("rare bright left"));
    std::normal_distribution<double> noise;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            bool hit = rng() % 8 == 0;
            for (int c = 0; c < 3; ++c) {
                double t = 0.3 + 0.2 * c + 0.3 * x / width + 0.1 * y / height;
                albedo.At(c, y, x) = 0.5f;
                if (x < brightColumns) {
                    // Per sample 0 or 40 t: mean 10 t or 0.
                    color.At(c, y, x) = hit ? float(10 * t) : 0.f;
                    variance.At(c, y, x) = hit ? float(std::pow(40 * t, 2) * 0.75 / 64) : 0.f;
                } else {
                    color.At(c, y, x) = float(std::max(0.0, t * (1 + 0.1 * noise(rng))));
                    variance.At(c, y, x) = float(std::pow(0.1 * t, 2));
                }
            }
        }
    for (auto [c, y, x] :
         {std::tuple{1, height / 3, width - 40}, std::tuple{0, height / 2, width - 20}}) {
        float &firefly = color.At(c, y, x);
        firefly *= 1000;
        variance.At(c, y, x) = firefly * firefly / 16;
    }
    frame.layers["color"] = std::move(color);
    frame.layers["variance"] = std::move(variance);
    frame.layers["albedo"] = std::move(albedo);
    return frame;
}

// The plan's line on what the firefly clamp read (printed): true for the variance layer.
bool ClampReadsTheLayer(const Result &result) {
    for (const std::string &line : result.plan)
        if (line.find("firefly clamp") != std::string::npos) {
            std::printf("%s\n", line.c_str());
            return line.find("so it reads the variance layer") != std::string::npos;
        }
    ADD_FAILURE() << "no line on the firefly clamp in the plan";
    return false;
}

// nfor on a plain frame (no variance layer) with lights across the tiles' seam: the lights'
// spread reads its 4 neighbours' output, inside the halo, so the tiled result is the
// untiled one bit for bit.
TEST_F(GpuTest, TiledRunNforSpreadsLightsAcrossTheSeam) {
    Device device = api::BorrowDevice(Ctx());
    const int width = 256, height = 40, tile = 128;
    Frame frame;
    frame.path = "lights across a seam";
    frame.width = width, frame.height = height;
    uint64_t seed = SeedFromName(frame.path);
    Image color = MakeVarianceInput(InputKind::Uniform, width, height, 3, seed);
    Image albedo = MakeVarianceInput(InputKind::Uniform, width, height, 3, seed + 1);
    // A strong light over the seam, a weak one beside it.
    for (int y = 10; y < 14; ++y)
        for (int x = tile - 2; x < tile + 2; ++x)
            for (int c = 0; c < 3; ++c) albedo.At(c, y, x) = color.At(c, y, x) = 300.f;
    for (int c = 0; c < 3; ++c) albedo.At(c, 25, tile) = color.At(c, 25, tile) = 3.f;
    frame.layers["color"] = std::move(color);
    frame.layers["albedo"] = std::move(albedo);
    frame.layers["normal"] = MakeInput(InputKind::Uniform, width, height, 3, seed + 2);
    Params params = {{"radius", 3}, {"pilot-bandwidths", std::string("none")}};
    auto [whole, tiled] = RunNforInTwoTiles(device, params, frame, tile);
    bool spread = false;
    for (const std::string &line : whole.plan) spread = spread || line.find("lights: ") == 0;
    EXPECT_TRUE(spread);
    ExpectSameBits(whole.image, tiled.image, "nfor tiled, lights spread");
}

// nfor beside a variance layer decides once for the frame whether its clamp reads the
// layer (--clamp-loss): every tile reads what the whole frame's run reads, though each
// window alone would decide otherwise, and the tiled result is the untiled one bit for bit;
// with the coarse pass too (its half-resolution frame decided once as well). So do the
// passes that follow that decision (the weak emitters' mean, the lights' spread): the right
// window alone reads the estimate and runs them, in tiles it reads the layer and does not.
TEST_F(GpuTest, TiledRunNforClampDecidesOnceForTheFrame) {
    Device device = api::BorrowDevice(Ctx());
    // Bright columns few enough that the right window's halo, which the passes widen,
    // holds none of them.
    const int width = 256, height = 48, tile = 128, bright = 48;
    Frame frame = RareBrightLeftFrame(width, height, bright);
    for (bool coarse : {false, true}) {
        SCOPED_TRACE(coarse ? "coarse pass" : "no coarse pass");
        Params params = {{"radius", 3},
                         {"noisy-radius", 0},
                         {"pilot-bandwidths", std::string("none")},
                         {"nfor-mean-radius", 0},
                         {"nfor-coarse", coarse}};
        auto [whole, tiled] = RunNforInTwoTiles(device, params, frame, tile);
        ASSERT_FALSE(tiled.plan.empty());
        EXPECT_NE(tiled.plan[0].find("bit for bit"), std::string::npos) << tiled.plan[0];
        EXPECT_TRUE(ClampReadsTheLayer(whole));
        ExpectSameBits(whole.image, tiled.image, "nfor tiled");

        std::unique_ptr<api::FrontEnd> nfor = api::FindMethod("nfor")->make();
        for (const auto &[param, value] : params) nfor->Set(param, value);
        api::Inputs inputs(frame, false, "nfor");
        api::TileNeeds needs = nfor->Tiling(Ctx(), inputs);
        // The right window holds none of the bright columns.
        ASSERT_LE(needs.reach, tile - bright);
        std::unique_ptr<api::FrontEnd> forTiles = nfor->ForTiles(Ctx(), inputs);
        // The windows RunTiled cuts: each tile and its halo.
        for (auto [x0, x1] :
             {std::pair{0, tile + needs.reach}, std::pair{tile - needs.reach, width}}) {
            SCOPED_TRACE(fmt::format("window [{}, {})", x0, x1));
            api::Inputs window(inputs, x0, 0, x1, height);
            RunOptions stages;
            stages.keepStages = true;
            Result alone = nfor->Run(Ctx(), window, stages);
            Result inTiles = forTiles->Run(Ctx(), window, stages);
            EXPECT_EQ(ClampReadsTheLayer(alone), x0 == 0) << "the frame decides alike";
            EXPECT_TRUE(ClampReadsTheLayer(inTiles));
            auto has = [](const Result &result, const std::string &name) {
                for (const auto &stage : result.stages)
                    if (stage.name == name) return true;
                return false;
            };
            for (const char *name : {"unkept", "lights"}) {
                EXPECT_EQ(has(alone, name), x0 != 0) << name << " alone";
                EXPECT_FALSE(has(inTiles, name)) << name << " in tiles";
            }
            bool said = false;
            for (const std::string &line : inTiles.plan)
                said = said || line.find("over the whole frame") != std::string::npos;
            EXPECT_TRUE(said) << "the plan says the decision is the frame's";
        }
    }
}

// nfor beside a variance layer whose clamp reads it, with lone samples (one sample of 64
// holding the mean) on both sides of the tiles' seam: isolated ones, pairs 12 apart (a
// caustic's, kept) and a pair 8 apart astride the edge the right tile's window would have
// without the lone samples' reach (there its right one would look isolated). Each tile's
// halo holds that reach, so the tiled result is the untiled one bit for bit.
TEST_F(GpuTest, TiledRunNforLoneSamplesAreTheWholeFrames) {
    Device device = api::BorrowDevice(Ctx());
    const int width = 512, height = 48, tile = 256;
    Frame frame = RareBrightLeftFrame(width, height, 48);
    Params params = {{"radius", 3}, {"pilot-bandwidths", std::string("none")}};
    Params without = params;
    without.push_back({"no-lone-sample-cap", true});
    const int reach = NeedsWith("nfor", params, frame).reach,
              shorter = NeedsWith("nfor", without, frame).reach;
    EXPECT_GT(reach, shorter) << "the lone samples' reach";
    // The right window's first column without that reach: the pair's right one inside.
    const int edge = tile - shorter;
    ASSERT_GT(edge - 7, 48 + kNforLoneReach) << "the pair is clear of the bright columns";
    Image &color = frame.layers["color"], &variance = frame.layers["variance"];
    for (auto [x, y] : {std::pair{edge + 1, 24}, std::pair{edge - 7, 24}, std::pair{300, 40},
                        std::pair{330, 20}, std::pair{342, 20}, std::pair{400, 6}})
        for (int c = 0; c < 3; ++c) {
            color.At(c, y, x) = 40.f;
            variance.At(c, y, x) = 1600.f;
        }
    auto [whole, tiled] = RunNforInTwoTiles(device, params, frame, tile);
    EXPECT_TRUE(ClampReadsTheLayer(whole));
    bool said = false;
    for (const std::string &line : whole.plan)
        said = said || line.find("lone samples: 2 pixels") != std::string::npos;
    EXPECT_TRUE(said) << "two isolated lone samples capped";
    ExpectSameBits(whole.image, tiled.image, "nfor tiled, lone samples");
}

// nfor beside a variance layer capped at --layer-noise-cap times the frame's own estimate:
// the tiled result is the untiled one bit for bit, where the clamp reads the layer (rare
// bright samples on the left) and where it reads the estimate (the passes run).
TEST_F(GpuTest, TiledRunNforLayerNoiseCapIsTheWholeFrames) {
    Device device = api::BorrowDevice(Ctx());
    const int width = 256, height = 48, tile = 128;
    for (int bright : {64, 0}) {
        SCOPED_TRACE(fmt::format("{} bright columns", bright));
        Frame frame = RareBrightLeftFrame(width, height, bright);
        Params params = {
            {"radius", 3}, {"pilot-bandwidths", std::string("none")}, {"layer-noise-cap", 3.f}};
        auto [whole, tiled] = RunNforInTwoTiles(device, params, frame, tile);
        EXPECT_EQ(ClampReadsTheLayer(whole), bright > 0);
        bool capped = false;
        for (const std::string &line : whole.plan)
            capped = capped || line.find("--layer-noise-cap") != std::string::npos;
        EXPECT_TRUE(capped);
        ExpectSameBits(whole.image, tiled.image, "nfor tiled, layer capped");
    }
}

// nfor beside a variance layer whose second pass reads it capped at --pilot-noise-cap times
// the frame's own estimate: the tiled result is the untiled one bit for bit.
TEST_F(GpuTest, TiledRunNforPilotNoiseCapIsTheWholeFrames) {
    Device device = api::BorrowDevice(Ctx());
    const int width = 256, height = 48, tile = 128;
    Frame frame = RareBrightLeftFrame(width, height, 0);
    Params params = {{"radius", 3}, {"pilot-noise-cap", 1.f}};
    auto [whole, tiled] = RunNforInTwoTiles(device, params, frame, tile);
    bool capped = false;
    for (const std::string &line : whole.plan)
        capped = capped || line.find("--pilot-noise-cap") != std::string::npos;
    EXPECT_TRUE(capped);
    ExpectSameBits(whole.image, tiled.image, "nfor tiled, second pass capped");
}

// bayes --zeros restore fills missed samples from their 3x3 neighbours before the filters:
// its halo is one pixel wider than --zeros denoise's, and says why.
TEST_F(GpuTest, TiledRunBayesRestoreHaloTakesTheFill) {
    Frame frame = RareBrightLeftFrame(64, 32, 8);
    int reach[2] = {};
    for (bool restore : {false, true}) {
        std::unique_ptr<api::FrontEnd> bayes = api::FindMethod("bayes")->make();
        bayes->Set("zeros", std::string(restore ? "restore" : "denoise"));
        api::Inputs inputs(frame, false, "bayes");
        api::TileNeeds needs = bayes->Tiling(Ctx(), inputs);
        reach[restore] = needs.reach;
        EXPECT_NE(needs.reachText.find(restore ? "3x3 fill 1" : "3x3 fill 0"),
                  std::string::npos)
            << needs.reachText;
    }
    EXPECT_EQ(reach[1], reach[0] + 1);
}

// Whether nfor's plan says its coarse pass ran, and that it read the whole frame's level.
bool CoarsePassRan(const Result &result, bool *wholeFrame = nullptr) {
    for (const std::string &line : result.plan)
        if (line.find("coarse pass: the frame denoised again") != std::string::npos) {
            if (wholeFrame)
                *wholeFrame = line.find("over the whole frame") != std::string::npos;
            return true;
        }
    return false;
}

// Whether nfor's plan says the run took the noisy radius's windows.
bool NoisyWindows(const Result &result) {
    for (const std::string &line : result.plan)
        if (line.find("(--noisy-radius") != std::string::npos) return true;
    return false;
}

// nfor's coarse pass runs where the frame's own noise, relative to relMSE's denominator in
// median, reaches --coarse-gate: its left 150 columns are noisy, the rest clean, so the
// frame takes the pass and the noisy radius's windows and the right window alone would not.
// Every tile reads the frame's level, and the tiled result is the untiled one bit for bit.
TEST_F(GpuTest, TiledRunNforCoarseGateDecidesOnceForTheFrame) {
    Device device = api::BorrowDevice(Ctx());
    const int width = 256, height = 40, tile = 128, noisy = 150;
    Frame frame;
    frame.path = "coarse gate left";
    frame.width = width, frame.height = height;
    Image color(width, height, 3), albedo(width, height, 3, 0.5f);
    std::mt19937_64 rng(SeedFromName("coarse gate left"));
    std::normal_distribution<double> noise;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
            for (int c = 0; c < 3; ++c) {
                double t = 0.3 + 0.2 * c + 0.2 * x / width, sigma = x < noisy ? 0.8 : 0.01;
                color.At(c, y, x) = float(std::max(0.0, t * (1 + sigma * noise(rng))));
            }
    frame.layers["color"] = std::move(color);
    frame.layers["albedo"] = std::move(albedo);
    Params params = {{"radius", 3},
                     {"noisy-radius", 4},
                     {"pilot-bandwidths", std::string("none")},
                     {"nfor-mean-radius", 0}};
    Result whole = RunWith(device, "nfor", params, frame, 0);
    Result tiled = RunWith(device, "nfor", params, frame, tile);
    EXPECT_TRUE(CoarsePassRan(whole));
    EXPECT_TRUE(NoisyWindows(whole));
    ExpectSameBits(whole.image, tiled.image, "nfor tiled, coarse gate");

    std::unique_ptr<api::FrontEnd> nfor = api::FindMethod("nfor")->make();
    for (const auto &[param, value] : params) nfor->Set(param, value);
    api::Inputs inputs(frame, false, "nfor");
    api::TileNeeds needs = nfor->Tiling(Ctx(), inputs);
    ASSERT_GT(tile - needs.reach, 2 * noisy - width) << "the right window is mostly clean";
    std::unique_ptr<api::FrontEnd> forTiles = nfor->ForTiles(Ctx(), inputs);
    api::Inputs window(inputs, tile - needs.reach, 0, width, height);
    Result alone = nfor->Run(Ctx(), window, RunOptions{});
    EXPECT_FALSE(CoarsePassRan(alone));
    EXPECT_FALSE(NoisyWindows(alone));
    bool wholeFrame = false;
    Result inTiles = forTiles->Run(Ctx(), window, RunOptions{});
    EXPECT_TRUE(CoarsePassRan(inTiles, &wholeFrame));
    EXPECT_TRUE(wholeFrame) << "the plan says the level is the frame's";
    EXPECT_TRUE(NoisyWindows(inTiles));
}

// nfor on a dark plain frame with a light (albedo 40) on a tile seam under a highlight line
// of hits (every third pixel 10, the gaps 0.05) that crosses the seam: the line spread, which
// reads its reach around each pixel, gives in tiles the untiled result bit for bit.
TEST_F(GpuTest, TiledRunNforLineSpreadAcrossTheSeamIsBitIdentical) {
    Device device = api::BorrowDevice(Ctx());
    const int width = 192, height = 48, tile = 64;
    Frame frame = RenderedFrame(width, height, render::kLayersAll);
    frame.layers.erase("variance");
    Image &color = frame.layers.at("color");
    Image &albedo = frame.layers.at("albedo");
    for (float &v : color.data) v *= 0.02f;
    const int lx = 64, ly = 30;
    for (int x = lx - 30; x < lx + 30; ++x) {
        const int y = ly - 4 + (x - lx) / 6;
        for (int c = 0; c < 3; ++c) color.At(c, y, x) = x % 3 == 0 ? 10.f : 0.05f;
    }
    for (int c = 0; c < 3; ++c) color.At(c, ly, lx) = 0.5f, albedo.At(c, ly, lx) = 40.f;
    Params params = {{"radius", 3}};
    Result whole = RunWith(device, "nfor", params, frame, 0);
    Result tiled = RunWith(device, "nfor", params, frame, tile);
    EXPECT_EQ(tiled.plan[0].find("1 tile(s)"), std::string::npos) << tiled.plan[0];
    bool spread = false;
    for (const std::string &line : whole.plan)
        spread = spread || (line.find("line spread: ") != std::string::npos &&
                            line.find("line spread: 0 ") == std::string::npos);
    EXPECT_TRUE(spread) << "some pixels of the line gave";
    ExpectSameBits(whole.image, tiled.image, "nfor tiled, line spread");
}

// nfor's halo grows by the line spread's reach on a frame with a light (an albedo channel
// above the gate, beside a NaN one too), and says so; not on a frame without one. The glint
// floor and the glint bands (off here: their gate is such a light too) grow it further, the
// bands by their reach.
TEST_F(GpuTest, TiledRunNforHaloTakesTheLineSpreadNearALight) {
    int reach[3] = {}, floored[3] = {}, banded[3] = {}, rimmed[3] = {};
    for (int lit : {0, 1, 2}) {
        SCOPED_TRACE(fmt::format("light {}", lit));
        Frame frame = RenderedFrame(64, 32, render::kLayersAll);
        frame.layers.erase("variance");
        // 16 samples a pixel, stated as Cycles states them: the rim hits' pass may run.
        frame.layers.erase("spp");
        frame.metadata["cycles.ViewLayer.samples"] = "16";
        Image &albedo = frame.layers.at("albedo");
        if (lit > 0)
            for (int c = 0; c < 3; ++c) albedo.At(c, 16, 32) = 40.f;
        if (lit == 2) albedo.At(0, 16, 32) = std::nanf("");
        api::TileNeeds needs = NeedsWith(
            "nfor", {{"glint-noise", 0.f}, {"glint-band-radius", 0}, {"rim-hits", 0}}, frame);
        reach[lit] = needs.reach;
        floored[lit] =
            NeedsWith("nfor", {{"glint-band-radius", 0}, {"rim-hits", 0}}, frame).reach;
        banded[lit] = NeedsWith("nfor", {{"glint-noise", 0.f}, {"rim-hits", 0}}, frame).reach;
        rimmed[lit] =
            NeedsWith("nfor", {{"glint-noise", 0.f}, {"glint-band-radius", 0}}, frame).reach;
        const std::string text = fmt::format("{} for the line spread", kNforLineReach);
        EXPECT_EQ(needs.reachText.find(text) != std::string::npos, lit > 0) << needs.reachText;
    }
    EXPECT_EQ(reach[1], reach[0] + kNforLineReach);
    EXPECT_EQ(reach[2], reach[1]);
    EXPECT_EQ(floored[0], reach[0]);
    EXPECT_GT(floored[1], reach[1]);
    EXPECT_EQ(floored[2], floored[1]);
    EXPECT_EQ(banded[0], reach[0]);
    EXPECT_EQ(banded[1], reach[1] + kNforGlintBandReach);
    // The rim hits': a core's and a ground's reach.
    EXPECT_EQ(rimmed[0], reach[0]);
    EXPECT_EQ(rimmed[1], reach[1] + 2 * NforRimSettings{}.radius);
}

// nfor on a plain frame over a transparent background (no variance layer, an alpha with
// partly covered pixels, colour and features premultiplied): the division by alpha, the
// specks' clamp (which reads the fits' output of its neighbours) and the weak emitters'
// pass give in tiles the untiled result bit for bit.
TEST_F(GpuTest, TiledRunNforPlainFrameWithAlphaIsBitIdentical) {
    Device device = api::BorrowDevice(Ctx());
    const int width = 320, height = 40, tile = 64;
    Frame frame = RenderedFrame(width, height, render::kLayersAll);
    frame.layers.erase("variance");
    Image alpha(width, height, 1);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            // Covered left of a slanted edge, empty right of it, 16 samples' coverage on it.
            double covered = std::clamp((0.6 * width + 0.5 * y - x) / 4.0, 0.0, 1.0);
            float a = float(std::round(16 * covered) / 16);
            alpha.At(0, y, x) = a;
            for (const char *layer : {"color", "albedo", "normal", "depth"}) {
                auto it = frame.layers.find(layer);
                if (it == frame.layers.end()) continue;
                for (int c = 0; c < it->second.channels; ++c) it->second.At(c, y, x) *= a;
            }
        }
    frame.layers["alpha"] = alpha;
    Params params = {{"radius", 3}};
    Result whole = RunWith(device, "nfor", params, frame, 0);
    Result tiled = RunWith(device, "nfor", params, frame, tile);
    ASSERT_FALSE(tiled.plan.empty());
    EXPECT_NE(tiled.plan[0].find("bit for bit"), std::string::npos) << tiled.plan[0];
    EXPECT_EQ(tiled.plan[0].find("1 tile(s)"), std::string::npos) << tiled.plan[0];
    bool divided = false;
    for (const std::string &line : whole.plan)
        divided = divided || line.find("partly covered pixels") != std::string::npos;
    EXPECT_TRUE(divided) << "the plan names the pixels divided by their alpha";
    ExpectSameBits(whole.image, tiled.image, "nfor tiled with alpha");
}

// Noise for an albedo (reflectances drawn per pixel and channel, seeded by `seed`, row by
// row) in the columns `column` takes: the colour does not follow it.
void NoisyAlbedo(Image *albedo, const std::string &seed,
                 const std::function<bool(int)> &column) {
    std::mt19937_64 rng(SeedFromName(seed));
    std::uniform_real_distribution<float> reflectance(0.05f, 0.95f);
    for (int y = 0; y < albedo->height; ++y)
        for (int x = 0; x < albedo->width; ++x)
            if (column(x))
                for (int c = 0; c < 3; ++c) albedo->At(c, y, x) = reflectance(rng);
}

// Bands of 24 columns either side of each seam of tiles `tile` wide.
std::function<bool(int)> SeamBands(int tile) {
    return [tile](int x) { return x % tile < 24 || x % tile >= tile - 24; };
}

// nfor on a rendered frame whose albedo is noise (random per pixel and channel, which the
// colour does not follow) in bands across the tile seams: the distance's trust, which reads
// the clamped colour and albedo of the 8 neighbours, gives in tiles the untiled result bit
// for bit. The frame is wide enough that the middle tiles' windows (the tile and its halo)
// hold only part of it.
TEST_F(GpuTest, TiledRunNforNoisyAlbedoAcrossTheSeamIsBitIdentical) {
    Device device = api::BorrowDevice(Ctx());
    const int width = 640, height = 24, tile = 168;
    Frame frame = RenderedFrame(width, height, render::kLayersAll);
    frame.layers.erase("variance");
    NoisyAlbedo(&frame.layers.at("albedo"), "tiled noisy albedo", SeamBands(tile));
    // The plain frame's wide second pass runs too, over windows that fit the tiles' halo.
    Params params = {{"radius", 3}, {"noisy-radius", 0}, {"plain-wide-radius", 4}};
    Result whole = RunWith(device, "nfor", params, frame, 0);
    Result tiled = RunWith(device, "nfor", params, frame, tile);
    ASSERT_FALSE(tiled.plan.empty());
    EXPECT_EQ(tiled.plan[0].find("1 tile(s)"), std::string::npos) << tiled.plan[0];
    const int halo = HaloOf(tiled);
    EXPECT_TRUE(halo > 0 && halo < tile && 2 * tile + halo < width) << tiled.plan[0];
    bool untrusted = false;
    for (const std::string &line : whole.plan)
        untrusted = untrusted || (line.find("whose albedo is noise") != std::string::npos &&
                                  line.find(": 0 pixels") == std::string::npos);
    EXPECT_TRUE(untrusted) << "the plan counts pixels whose albedo is noise";
    ExpectSameBits(whole.image, tiled.image, "nfor tiled, a noisy albedo across the seams");
}

// nfor's glint floor: a noisy albedo across the seams with glints (an albedo channel above
// kNforGlintAlbedo) just either side of one and one 16 pixels off the other: the halo takes
// the floor's gate and its guard, the result is the untiled one bit for bit, and the reach
// and memory grow only on a frame with a glint.
TEST_F(GpuTest, TiledRunNforGlintFloorAcrossTheSeamIsBitIdentical) {
    Device device = api::BorrowDevice(Ctx());
    const int width = 640, height = 24, tile = 160;
    Frame frame = RenderedFrame(width, height, render::kLayersAll);
    frame.layers.erase("variance");
    Image &albedo = frame.layers.at("albedo");
    NoisyAlbedo(&albedo, "tiled glint floor", SeamBands(tile));
    // The other reaches at their smallest (no line spread, local means or pilot), so that a
    // halo short of the floor's gate shows in the bits.
    Params params = {{"radius", 3},
                     {"line-spread", 0.f},
                     {"nfor-mean-radius", 0},
                     {"pilot-bandwidths", std::string("none")}};
    const api::TileNeeds plain = NeedsWith("nfor", params, frame);
    albedo.At(0, 12, tile - 2) = 2 * kNforGlintAlbedo;
    albedo.At(1, 5, tile + 1) = 2 * kNforGlintAlbedo;
    albedo.At(2, 18, 2 * tile + kNforGlintReach) = 2 * kNforGlintAlbedo;
    const api::TileNeeds glints = NeedsWith("nfor", params, frame);
    EXPECT_GT(glints.reach, plain.reach);
    EXPECT_EQ(glints.bytesPerPixel, plain.bytesPerPixel + 8.0);
    Result whole = RunWith(device, "nfor", params, frame, 0);
    Result tiled = RunWith(device, "nfor", params, frame, tile);
    ASSERT_FALSE(tiled.plan.empty());
    EXPECT_EQ(tiled.plan[0].find("1 tile(s)"), std::string::npos) << tiled.plan[0];
    bool floored = false;
    for (const std::string &line : whole.plan)
        floored = floored || (line.find("glint floor:") != std::string::npos &&
                              line.find(" at 0 pixels") == std::string::npos);
    EXPECT_TRUE(floored) << "the plan counts the pixels the floor raised";
    ExpectSameBits(whole.image, tiled.image, "nfor tiled, the glint floor across the seams");
}

// nfor's glint floor on a partly covered pixel whose straight albedo (albedo / alpha) passes
// the gate, beside a seam, with no albedo above kNforGlintAlbedo as written: the reach grows
// all the same and the tiled result is the untiled one bit for bit.
TEST_F(GpuTest, TiledRunNforGlintFloorCountsAPartlyCoveredGlint) {
    Device device = api::BorrowDevice(Ctx());
    const int width = 320, height = 24, tile = 160;
    Frame frame = RenderedFrame(width, height, render::kLayersAll);
    frame.layers.erase("variance");
    frame.layers["alpha"] = Image(width, height, 1);
    Image &albedo = frame.layers.at("albedo"), &alpha = frame.layers.at("alpha");
    std::fill(alpha.data.begin(), alpha.data.end(), 1.f);
    NoisyAlbedo(&albedo, "tiled glint floor, partly covered",
                [tile](int x) { return x >= tile - 24 && x < tile + 24; });
    Params params = {{"radius", 3},
                     {"line-spread", 0.f},
                     {"nfor-mean-radius", 0},
                     {"pilot-bandwidths", std::string("none")}};
    const api::TileNeeds plain = NeedsWith("nfor", params, frame);
    alpha.At(0, 12, tile + 2) = 0.5f;
    albedo.At(0, 12, tile + 2) = 0.625f * kNforGlintAlbedo;
    const api::TileNeeds glints = NeedsWith("nfor", params, frame);
    EXPECT_GT(glints.reach, plain.reach);
    Result whole = RunWith(device, "nfor", params, frame, 0);
    Result tiled = RunWith(device, "nfor", params, frame, tile);
    ASSERT_FALSE(tiled.plan.empty());
    EXPECT_EQ(tiled.plan[0].find("1 tile(s)"), std::string::npos) << tiled.plan[0];
    ExpectSameBits(whole.image, tiled.image, "nfor tiled, a partly covered glint by a seam");
}

// nfor's memory per pixel counts the trust plane (one float) where the distance trusts an
// albedo, and not with --albedo-noise 0.
TEST_F(GpuTest, TiledRunNforNeedsCountTheTrustPlane) {
    Frame frame = RenderedFrame(32, 16, render::kLayersAll);
    api::TileNeeds on = NeedsWith("nfor", {}, frame),
                   off = NeedsWith("nfor", {{"albedo-noise", 0.f}}, frame);
    EXPECT_EQ(on.bytesPerPixel, off.bytesPerPixel + 4.0);
    EXPECT_EQ(on.reach, off.reach);
}

// Whether a plan holds a line (the tiled run's: of its first tile) on the clamp's light.
bool ClampLightRan(const Result &result) {
    for (const std::string &line : result.plan)
        if (line.find("the clamp's light: ") != std::string::npos) return true;
    return false;
}

// nfor's clamp's light (a plain frame, the coarse pass shut) over a transparent
// background: glints the clamp takes straddle the seam and line a hard edge (empty
// pixels, alpha 0) in the left tile, whose window holds no partly covered pixel; a soft
// edge (partly covered pixels) lies in the right tile. The pass keeps the clamped colour
// only near partly covered pixels, so the left window run without the alpha keeps what
// the whole frame's does, and the tiled result is the untiled one bit for bit.
TEST_F(GpuTest, TiledRunNforClampLightAcrossTheSeamIsBitIdentical) {
    Device device = api::BorrowDevice(Ctx());
    const int width = 400, height = 32, tile = 200, hard = 24, soft = width - 40;
    Frame frame;
    frame.path = "clamp light across a seam";
    frame.width = width, frame.height = height;
    Image color(width, height, 3), albedo(width, height, 3), alpha(width, height, 1);
    std::mt19937_64 rng(SeedFromName(frame.path));
    std::normal_distribution<double> noise(0, 0.05);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            // Empty left of the hard edge, covered in part over 8 pixels from the soft one.
            double a = x < hard ? 0 : std::clamp(1 - (x - soft) / 8.0, 0.0, 1.0);
            bool glints = x < hard + 24 || std::abs(x - tile) < 48;
            double gain = glints && rng() % 6 == 0 ? 8 : 1;
            alpha.At(0, y, x) = float(a);
            for (int c = 0; c < 3; ++c) {
                albedo.At(c, y, x) = float(0.5 * a);
                double t = 0.2 + 0.1 * c + 0.1 * x / width;
                color.At(c, y, x) = float(std::max(0.0, a * t * (1 + noise(rng)) * gain));
            }
        }
    frame.layers["color"] = std::move(color);
    frame.layers["albedo"] = std::move(albedo);
    frame.layers["alpha"] = alpha;
    Params params = {
        {"radius", 3}, {"pilot-bandwidths", std::string("none")}, {"coarse-gate", 0.f}};
    auto [whole, tiled] = RunNforInTwoTiles(device, params, frame, tile);
    EXPECT_TRUE(ClampLightRan(whole));
    EXPECT_TRUE(ClampLightRan(tiled));
    ExpectSameBits(whole.image, tiled.image, "nfor tiled, the clamp's light");

    // The left window holds no partly covered pixel, the right one the soft edge.
    api::TileNeeds needs = NeedsWith("nfor", params, frame);
    ASSERT_LE(tile + needs.reach, soft);
}

// nfor (radius 3, no pilot pass, no coarse pass) on a plain seam frame whole and in two
// tiles: the pass whose plan line holds `ran` ran on the whole frame, and the tiles give the
// whole frame's bits.
void ExpectPlainPassTiledAsWhole(Device &device, const Frame &frame, int tile,
                                 const std::string &ran, const std::string &what,
                                 const Params &extra = {}) {
    Params params = {
        {"radius", 3}, {"pilot-bandwidths", std::string("none")}, {"coarse-gate", 0.f}};
    params.insert(params.end(), extra.begin(), extra.end());
    auto [whole, tiled] = RunNforInTwoTiles(device, params, frame, tile);
    bool found = false;
    for (const std::string &line : whole.plan) found |= line.find(ran) != std::string::npos;
    EXPECT_TRUE(found) << what;
    ExpectSameBits(whole.image, tiled.image, what);
}

// A plain 400x32 frame for a two-tile seam at 200: colour level(y, x) x (1 + 5% seeded
// Gaussian noise, seeded by `path`), a grey albedo of 0.5.
Frame PlainSeamFrame(const std::string &path, const std::function<double(int, int)> &level) {
    const int width = 400, height = 32;
    Frame frame;
    frame.path = path;
    frame.width = width, frame.height = height;
    Image color(width, height, 3), albedo(width, height, 3, 0.5f);
    std::mt19937_64 rng(SeedFromName(frame.path));
    std::normal_distribution<double> noise(0, 0.05);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
            for (int c = 0; c < 3; ++c)
                color.At(c, y, x) = float(level(y, x) * (1 + noise(rng)));
    frame.layers["color"] = std::move(color);
    frame.layers["albedo"] = std::move(albedo);
    return frame;
}

// nfor's rare light (a plain frame, the coarse pass shut): a cluster of hits the firefly
// clamp cuts far down, each within 6 of two others, on both sides of the seam, and one lone:
// a source's others and its Gaussian reach across the seam, so the tiled result is the
// untiled one bit for bit.
TEST_F(GpuTest, TiledRunNforRareLightAcrossTheSeamIsBitIdentical) {
    Device device = api::BorrowDevice(Ctx());
    const int tile = 200;
    Frame frame = PlainSeamFrame("rare light across a seam", [](int, int) { return 0.02; });
    Image &color = frame.layers.at("color");
    for (auto [y, x] : {std::pair{14, 197}, {16, 202}, {19, 199}, {12, 203}, {8, 60}})
        for (int c = 0; c < 3; ++c) color.At(c, y, x) = 4.f;
    ExpectPlainPassTiledAsWhole(device, frame, tile, "rare light: 4 pixels",
                                "nfor tiled, the rare light");
    // The widest pairing, the clamp's light's own reach short: hits 16 apart across the
    // seam pair, and the tiles give the whole frame's bits. (The halo's other terms hold
    // more than this pass reads here: a reach short of the pair's would pass too.)
    Frame wide =
        PlainSeamFrame("rare light paired across a seam", [](int, int) { return 0.02; });
    Image &hits = wide.layers.at("color");
    for (auto [y, x] : {std::pair{14, 190}, {14, 206}, {20, 198}, {8, 60}})
        for (int c = 0; c < 3; ++c) hits.At(c, y, x) = 4.f;
    ExpectPlainPassTiledAsWhole(
        device, wide, tile, "rare light: 3 pixels", "nfor tiled, the rare light paired over 16",
        {{"clamp-light-radius", 1}, {"clamp-light-fine", 0}, {"rare-light-pair", 16}});
}

// The glint bands' pass across a tile seam: a broken band beside a glint on the seam comes out
// with the whole frame's bits (the halo holds the glints' reach).
TEST_F(GpuTest, TiledRunNforGlintBandsAcrossTheSeamIsBitIdentical) {
    Device device = api::BorrowDevice(Ctx());
    const int tile = 200;
    Frame frame = PlainSeamFrame("glint bands across a seam", [](int y, int x) {
        return y == 16 ? (x % 2 ? 1.0 : 0.6) : 0.05;
    });
    for (int c = 0; c < 3; ++c) frame.layers.at("albedo").At(c, 6, 208) = 20.f;
    ExpectPlainPassTiledAsWhole(device, frame, tile,
                                "glint bands:", "nfor tiled, the glint bands");
}

// The rim hits across a tile seam: a light whose core lies left of the seam and whose rim
// hits (one of 16 samples) lie on both sides comes out with the whole frame's bits (the
// halo holds the core's and the ground's reach).
TEST_F(GpuTest, TiledRunNforRimHitsAcrossTheSeamIsBitIdentical) {
    Device device = api::BorrowDevice(Ctx());
    const int tile = 200;
    Frame frame = PlainSeamFrame("rim hits across a seam", [](int, int) { return 0.05; });
    frame.metadata["cycles.ViewLayer.samples"] = "16";
    Image &color = frame.layers.at("color"), &albedo = frame.layers.at("albedo");
    for (int y = 14; y <= 16; ++y)
        for (int x = 197; x <= 199; ++x)
            for (int c = 0; c < 3; ++c) color.At(c, y, x) = albedo.At(c, y, x) = 320.f;
    for (auto [y, x] : {std::pair{13, 199}, {15, 200}, {17, 198}, {16, 201}})
        for (int c = 0; c < 3; ++c) color.At(c, y, x) = albedo.At(c, y, x) = 20.f;
    ExpectPlainPassTiledAsWhole(device, frame, tile, "rim hits:", "nfor tiled, the rim hits");
}

// nfor's halo holds the clamp's light's reach only where the pass runs: on a plain frame
// the coarse pass leaves; not beside a variance layer, nor where the coarse pass runs
// (whose half-resolution run has no such pass), whose reach is then doubled.
TEST_F(GpuTest, TiledRunNforHaloHoldsTheClampLightOnlyWhereItRuns) {
    Frame layered = RareBrightLeftFrame(64, 32, 16), plain = layered;
    plain.layers.erase("variance");
    auto reach = [&](const Frame &frame, const Params &params) {
        return NeedsWith("nfor", params, frame).reach;
    };
    Params off = {{"clamp-light-radius", 0}};
    Params plainOn = {{"coarse-gate", 0.f}}, plainOff = {{"coarse-gate", 0.f}};
    plainOff.push_back(off[0]);
    // 4 x 16 + 4 x 2 for the default tents (the means' and the gain's average), 4 for the
    // guard.
    EXPECT_EQ(reach(plain, plainOn) - reach(plain, plainOff), 76);
    EXPECT_EQ(reach(layered, {}), reach(layered, off)) << "beside a variance layer";
    Params coarse = {{"nfor-coarse", true}}, coarseOff = coarse;
    coarseOff.push_back(off[0]);
    EXPECT_EQ(reach(plain, coarse), reach(plain, coarseOff)) << "the coarse pass runs";
    EXPECT_EQ(reach(layered, coarse), reach(layered, coarseOff)) << "coarse, a layer";
}

// The wavelet methods' statistics are frame-wide: in tiles they complete with a finite
// image of the frame's size, the plan says the result differs and why, and the difference
// from the untiled result stays within the bound measured on this frame (relative RMS over
// the pixels, and the largest relative difference of one value; measured 0.0084 and 0.12
// for awr (5 levels in a tile, 8 whole), 0.021 and 0.44 for bayes (haar, halo 15: each
// tile takes its own band noise from the variance layer and its own log floor).
TEST_F(GpuTest, TiledRunWaveletsDifferWithinBound) {
    Device device = api::BorrowDevice(Ctx());
    Frame frame = RenderedFrame(203, 151, render::kLayersAll);
    struct Bound {
        const char *method;
        double rms, largest;
        Params params;
        int tile;
    };
    for (const Bound &bound :
         {Bound{"awr", 0.02, 0.3, {}, 64}, Bound{"bayes", 0.04, 0.8, {}, 64}}) {
        const char *name = bound.method;
        Result whole = RunWith(device, name, bound.params, frame, 0);
        Result tiled = RunWith(device, name, bound.params, frame, bound.tile);
        ASSERT_TRUE(whole.image.SameShape(tiled.image)) << name;
        ASSERT_FALSE(tiled.plan.empty()) << name;
        EXPECT_NE(tiled.plan[0].find("differs from the untiled one"), std::string::npos)
            << name << ": " << tiled.plan[0];
        double sum = 0, largest = 0;
        for (size_t i = 0; i < whole.image.data.size(); ++i) {
            double a = whole.image.data[i], b = tiled.image.data[i];
            ASSERT_TRUE(std::isfinite(b)) << name;
            double rel = std::abs(a - b) / (std::abs(a) + 0.01);
            sum += rel * rel;
            largest = std::max(largest, rel);
        }
        double rms = std::sqrt(sum / double(whole.image.data.size()));
        std::printf("%s tiled vs untiled: relative RMS %.4g, largest %.4g\n", name, rms,
                    largest);
        EXPECT_LE(rms, bound.rms) << name;
        EXPECT_LE(largest, bound.largest) << name;
    }
}

// auto in tiles (its candidates' widest reach and its box radius as halo): the plumbing
// runs, the plan says the result may differ, and the image is finite. This frame is
// narrower than auto's halo (awr's alone is 2 x 4 x 31 at 5 levels of CDF 9/7), so every
// window is the whole frame and the result must be the untiled one; a frame wide enough
// to differ is too slow for the suite (the difference is not measured).
TEST_F(GpuTest, TiledRunAutoCompletesCloseToUntiled) {
    Device device = api::BorrowDevice(Ctx());
    Frame frame = RenderedFrame(70, 54, render::kLayersAll);
    Result whole = RunWith(device, "auto", {}, frame, 0, {"auto.map"});
    Result tiled = RunWith(device, "auto", {}, frame, 32, {"auto.map"});
    ASSERT_TRUE(whole.image.SameShape(tiled.image));
    ASSERT_FALSE(tiled.plan.empty());
    EXPECT_NE(tiled.plan[0].find("differs from the untiled one"), std::string::npos)
        << tiled.plan[0];
    double sum = 0, norm = 0;
    for (size_t i = 0; i < whole.image.data.size(); ++i) {
        ASSERT_TRUE(std::isfinite(tiled.image.data[i]));
        double d = tiled.image.data[i] - whole.image.data[i];
        sum += d * d;
        norm += double(whole.image.data[i]) * whole.image.data[i];
    }
    double rel = std::sqrt(sum / norm);
    std::printf("auto tiled vs untiled: relative RMS %.4g\n", rel);
    EXPECT_EQ(rel, 0.0);
    // The map asked for is put together from the tiles' maps.
    ASSERT_EQ(whole.stages.size(), 1u);
    ASSERT_EQ(tiled.stages.size(), 1u);
    EXPECT_EQ(tiled.stages[0].name, "auto.map");
    ExpectSameBits(whole.stages[0].image, tiled.stages[0].image, "auto's map");
}

// RHF's distance strips hold every offset of a whole row: a frame too wide for one row of
// them (with the terms' apron) in a binding is cut into narrower tiles rather than refused,
// even where its pixels would fit (3200 x 2 with a 33 x 33 search window: 3147 at most), and
// the memory a run needs whatever its size counts such a row for a window, not the frame
// (8192 x 1 with a 41 x 41 window: 1.5 GB counted for the whole row).
TEST_F(GpuTest, TiledRunCutsFramesTooWideForRhfStrips) {
    Device device = api::BorrowDevice(Ctx());
    for (auto [width, height, searchHalf] :
         {std::tuple{3200, 2, 16}, std::tuple{8192, 1, 20}}) {
        SCOPED_TRACE(fmt::format("{}x{}, search half-window {}", width, height, searchHalf));
        Frame frame = RandomFrame(width, height, SeedFromName("rhf wide strips"));
        Result result;
        ASSERT_NO_THROW(result =
                            RunWith(device, "rhf", {{"search-half", searchHalf}}, frame, 0));
        ASSERT_FALSE(result.plan.empty());
        EXPECT_NE(result.plan[0].find("tiled:"), std::string::npos) << result.plan[0];
        EXPECT_EQ(result.image.width, width);
        EXPECT_EQ(result.image.height, height);
    }
}

// The planner: a frame that fits runs whole; one whose largest buffer exceeds a binding is
// cut into tiles whose windows fit it, aligned, covering the frame.
TEST_F(GpuTest, TiledRunPlanCutsOnlyWhatDoesNotFit) {
    api::TileNeeds needs;
    needs.reach = 10;
    needs.align = 4;
    needs.bindingBytesPerPixel = 4;
    double bindingPixels = double(Ctx().BindingBytes()) / 4;
    int side = int(std::sqrt(bindingPixels) / 2);
    EXPECT_EQ(api::PlanTiles(Ctx(), needs, side, side, 0).tileWidth, 0);
    int big = int(std::sqrt(bindingPixels) * 1.5);
    api::TilePlan plan = api::PlanTiles(Ctx(), needs, big, big, 0);
    ASSERT_GT(plan.tileWidth, 0);
    ASSERT_GT(plan.tileHeight, 0);
    EXPECT_EQ(plan.tileWidth % 4, 0);
    EXPECT_EQ(plan.tileHeight % 4, 0);
    double windowPixels =
        double(std::min(big, plan.tileWidth + 20)) * std::min(big, plan.tileHeight + 20);
    EXPECT_LE(windowPixels, bindingPixels);
    EXPECT_FALSE(plan.why.empty());
    EXPECT_EQ(api::PlanTiles(Ctx(), needs, 9, 9, 5).tileWidth, 8);  // forced, aligned up
}

// The memory budget: a method that tiles reproduce runs whole up to three quarters of the
// device's memory (so a frame between half and three quarters, which tiled before, does not
// tile) and tiles beyond; one that tiles change runs whole up to all of it.
TEST_F(GpuTest, TiledRunPlanBudgetIsThreeQuartersForLocalMethods) {
    const double device = double(Ctx().Info().deviceLocalBytes);
    api::TileNeeds needs;
    needs.reach = 4;
    needs.align = 1;
    EXPECT_EQ(api::TileMemoryBudget(Ctx(), needs), device * 3 / 4);
    // A 1024x1024 frame whose memory is 0.7 of the device's (no binding limit): whole.
    const int w = 1024;
    needs.bytesPerPixel = device * 0.7 / (double(w) * w);
    EXPECT_EQ(api::PlanTiles(Ctx(), needs, w, w, 0).tileWidth, 0);
    // 0.8 of it: tiles whose windows fit three quarters.
    const int h = w * 8 / 7;
    api::TilePlan plan = api::PlanTiles(Ctx(), needs, w, h, 0);
    ASSERT_GT(plan.tileWidth, 0);
    double windowPixels = double(std::min(w, plan.tileWidth + 2 * needs.reach)) *
                          std::min(h, plan.tileHeight + 2 * needs.reach);
    EXPECT_LE(needs.bytesPerPixel * windowPixels, device * 3 / 4);
    // A method that tiles change: all of the device's memory.
    needs.notLocal = "its output changes with the tiles";
    EXPECT_EQ(api::TileMemoryBudget(Ctx(), needs), device);
    EXPECT_EQ(api::PlanTiles(Ctx(), needs, w, h, 0).tileWidth, 0);
}

// pivot binds each channel's fits and packed z, s, nu on their own: an RGB frame tiles only
// where its largest binding, a channel's fit buffer (8 floats a pixel), exceeds the
// device's, so a 2560x1440 frame runs whole within lavapipe's 128 MiB, and one 4 times the
// size of 1920x1080 does not (where the memory allows it whole, which on lavapipe it does not:
// the binding's part is checked with the memory out of play).
TEST_F(GpuTest, TiledRunPlanPivotBindsAChannelsFitsAlone) {
    std::unique_ptr<api::FrontEnd> pivot = api::FindMethod("pivot")->make();
    Frame frame = RandomFrame(16, 16, 7);
    api::Inputs inputs(frame, false, "pivot");
    api::TileNeeds needs = pivot->Tiling(Ctx(), inputs);
    EXPECT_EQ(needs.bindingBytesPerPixel, PIVOT_PLANES_PER_BUFFER * 4);
    const double binding = double(Ctx().BindingBytes());
    for (auto [w, h] : {std::pair{1920, 1080}, std::pair{2560, 1440}, std::pair{3840, 2160}}) {
        const double pixels = double(w) * h;
        if (needs.fixedBytes + needs.bytesPerPixel * pixels >
            api::TileMemoryBudget(Ctx(), needs))
            continue;  // the device's memory, not a binding, decides
        api::TilePlan plan = api::PlanTiles(Ctx(), needs, w, h, 0);
        EXPECT_EQ(plan.tileWidth == 0, PIVOT_PLANES_PER_BUFFER * 4 * pixels <= binding)
            << w << "x" << h << ": " << plan.why;
    }
    // A 16:9 frame a tenth above what one binding of the packed z, s, nu of all 3 channels
    // (48 B a pixel) held, 2.8 Mpixels on lavapipe: it runs whole, within the memory budget.
    const double above = 1.1 * binding / 48;
    const int w = int(std::sqrt(above * 16 / 9)), h = int(std::sqrt(above * 9 / 16));
    const double pixels = double(w) * h;
    ASSERT_GT(48 * pixels, binding);
    ASSERT_LE(needs.fixedBytes + needs.bytesPerPixel * pixels,
              api::TileMemoryBudget(Ctx(), needs));
    api::TilePlan plan = api::PlanTiles(Ctx(), needs, w, h, 0);
    EXPECT_EQ(plan.tileWidth, 0) << w << "x" << h << ": " << plan.why;
    // With the memory out of play, a frame a tenth above a channel's fit buffer's binding
    // tiles, each window's fit buffer within one binding.
    needs.fixedBytes = needs.bytesPerPixel = 0;
    const double over = 1.1 * binding / (PIVOT_PLANES_PER_BUFFER * 4);
    const int bigW = int(std::sqrt(over * 16 / 9)), bigH = int(std::sqrt(over * 9 / 16));
    plan = api::PlanTiles(Ctx(), needs, bigW, bigH, 0);
    ASSERT_GT(plan.tileWidth, 0) << bigW << "x" << bigH;
    const int reach = 2 * needs.reach + needs.align - 1;
    const double window = double(std::min(bigW, plan.tileWidth + reach)) *
                          std::min(bigH, plan.tileHeight + reach);
    EXPECT_LE(PIVOT_PLANES_PER_BUFFER * 4 * window, binding) << plan.why;
}

}  // namespace
}  // namespace mcd::test
