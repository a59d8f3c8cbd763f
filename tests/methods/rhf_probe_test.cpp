// auto's probe of rhf (FrontEnd::ForProbe): it cuts the pixels the run cut (lights' rims,
// bright clusters, and on half0 the lone spikes), each from the probe's own colour, and gives
// the rims and clusters the probe's input back; a perturbation that would flip a cut does not,
// and on the run's own colour the probe is the run, bit for bit, whole and in tiles.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "harness/compare.h"
#include "harness/frames.h"
#include "harness/gpu_fixture.h"
#include "harness/inputs.h"
#include "host/api/device.h"
#include "host/api/front_end.h"
#include "host/api/registry.h"
#include "host/api/tiled_run.h"
#include "host/common/local_mean.h"
#include "host/methods/run_memo.h"
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

// The stage `name` of `stages` (empty if none).
Image StageOf(const std::vector<Stage> &stages, const std::string &name) {
    for (const Stage &stage : stages)
        if (stage.name == name) return stage.image;
    return Image();
}
Image StageOf(const Result &result, const std::string &name) {
    return StageOf(result.stages, name);
}

// A wall of 16 samples a pixel with a light's reflection of 4 pixels (1, 2, 1 and 3 samples
// of 16 at 300 a channel, cut whole as a bright cluster) and a 3x3 light whose edge a wide
// pixel filter spread, with a rim one sample saw beyond it (cut as a light's rim), and a
// firefly one sample of 16 saw at 40 (cut as a lone spike), and a caustic of 5 pixels with its
// corner at (36, 8), split at its middle (cut whole as bridged; rhf_clusters_test.cpp).
constexpr int kCausticX = 36, kCausticY = 8;
Frame ReflectionFrame() {
    const int w = 48, h = 40;
    std::mt19937_64 rng(SeedFromName("rhf probe cuts"));
    std::uniform_real_distribution<double> wallSample(0.005, 0.0216);
    auto reflection = [](int x, int y) { return ReflectionSamplesAt(x - 12, y - 12); };
    // The caustic's bright samples of 16 and their value, and its dim pixel's samples.
    auto caustic = [](int dx, int dy, int s) {
        const int samples = dy == 2 && dx == 0 ? 2 : dy == 1 || (dy == 0 && dx == 2) ? 1 : 0;
        const double value = dy == 0   ? 12.7
                             : dy == 2 ? 9.6
                             : dx == 0 ? 39.3
                             : dx == 1 ? 20.6
                                       : 16.5;
        if (dx < 0 || dy < 0 || dx > 2 || dy > 2) return -1.0;
        if (s < samples) return value;
        return dy == 0 && dx == 1 ? 0.1 : -1.0;
    };
    auto sample = [&](int x, int y, int s) {
        if (s < reflection(x, y)) return 300.0;
        if (const double c = caustic(x - kCausticX, y - kCausticY, s); c >= 0) {
            wallSample(rng);  // drawn all the same: the other pixels keep their samples
            return c;
        }
        if (x == 6 && y == 30 && s == 0) return 40.0;
        const bool rows = y >= 26 && y <= 28;
        if (rows && x >= 30 && x <= 32) return 10.0;
        if (rows && (x == 29 || x == 33) && s < 8) return 10.0;
        if (y == 27 && x == 28 && s == 0) return 10.0;
        return wallSample(rng);
    };
    return SampledFrame(w, h, sample);
}

// The run's colour with two of the reflection's pixels, the firefly and the caustic's middle
// and top right pixels at their wall's level: the probe's noise there would leave a cluster
// of 2, which is not cut, no firefly, and of the caustic a pair and a lone pixel, no bridge.
Image FlippedColour(const Frame &frame) {
    Image color = frame.Get("color");
    for (int c = 0; c < 3; ++c)
        color.At(c, 12, 12) = color.At(c, 13, 11) = color.At(c, 30, 6) = color.At(
            c, kCausticY, kCausticX + 2) = color.At(c, kCausticY + 1, kCausticX + 1) = 0.0133f;
    return color;
}

// The count of a run's bridged pixels ("...; N more in clusters joined"), or -1.
int BridgedIn(const Result &result) {
    const std::string marker = "; ", what = " more in clusters joined";
    for (const std::string &line : result.plan) {
        const size_t end = line.find(what);
        if (line.rfind("bright clusters: ", 0) != 0 || end == std::string::npos) continue;
        const size_t begin = line.rfind(marker, end);
        return std::stoi(line.substr(begin + marker.size(), end - begin - marker.size()));
    }
    return -1;
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
    ASSERT_EQ(BridgedIn(run), 5);
    ASSERT_GT(rims, 0);
    // The firefly and the caustic's brightest pixel (a pair's, above its other neighbours).
    const int spikes = CountIn(run, "spikes: ");
    ASSERT_EQ(spikes, 2);
    std::unique_ptr<api::FrontEnd> onHalf = rhf->ForProbe(Ctx(), inputs, true),
                                   onPerturbed = rhf->ForProbe(Ctx(), inputs, false);
    ASSERT_NE(onHalf, nullptr);
    ASSERT_NE(onPerturbed, nullptr);

    const Image flipped = FlippedColour(frame);
    inputs.Override("color", flipped);
    // Alone the flipped colour cuts no cluster, bridges none, and cuts the reflection's other
    // two pixels and the caustic's other three as spikes: the test tells the probe's cuts
    // apart.
    const Result alone = api::RunTiled(Ctx(), *rhf, inputs, keep);
    EXPECT_EQ(CountIn(alone, "bright clusters: "), 0);
    EXPECT_EQ(BridgedIn(alone), 0);
    const int ownSpikes = CountIn(alone, "spikes: ");
    EXPECT_EQ(ownSpikes, 5);
    for (const auto *probe : {onHalf.get(), onPerturbed.get()}) {
        const bool half = probe == onHalf.get();
        SCOPED_TRACE(half ? "on half0" : "on the perturbed colour");
        const Result probed = api::RunTiled(Ctx(), *probe, inputs, keep);
        EXPECT_EQ(CountIn(probed, "bright clusters: "), clusters);
        EXPECT_EQ(BridgedIn(probed), 5);
        EXPECT_EQ(CountIn(probed, "lights' rims: "), rims);
        EXPECT_EQ(CountIn(probed, "spikes: "), half ? spikes : ownSpikes);
        // Each of the run's cluster pixels takes the probe's input back after the filter.
        const Image given = StageOf(probed, "exact pixels");
        ASSERT_TRUE(given.SameShape(flipped));
        for (auto [x, y] : {std::pair{12, 12}, {13, 12}, {11, 13}, {12, 13}})
            for (int c = 0; c < 3; ++c)
                EXPECT_EQ(given.At(c, y, x), flipped.At(c, y, x))
                    << x << ", " << y << " c" << c;
        // The run's bridged pixels do not: the caustic's brightest keeps the filter's output.
        EXPECT_LT(given.At(0, kCausticY + 1, kCausticX),
                  0.5f * flipped.At(0, kCausticY + 1, kCausticX));
    }
}

// On the run's own colour the probe cuts what the run cuts, to the same bits, untiled and
// in tiles of 20 (the sets are the frame's, mapped per window; a tile's window reaches past
// its seams to the cuts of its neighbours).
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

// auto's rhf candidates (one scale and two) cut their frame alike: through the run memo the
// second's probe takes the first's cut sets, and probes as it does alone, bit for bit; another
// colour or search window cuts anew.
TEST_F(RhfProbe, CandidatesOfOneColourShareTheirCutSets) {
    const Frame frame = ReflectionFrame();
    std::unique_ptr<api::FrontEnd> rhf = api::FindMethod("rhf")->make(),
                                   twoScales = api::FindMethod("rhf")->make();
    twoScales->Set("nscales", 2);
    RunMemo memo;
    api::Inputs shared(frame, false, "rhf"), alone(frame, false, "rhf");
    shared.SetMemo(&memo);
    ASSERT_NE(rhf->ForProbe(Ctx(), shared, false), nullptr);
    EXPECT_EQ(memo.CountWithPrefix("rhf.cuts"), 1u);
    std::unique_ptr<api::FrontEnd> taken = twoScales->ForProbe(Ctx(), shared, false),
                                   own = twoScales->ForProbe(Ctx(), alone, false);
    EXPECT_EQ(memo.CountWithPrefix("rhf.cuts"), 1u) << "the second candidate cut anew";
    const Image flipped = FlippedColour(frame);
    shared.Override("color", flipped);
    alone.Override("color", flipped);
    RunOptions keep;
    keep.keepStages = true;
    const Result a = api::RunTiled(Ctx(), *taken, shared, keep),
                 b = api::RunTiled(Ctx(), *own, alone, keep);
    EXPECT_EQ(CountIn(a, "bright clusters: "), 4);
    EXPECT_TRUE(BitIdentical(a.image, b.image));
    EXPECT_NE(rhf->ForProbe(Ctx(), shared, false), nullptr);
    EXPECT_EQ(memo.CountWithPrefix("rhf.cuts"), 2u) << "another colour took the first's sets";
    twoScales->Set("search-half", 4);
    EXPECT_NE(twoScales->ForProbe(Ctx(), shared, false), nullptr);
    EXPECT_EQ(memo.CountWithPrefix("rhf.cuts"), 3u) << "another search window took them";
    EXPECT_EQ(BridgedIn(a), 5) << "the kept sets lost the bridged clusters";
    // Cut reads the variance and the histograms too: another of either cuts anew.
    Image variance = frame.Get("variance");
    for (float &v : variance.data) v *= 4.0f;
    shared.Override("variance", variance);
    EXPECT_NE(twoScales->ForProbe(Ctx(), shared, false), nullptr);
    EXPECT_EQ(memo.CountWithPrefix("rhf.cuts"), 4u) << "another variance took the first's sets";
    Image histograms = frame.Get("hist");
    histograms.data[0] += 1.0f;
    shared.Override("hist", histograms);
    EXPECT_NE(twoScales->ForProbe(Ctx(), shared, false), nullptr);
    EXPECT_EQ(memo.CountWithPrefix("rhf.cuts"), 5u) << "other histograms took the first's sets";
}

// auto's rhf candidates cut one colour once: through the run memo the second run takes the
// first's cuts, ForProbe its sets from them, and a probe the cuts an earlier probe made as
// decided on the same colour; each bit for bit as alone. Another colour cuts anew.
TEST_F(RhfProbe, CandidatesOfOneColourShareTheirCuts) {
    const Frame frame = ReflectionFrame();
    std::unique_ptr<api::FrontEnd> rhf = api::FindMethod("rhf")->make(),
                                   twoScales = api::FindMethod("rhf")->make();
    twoScales->Set("nscales", 2);
    RunMemo memo;
    api::Inputs shared(frame, false, "rhf"), alone(frame, false, "rhf");
    shared.SetMemo(&memo);
    api::RunTiled(Ctx(), *rhf, shared, RunOptions());
    EXPECT_EQ(memo.CountWithPrefix("rhf.own cuts"), 1u);
    const Result second = api::RunTiled(Ctx(), *twoScales, shared, RunOptions());
    EXPECT_EQ(memo.CountWithPrefix("rhf.own cuts"), 1u) << "the second candidate cut anew";
    EXPECT_TRUE(BitIdentical(second.image,
                             api::RunTiled(Ctx(), *twoScales, alone, RunOptions()).image));
    std::unique_ptr<api::FrontEnd> probe = rhf->ForProbe(Ctx(), shared, false),
                                   secondProbe = twoScales->ForProbe(Ctx(), shared, false),
                                   ownProbe = twoScales->ForProbe(Ctx(), alone, false);
    EXPECT_EQ(memo.CountWithPrefix("rhf.own cuts"), 1u) << "ForProbe cut anew";
    // The first probe on the run's colour, the second on another: it cuts as decided anew.
    api::RunTiled(Ctx(), *probe, shared, RunOptions());
    EXPECT_EQ(memo.CountWithPrefix("rhf.decided cuts"), 1u);
    const Image flipped = FlippedColour(frame);
    shared.Override("color", flipped);
    alone.Override("color", flipped);
    const Result a = api::RunTiled(Ctx(), *secondProbe, shared, RunOptions()),
                 b = api::RunTiled(Ctx(), *ownProbe, alone, RunOptions());
    EXPECT_EQ(memo.CountWithPrefix("rhf.decided cuts"), 2u) << "another colour took the cuts";
    EXPECT_TRUE(BitIdentical(a.image, b.image));
    api::RunTiled(Ctx(), *probe, shared, RunOptions());
    EXPECT_EQ(memo.CountWithPrefix("rhf.decided cuts"), 2u) << "the first probe cut anew";
    // Sets decided on the other colour (no cluster) cut it anew, as alone.
    std::unique_ptr<api::FrontEnd> otherSets = rhf->ForProbe(Ctx(), shared, false),
                                   ownSets = rhf->ForProbe(Ctx(), alone, false);
    EXPECT_EQ(memo.CountWithPrefix("rhf.own cuts"), 1u) << "ForProbe kept the cuts it made";
    const Result e = api::RunTiled(Ctx(), *otherSets, shared, RunOptions()),
                 f = api::RunTiled(Ctx(), *ownSets, alone, RunOptions());
    EXPECT_EQ(memo.CountWithPrefix("rhf.decided cuts"), 3u) << "other sets took the cuts";
    EXPECT_TRUE(BitIdentical(e.image, f.image));
    EXPECT_FALSE(BitIdentical(e.image, a.image)) << "the sets make no difference here";
    // A run on the other colour cuts anew (ForProbe kept none), as alone (no cluster there).
    RunOptions keep;
    keep.keepStages = true;
    const Result c = api::RunTiled(Ctx(), *twoScales, shared, keep),
                 d = api::RunTiled(Ctx(), *twoScales, alone, keep);
    EXPECT_EQ(memo.CountWithPrefix("rhf.own cuts"), 2u) << "another colour took the cuts";
    EXPECT_EQ(CountIn(c, "bright clusters: "), 0);
    EXPECT_TRUE(BitIdentical(c.image, d.image));
}

// The run against its CPU reference (FrontEnd::Reference) on the frame with the caustic: the
// same stages, their values within float rounding; the bridged pixels keep the filter's
// output (not their input: the local mean gives their energy back).
TEST_F(RhfProbe, RunMatchesItsReferenceWithACaustic) {
    const Frame frame = ReflectionFrame();
    Device device = api::BorrowDevice(Ctx());
    Method rhf("rhf");
    RunOptions keep;
    keep.keepStages = true;
    const Result run = rhf.Run(device, frame, keep);
    ASSERT_EQ(BridgedIn(run), 5);
    const std::vector<Stage> cpu = rhf.Reference(device, frame);
    ASSERT_EQ(run.stages.size(), cpu.size());
    Tolerance tolerance;
    tolerance.relTol = 1e-3, tolerance.absTol = 1e-5, tolerance.maxNmse = 1e-8;
    for (size_t i = 0; i < cpu.size(); ++i) {
        ASSERT_EQ(run.stages[i].name, cpu[i].name);
        EXPECT_TRUE(ImagesMatch(cpu[i].image, run.stages[i].image, Image(), tolerance))
            << cpu[i].name;
    }
    // The caustic's middle pixel, bright in the input, is no longer so after the filter.
    const Image &given = frame.Get("color"), exact = StageOf(run, "exact pixels");
    EXPECT_LT(exact.At(0, kCausticY + 1, kCausticX + 1),
              0.5f * given.At(0, kCausticY + 1, kCausticX + 1));
}

// auto's probe doubles the variance (a half's mean, SURE's probe): the lights beside the run's
// rims stay the run's. The light's edge column beside the rim is made a light whose variance is
// within its bound but not within twice it; told from the doubled variance, the rim's median
// would take one of them and the filter's output near it would move.
TEST_F(RhfProbe, TheRimsLightsAreTheRunsUnderTheDoubledVariance) {
    Frame frame = ReflectionFrame();
    Image &variance = frame.layers["variance"];
    for (int y = 26; y <= 28; ++y) {
        const double sum = frame.Get("color").At(0, y, 29) + frame.Get("color").At(1, y, 29) +
                           frame.Get("color").At(2, y, 29);
        for (int c = 0; c < 3; ++c) variance.At(c, y, 29) = float(0.3 * 0.0001 * sum * sum);
    }
    std::unique_ptr<api::FrontEnd> rhf = api::FindMethod("rhf")->make();
    api::Inputs inputs(frame, false, "rhf");
    RunOptions keep;
    keep.keepStages = true;
    const Result run = api::RunTiled(Ctx(), *rhf, inputs, keep);
    ASSERT_GT(CountIn(run, "lights' rims: "), 0);
    Image doubled = variance;
    for (float &v : doubled.data) v *= 2;
    for (bool onHalf : {true, false}) {
        SCOPED_TRACE(onHalf ? "on half0" : "on the perturbed colour");
        std::unique_ptr<api::FrontEnd> probe = rhf->ForProbe(Ctx(), inputs, onHalf);
        ASSERT_NE(probe, nullptr);
        api::Inputs probed(frame, false, "rhf");
        probed.Override("variance", doubled);
        const Result result = api::RunTiled(Ctx(), *probe, probed, keep);
        EXPECT_EQ(CountIn(result, "lights' rims: "), CountIn(run, "lights' rims: "));
        // Zero variance stays zero: before the local mean the variance tells nothing else.
        EXPECT_TRUE(
            BitIdentical(StageOf(run, "exact pixels"), StageOf(result, "exact pixels")));
    }
}

// A cut pixel takes its neighbours' median, those skipped left out; one with a neighbour not
// finite (no median) keeps its value, per channel. (Inputs replace NaN with 0 before a
// method reads them: this is the step alone.)
TEST(RhfProbeMedians, SkipTheSkippedAndLeaveAPixelBesideANaN) {
    Image given(4, 3, 2);
    std::mt19937_64 rng(SeedFromName("rhf probe medians"));
    std::uniform_real_distribution<float> value(0.f, 1.f);
    for (float &v : given.data) v = value(rng);
    given.At(1, 0, 0) = NAN;
    std::vector<char> skipped(given.PixelCount(), 0);
    skipped[2] = 1;
    // (1, 1) beside the NaN in channel 1; (2, 1) beside neither; (3, 2) at the corner.
    const std::vector<size_t> pixels = {5, 6, 11};
    Image cut = given;
    TakeNeighbourMedians(given, pixels, skipped, &cut);
    for (size_t p : pixels)
        for (int c = 0; c < 2; ++c) {
            const int x = int(p % 4), y = int(p / 4);
            std::vector<float> values;
            bool finite = true;
            for (int j = std::max(0, y - 1); j <= std::min(2, y + 1); ++j)
                for (int i = std::max(0, x - 1); i <= std::min(3, x + 1); ++i)
                    if ((i != x || j != y) && !skipped[size_t(j) * 4 + i]) {
                        values.push_back(given.At(c, j, i));
                        finite = finite && std::isfinite(values.back());
                    }
            std::sort(values.begin(), values.end());
            const float want = finite ? values[(values.size() - 1) / 2] : given.At(c, y, x);
            EXPECT_EQ(cut.At(c, y, x), want) << x << ", " << y << " c" << c;
        }
    // The NaN's neighbour keeps its value in channel 1 only; the others all take medians.
    EXPECT_EQ(cut.At(1, 1, 1), given.At(1, 1, 1));
    EXPECT_NE(cut.At(0, 1, 1), given.At(0, 1, 1));
    EXPECT_TRUE(std::isnan(cut.At(1, 0, 0)));
}

class AutoProbeOfRhf : public GpuTest {};

// auto runs rhf's probe with the run's cuts: on the perturbed colour (SURE on the variance
// layer) its plan states the run's clusters and rims, though the probe's doubled variance and
// its noise would decide its own.
TEST_F(AutoProbeOfRhf, KeepsTheRunsCuts) {
    const Frame frame = ReflectionFrame();
    Device device = api::BorrowDevice(Ctx());
    Method automatic("auto");
    automatic.Set("auto-candidates", std::string("rhf"));
    const Result result = automatic.Run(device, frame);
    std::string plan;
    for (const std::string &line : result.plan) plan += line + "\n";
    auto count = [&](const std::string &prefix) {
        for (const std::string &line : result.plan)
            if (line.rfind(prefix, 0) == 0) return std::stoi(line.substr(prefix.size()));
        return -1;
    };
    ASSERT_EQ(count("rhf: bright clusters: "), 4) << plan;
    EXPECT_EQ(count("rhf (probe): bright clusters: "), 4) << plan;
    EXPECT_EQ(count("rhf (probe): lights' rims: "), count("rhf: lights' rims: ")) << plan;
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

// What the filter wrote is never its input but for 0 (FilteredValue), on the GPU and in the
// twin: the restore after it keeps the values equal to their input, and a mean that rounds
// onto its input on one side only was kept there and restored on the other. The left part's
// pixels have the same samples (mean 0.4, variance above 0, so not exact pixels), so their
// means are of equal values: the twin's double mean rounds onto the input.
TEST_F(RhfProbe, FilteredValuesNeverEqualTheirInput) {
    const int w = 31, h = 23, flat = 15;
    std::mt19937_64 rng(SeedFromName("rhf filtered values"));
    std::uniform_real_distribution<double> wallSample(0.05, 0.5);
    const Frame frame = SampledFrame(w, h, [&](int x, int, int s) {
        const double wall = wallSample(rng);
        return x < flat ? (s % 2 ? 0.6 : 0.2) : wall;
    });
    Device device = api::BorrowDevice(Ctx());
    Method rhf("rhf");
    RunOptions keep;
    keep.keepStages = true;
    const Result run = rhf.Run(device, frame, keep);
    const std::vector<Stage> cpu = rhf.Reference(device, frame);
    const Image &given = frame.Get("color");
    const std::pair<std::string, Image> sides[] = {{"GPU", StageOf(run, "exact pixels")},
                                                   {"twin", StageOf(cpu, "exact pixels")}};
    for (const auto &[what, filtered] : sides) {
        ASSERT_EQ(filtered.Size(), given.Size()) << what;
        int equal = 0, moved = 0;
        for (int c = 0; c < 3; ++c)
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) {
                    const float in = given.At(c, y, x), out = filtered.At(c, y, x);
                    equal += std::memcmp(&in, &out, sizeof(float)) == 0;
                    moved += x < flat && out == std::nextafter(in, INFINITY);
                }
        EXPECT_EQ(equal, 0) << what;
        if (what == "twin") {
            EXPECT_GT(moved, 3 * flat * h / 2) << "few values moved";
        }
    }
    Tolerance tolerance;
    tolerance.relTol = 1e-3, tolerance.absTol = 1e-5, tolerance.maxNmse = 1e-8;
    EXPECT_TRUE(ImagesMatch(cpu.back().image, run.image, Image(), tolerance));
}

}  // namespace
}  // namespace mcd::test
