// The temporal mode's gather (host/methods/temporal.h) against the whole-gather CPU
// reference (ref::TemporalGather: each pixel's chain walked, the statistics in two passes
// in double) on synthetic sequences with motion, features, spp, NaN samples and odd sizes;
// and its properties: a still sequence gives accumulate's mean and variance, a moving
// object leaves no trail on the background, vectors off the frame and disagreeing
// features leave the frame alone, reruns are bit-identical; and mcd::Temporal's API.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "cpu_reference/temporal.h"
#include "harness/compare.h"
#include "harness/gpu_fixture.h"
#include "harness/inputs.h"
#include "host/api/device.h"
#include "host/io/accumulate.h"
#include "host/io/layer_names.h"
#include "host/methods/temporal.h"
#include "mcdenoise/temporal.h"
#include "temporal/temporal.h"

namespace mcd::test {
namespace {

constexpr double kUnitRoundoff = 0x1p-24;

// A synthetic shot: a background of three regions (ids 0-2, their own albedo, normal and
// depth) and a square (id 3) that moves `step` pixels a frame right and down, each frame's
// colour the clean image times (1 + noise) with its own seed; Blender's Vector pass for
// it (the background still).
struct Shot {
    int w, h, frames;
    double step;
    std::vector<Image> color, variance, spp, motion, normal, depth, albedo, id;
    std::vector<Image> min, max, direct, directVariance;

    // Whether (x, y) of frame f is on the square.
    bool OnSquare(int f, int x, int y) const {
        double x0 = 3 + step * f, y0 = 2 + 0.5 * step * f;
        return x >= x0 && x < x0 + 6 && y >= y0 && y < y0 + 5;
    }
};

Shot MakeShot(int w, int h, int frames, double step, uint64_t seed, bool nanSamples = false) {
    Shot s{w, h, frames, step};
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> normal(0, 1);
    for (int f = 0; f < frames; ++f) {
        Image color(w, h, 3), variance(w, h, 3), spp(w, h, 1, 16.f), motion(w, h, 4);
        Image n(w, h, 3), d(w, h, 1), a(w, h, 3), id(w, h, 1), mn(w, h, 3), mx(w, h, 3);
        Image direct(w, h, 3), dv(w, h, 3);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                bool square = s.OnSquare(f, x, y);
                int region = square ? 3 : (x / 7 + y / 5) % 3;
                id.At(0, y, x) = float(region);
                d.At(0, y, x) = square ? 2.f : 5.f + float(region);
                for (int c = 0; c < 3; ++c) {
                    n.At(c, y, x) = c == region % 3 ? 1.f : 0.f;
                    a.At(c, y, x) = 0.2f + 0.2f * float(region);
                    double clean = (square ? 2.0 : 0.3) * (1 + 0.1 * c);
                    double value = clean * (1 + 0.3 * normal(rng));
                    color.At(c, y, x) = float(value);
                    variance.At(c, y, x) = float(clean * clean * 0.09 / 16);
                    mn.At(c, y, x) = float(value * 0.5);
                    mx.At(c, y, x) = float(value * 2);
                    direct.At(c, y, x) = float(value * 0.6);
                    dv.At(c, y, x) = float(clean * clean * 0.03 / 16);
                }
                if (square) {  // previous minus here, here minus next; y up
                    motion.At(0, y, x) = float(-step), motion.At(1, y, x) = float(0.5 * step);
                    motion.At(2, y, x) = float(-step), motion.At(3, y, x) = float(0.5 * step);
                }
                if (nanSamples && (x * 7 + y * 3 + f) % 29 == 0)
                    color.At(1, y, x) = std::numeric_limits<float>::quiet_NaN();
            }
        s.color.push_back(color), s.variance.push_back(variance), s.spp.push_back(spp);
        s.motion.push_back(motion), s.normal.push_back(n), s.depth.push_back(d);
        s.albedo.push_back(a), s.id.push_back(id), s.min.push_back(mn), s.max.push_back(mx);
        s.direct.push_back(direct), s.directVariance.push_back(dv);
    }
    return s;
}

struct Use {
    bool variance = true, spp = true, motion = true, features = true, extras = false;
};

std::vector<TemporalFrameLayers> GpuFrames(const Shot &s, int current, const Use &use) {
    std::vector<TemporalFrameLayers> frames;
    for (int f = 0; f < s.frames; ++f) {
        TemporalFrameLayers l;
        l.offset = f - current;
        l.color = &s.color[f];
        if (use.variance) l.variance = &s.variance[f];
        if (use.spp) l.spp = &s.spp[f];
        if (use.motion) l.motion = &s.motion[f];
        if (use.features) {
            l.normal = &s.normal[f], l.depth = &s.depth[f], l.albedo = &s.albedo[f];
            l.objectId = &s.id[f];
        }
        if (use.extras) {
            l.layers = {{"min", &s.min[f]},
                        {"max", &s.max[f]},
                        {"direct", &s.direct[f]},
                        {"direct.variance", &s.directVariance[f]}};
        }
        frames.push_back(l);
    }
    return frames;
}

std::vector<ref::TemporalFrame> RefFrames(const std::vector<TemporalFrameLayers> &gpu) {
    std::vector<ref::TemporalFrame> frames;
    for (const TemporalFrameLayers &l : gpu) {
        ref::TemporalFrame f;
        f.offset = l.offset;
        f.color = l.color, f.variance = l.variance, f.spp = l.spp, f.motion = l.motion;
        f.layers = l.layers;
        int w = l.color->width, h = l.color->height;
        f.features = Image(w, h, TEMPORAL_FEATURE_PLANES);
        auto put = [&](const Image *image, int plane, int bit) {
            if (!image) return;
            std::copy(image->data.begin(), image->data.end(), f.features.Plane(plane));
            f.mask |= bit;
        };
        put(l.normal, TEMPORAL_FEATURE_NORMAL, TEMPORAL_HAS_NORMAL);
        put(l.depth, TEMPORAL_FEATURE_DEPTH, TEMPORAL_HAS_DEPTH);
        put(l.albedo, TEMPORAL_FEATURE_ALBEDO, TEMPORAL_HAS_ALBEDO);
        put(l.objectId, TEMPORAL_FEATURE_ID, TEMPORAL_HAS_ID);
        frames.push_back(std::move(f));
    }
    return frames;
}

const Image &LayerOf(const TemporalGathered &g, const std::string &name) {
    for (const auto &[n, image] : g.layers)
        if (n == name) return image;
    static const Image none;
    ADD_FAILURE() << "no layer " << name;
    return none;
}

// The largest finite |value| over the shot's colours: the scale of every rounding error
// of the folds.
double ShotScale(const Shot &s) {
    double m = 0;
    for (const Image &c : s.color)
        for (float v : c.data)
            if (std::isfinite(v)) m = std::max(m, double(std::fabs(v)));
    return m;
}

class TemporalGather : public GpuTest {};

// k folds of West's update each err by a few ulps of the values' size; the variance's
// squared deviations by a few ulps of the values' size squared a fold.
TEST_F(TemporalGather, MatchesReference) {
    struct Case {
        int w, h, frames, current, radius;
        double step;
        Use use;
        bool nan;
    };
    const Case cases[] = {{23, 17, 5, 2, 2, 2.0, {}, true},
                          {23, 17, 5, 1, 3, 1.5, {}, false},
                          {23, 17, 4, 3, 2, 1.0, {false, true, true, true, true}, true},
                          {23, 17, 5, 2, 2, 2.0, {true, false, false, false, true}, false},
                          {1, 1, 3, 1, 1, 0.0, {}, true},
                          {13, 1, 4, 0, 3, 1.0, {false, false, true, true, false}, false},
                          {1, 9, 3, 2, 2, 1.0, {}, false}};
    for (const Case &c : cases) {
        SCOPED_TRACE(fmt::format("{}x{} frames {} current {} radius {} step {}", c.w, c.h,
                                 c.frames, c.current, c.radius, c.step));
        Shot shot = MakeShot(c.w, c.h, c.frames, c.step,
                             SeedFromName(fmt::format("gather{}x{}", c.w, c.h)), c.nan);
        std::vector<TemporalFrameLayers> frames = GpuFrames(shot, c.current, c.use);
        TemporalParams params;
        params.radius = c.radius;
        TemporalGathered g = mcd::TemporalGather(Ctx(), frames, params);
        EXPECT_EQ(g.pooled, c.use.variance);
        EXPECT_EQ(g.motion, c.use.motion);
        std::map<std::string, bool> layerPooled = {{"direct", true}};
        ref::TemporalGatheredRef expected = ref::TemporalGather(
            RefFrames(frames), params, c.use.spp, c.use.motion, c.use.variance, layerPooled);
        EXPECT_TRUE(ImagesMatch(expected.layers.at("frames"), g.frames, {}, {0, 0, 0}));
        double scale = ShotScale(shot), folds = 2.0 * c.radius + 1;
        Tolerance mean{0, 8 * folds * kUnitRoundoff * scale, 1e-10};
        Tolerance variance{0, 32 * folds * kUnitRoundoff * scale * scale, 1e-10};
        for (const char *name : {"color", "half0.color", "half1.color"})
            EXPECT_TRUE(ImagesMatch(expected.layers.at(name), LayerOf(g, name), {}, mean))
                << name;
        EXPECT_TRUE(
            ImagesMatch(expected.layers.at("variance"), LayerOf(g, "variance"), {}, variance));
        if (c.use.spp) {
            EXPECT_TRUE(
                ImagesMatch(expected.layers.at("spp"), LayerOf(g, "spp"), {}, {0, 0, 0}));
        }
        if (!c.use.extras) continue;
        for (const char *name : {"min", "max"})
            EXPECT_TRUE(ImagesMatch(expected.layers.at(name), LayerOf(g, name), {}, {0, 0, 0}))
                << name;
        EXPECT_TRUE(ImagesMatch(expected.layers.at("direct"), LayerOf(g, "direct"), {}, mean));
        EXPECT_TRUE(ImagesMatch(expected.layers.at("direct.variance"),
                                LayerOf(g, "direct.variance"), {}, variance));
    }
}

TEST_F(TemporalGather, RerunIsBitIdentical) {
    Shot shot = MakeShot(31, 19, 5, 1.5, SeedFromName("rerun"), true);
    std::vector<TemporalFrameLayers> frames =
        GpuFrames(shot, 2, {true, true, true, true, true});
    TemporalParams params;
    params.radius = 2;
    TemporalGathered a = mcd::TemporalGather(Ctx(), frames, params);
    TemporalGathered b = mcd::TemporalGather(Ctx(), frames, params);
    ASSERT_EQ(a.layers.size(), b.layers.size());
    for (size_t i = 0; i < a.layers.size(); ++i)
        EXPECT_TRUE(BitIdentical(a.layers[i].second, b.layers[i].second)) << a.layers[i].first;
}

// A still camera and no features: the gathered frame is accumulate's mean of all the frames
// and its variance of the mean from their spread (the frames' weights equal).
TEST_F(TemporalGather, StillFramesAreAccumulated) {
    Shot shot = MakeShot(17, 11, 5, 0.0, SeedFromName("still"));
    std::vector<TemporalFrameLayers> frames =
        GpuFrames(shot, 2, {false, true, false, false, false});
    TemporalParams params;
    params.radius = 2;
    TemporalGathered g = mcd::TemporalGather(Ctx(), frames, params);
    io::Accumulator accumulator;
    for (int f = 0; f < shot.frames; ++f) {
        Frame frame(shot.w, shot.h);
        frame.layers["color"] = shot.color[f];
        accumulator.Add(frame);
    }
    Frame accumulated = accumulator.Finish();
    double scale = ShotScale(shot);
    EXPECT_TRUE(ImagesMatch(accumulated.Get("color"), LayerOf(g, "color"), {},
                            {0, 40 * kUnitRoundoff * scale, 1e-10}));
    EXPECT_TRUE(ImagesMatch(accumulated.Get("variance"), LayerOf(g, "variance"), {},
                            {0, 160 * kUnitRoundoff * scale * scale, 1e-10}));
    for (float n : g.frames.data) EXPECT_EQ(n, 5.f);
}

// The square moves over the still background: no background pixel gathers a sample of the
// square (a trail), and the square's pixels follow it through every frame that shows it.
TEST_F(TemporalGather, MovingObjectLeavesNoTrail) {
    Shot shot = MakeShot(32, 20, 7, 2.0, SeedFromName("trail"));
    const int current = 3;
    TemporalParams params;
    params.radius = 3;
    TemporalGathered g = mcd::TemporalGather(Ctx(), GpuFrames(shot, current, {}), params);
    const Image &color = LayerOf(g, "color");
    int square = 0, full = 0;
    for (int y = 0; y < shot.h; ++y)
        for (int x = 0; x < shot.w; ++x) {
            if (!shot.OnSquare(current, x, y)) {
                // Background 0.3-0.4 with 30% noise over >= 1 frame; the square is 2.
                for (int c = 0; c < 3; ++c) EXPECT_LT(color.At(c, y, x), 1.2f) << x << "," << y;
                continue;
            }
            ++square;
            full += g.frames.At(0, y, x) == 7.f;
        }
    // Every frame of the square fits in the frame here.
    EXPECT_EQ(full, square);
}

// Vectors that lead off the frame, or features that disagree everywhere: the neighbours
// give nothing and the colour is the frame's own, bit for bit.
TEST_F(TemporalGather, RejectedNeighboursLeaveTheFrame) {
    Shot shot = MakeShot(15, 9, 3, 0.0, SeedFromName("off"));
    for (Image &m : shot.motion)
        for (int y = 0; y < shot.h; ++y)
            for (int x = 0; x < shot.w; ++x) {
                m.At(0, y, x) = float(shot.w),
                           m.At(2, y, x) = float(-2 * shot.w);  // off the frame
                m.At(1, y, x) = m.At(3, y, x) = 0;
            }
    TemporalParams params;
    params.radius = 1;
    TemporalGathered off = mcd::TemporalGather(Ctx(), GpuFrames(shot, 1, {}), params);
    EXPECT_TRUE(BitIdentical(LayerOf(off, "color"), shot.color[1]));
    for (float n : off.frames.data) EXPECT_EQ(n, 1.f);
    for (double p : off.acceptedPercent) EXPECT_EQ(p, 0.0);
    // Still, but every neighbour's ids differ: all rejected. With the frames' variances the
    // variance is the frame's own; from the spread, none is known (0).
    Shot other = MakeShot(15, 9, 3, 0.0, SeedFromName("ids"));
    for (int f : {0, 2})
        for (float &id : other.id[f].data) id += 10;
    TemporalGathered ids =
        mcd::TemporalGather(Ctx(), GpuFrames(other, 1, {true, true, false, true}), params);
    EXPECT_TRUE(BitIdentical(LayerOf(ids, "color"), other.color[1]));
    EXPECT_TRUE(ImagesMatch(other.variance[1], LayerOf(ids, "variance"), {},
                            {4 * kUnitRoundoff, 0, 1e-10}));
    params.variance = TemporalVariance::Spread;
    TemporalGathered spread =
        mcd::TemporalGather(Ctx(), GpuFrames(other, 1, {true, true, false, true}), params);
    for (float v : LayerOf(spread, "variance").data) EXPECT_EQ(v, 0.f);
}

// A window of the current frame alone gives the frame back.
TEST_F(TemporalGather, OneFrameIsItself) {
    Shot shot = MakeShot(9, 7, 1, 0.0, SeedFromName("one"));
    TemporalGathered g = mcd::TemporalGather(Ctx(), GpuFrames(shot, 0, {}), TemporalParams());
    EXPECT_TRUE(BitIdentical(LayerOf(g, "color"), shot.color[0]));
    EXPECT_TRUE(g.offsets.empty());
}

// Blender's Vector pass, whose channels an EXR lists W, X, Y, Z, is layer motion in X, Y,
// Z, W order; ours round-trips.
TEST(TemporalIo, ReadsBlendersVectorPassAsMotion) {
    std::vector<io::LayerChannels> layers =
        io::GroupChannels({"ViewLayer.Combined.B", "ViewLayer.Combined.G",
                           "ViewLayer.Combined.R", "ViewLayer.Vector.W", "ViewLayer.Vector.X",
                           "ViewLayer.Vector.Y", "ViewLayer.Vector.Z"});
    bool found = false;
    for (const io::LayerChannels &l : layers)
        if (l.name == "motion") {
            found = true;
            EXPECT_EQ(l.channels, (std::vector<int>{4, 5, 6, 3}));
        }
    EXPECT_TRUE(found);
    std::vector<std::string> names = io::ChannelNamesOf("motion", 4);
    std::vector<io::LayerChannels> back = io::GroupChannels(names);
    ASSERT_EQ(back.size(), 1u);
    EXPECT_EQ(back[0].name, "motion");
    EXPECT_EQ(back[0].channels, (std::vector<int>{0, 1, 2, 3}));
}

TEST(TemporalApi, ParamsAreCheckedAndTyped) {
    Temporal temporal;
    EXPECT_EQ(temporal.Radius(), TemporalParams().radius);
    temporal.SetText("temporal-radius", "2");
    EXPECT_EQ(std::get<int>(temporal.Get("temporal-radius")), 2);
    temporal.Set("temporal-normal", 30);  // an int where a number is asked for
    EXPECT_EQ(std::get<float>(temporal.Get("temporal-normal")), 30.f);
    temporal.SetText("temporal-variance", "spread");
    EXPECT_EQ(std::get<std::string>(temporal.Get("temporal-variance")), "spread");
    EXPECT_THROW(temporal.SetText("temporal-radius", "17"), Error);
    EXPECT_THROW(temporal.SetText("temporal-radius", "two"), Error);
    EXPECT_THROW(temporal.SetText("temporal-variance", "pooled"), Error);
    EXPECT_THROW(temporal.Get("temporal-nothing"), Error);
    for (const ParamInfo &info : temporal.Params()) EXPECT_TRUE(temporal.HasParam(info.name));
}

// Frames of borrowed views: the gathered frame owns its layers, keeps the current frame's
// others, and leaves out the sample statistics it cannot gather.
TEST_F(TemporalGather, ApiGathersFramesOfViews) {
    Shot shot = MakeShot(12, 8, 3, 1.0, SeedFromName("api"));
    std::vector<Frame> frames(3);
    std::vector<std::vector<float>> interleaved(3);
    for (int f = 0; f < 3; ++f) {
        Frame &frame = frames[f];
        interleaved[f].resize(size_t(shot.w) * shot.h * 3);
        for (int y = 0; y < shot.h; ++y)
            for (int x = 0; x < shot.w; ++x)
                for (int c = 0; c < 3; ++c)
                    interleaved[f][(size_t(y) * shot.w + x) * 3 + c] =
                        shot.color[f].At(c, y, x);
        frame.SetLayer("color",
                       LayerView::Interleaved(interleaved[f].data(), shot.w, shot.h, 3));
        frame.SetLayer("motion", shot.motion[f]);
        frame.SetLayer("objectId", shot.id[f]);
        frame.SetLayer("albedo", shot.albedo[f]);
        frame.SetLayer("zhist", Image(shot.w, shot.h, 4));
    }
    Device device = api::BorrowDevice(Ctx());
    Temporal temporal;
    temporal.Set("temporal-radius", 1);
    TemporalResult r =
        temporal.Gather(device, {{-1, &frames[0]}, {0, &frames[1]}, {1, &frames[2]}});
    EXPECT_TRUE(r.frame.views.empty());
    for (const char *name :
         {"color", "variance", "half0.color", "half1.color", "albedo", "objectId", "motion"})
        EXPECT_TRUE(r.frame.Has(name)) << name;
    EXPECT_FALSE(r.frame.Has("zhist"));
    EXPECT_EQ(r.offsets, (std::vector<int>{-1, 1}));
    EXPECT_THROW(temporal.Gather(device, {{1, &frames[2]}}), Error);
}

}  // namespace
}  // namespace mcd::test
