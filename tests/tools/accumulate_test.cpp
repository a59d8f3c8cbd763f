// `mcdenoise accumulate` (issue #16) and host/io/accumulate.h: 1-spp frames from the
// renderer with different seeds accumulate to exactly the statistics of their samples
// (computed here directly); mismatched frames are refused naming the file; NaN/Inf are
// counted and left out; the output may not be an input; frames that share their camera
// rays (Cycles' unjittered 1-spp frames) are detected and warned about. Real Cycles
// frames (tests/data/cycles_cornell_24_1spp_*.exr) are checked the same way.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "harness/errors.h"
#include "harness/tool.h"
#include "host/error.h"
#include "host/image.h"
#include "host/io/accumulate.h"
#include "host/io/conventions.h"
#include "host/io/frame.h"
#include "host/io/layer_names.h"
#include "tools/mcdenoise/exit_status.h"
#include "tools/render/renderer.h"

namespace mcd::test {
namespace {

namespace fs = std::filesystem;

// Relative closeness for float results of double sums.
void ExpectClose(float got, double want, const std::string &what) {
    EXPECT_LE(std::abs(got - want), 1e-5 * std::max(1.0, std::abs(want))) << what;
}

// A float result of a double computation on values of magnitude `scale` (the sum of their
// absolute values or squares): its rounding to float (under eps |want|) and the double
// roundings of those sums in another order (far under 1e-14 scale for a few frames).
void ExpectFloatOf(float got, double want, double scale, const std::string &what) {
    EXPECT_LE(std::abs(got - want),
              std::numeric_limits<float>::epsilon() * std::abs(want) + 1e-14 * scale)
        << what << ": " << got << " for " << want;
}

// The samples' histograms at a pixel, binned directly by the renderer's rule.
std::vector<float> BinnedSamples(const std::vector<io::Frame> &in, int x, int y, int bins) {
    std::vector<float> direct(3 * bins, 0.f);
    for (const io::Frame &f : in) {
        double v[3];
        for (int c = 0; c < 3; ++c) v[c] = f.Get("color").At(c, y, x);
        render::AddToHistogram(v, bins, direct.data());
    }
    return direct;
}

// A channel's statistics over the frames at a pixel, computed directly.
struct SampleStats {
    double sum = 0, sumSq = 0, magnitude = 0, lo = INFINITY, hi = -INFINITY, halves[2] = {};
};

SampleStats StatsOf(const std::vector<io::Frame> &in, int c, int x, int y) {
    SampleStats s;
    for (size_t k = 0; k < in.size(); ++k) {
        double v = in[k].Get("color").At(c, y, x);
        s.sum += v, s.sumSq += v * v, s.magnitude += std::abs(v), s.halves[k % 2] += v;
        s.lo = std::min(s.lo, v), s.hi = std::max(s.hi, v);
    }
    return s;
}

class CliAccumulate : public ::testing::Test {
  protected:
    ToolResult Run(const std::string &args) { return tool.Run(args); }
    std::string Path(const std::string &name) const { return tool.Path(name).string(); }
    // Renders cornell 14x10 frames f1.exr .. fN.exr (seeds 1..N, every layer) and returns
    // their names for accumulate's command line (" f1.exr f2.exr ...").
    std::string RenderFrames(int count, int spp) {
        std::string inputs;
        for (int k = 1; k <= count; ++k) {
            ToolResult r =
                Run(fmt::format("render --scene cornell --size 14x10 --spp {} --seed {} "
                                "--layers all -o f{}.exr",
                                spp, k, k));
            EXPECT_EQ(r.code, 0) << r.All();
            inputs += fmt::format(" f{}.exr", k);
        }
        return inputs;
    }
    ToolDir tool{"mcd_accumulate_cli"};
};

// Five 1-spp frames are five samples per pixel: the accumulated frame must hold their
// mean, unbiased variance / 5, range, per-sample histograms (as the renderer bins them)
// and the carried layers.
TEST_F(CliAccumulate, OneSppFramesGiveTheirSamplesStatistics) {
    const int frames = 5, bins = 20;
    const std::string inputs = RenderFrames(frames, 1);
    ASSERT_FALSE(HasFailure());
    ToolResult r = Run("accumulate" + inputs + " -o acc.exr");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(Contains(r.out, "5 frames 14x10")) << r.out;
    // Every layer of --layers all is carried or made anew.
    EXPECT_FALSE(Contains(r.out, "not carried")) << r.out;

    std::vector<io::Frame> in;
    for (int k = 1; k <= frames; ++k)
        in.push_back(io::ReadFrame(Path(fmt::format("f{}.exr", k))));
    io::Frame acc = io::ReadFrame(Path("acc.exr"));
    for (const char *layer :
         {"color", "variance", "spp", "min", "max", "hist", "albedo", "normal", "depth",
          "pivot", "direct", "indirect", "direct.variance", "indirect.variance", "objectId",
          "partId", "half0.color", "half1.color"})
        ASSERT_TRUE(acc.Has(layer)) << layer;
    EXPECT_EQ(acc.metadata["mcd:spp"], "5");
    const Image &hist = acc.Get("hist");
    ASSERT_EQ(hist.channels, 3 * bins + 1);

    for (int y = 0; y < 10; ++y)
        for (int x = 0; x < 14; ++x) {
            std::string at = fmt::format(" at ({}, {})", x, y);
            // The histogram of the samples, binned by the renderer's own rule.
            std::vector<float> direct = BinnedSamples(in, x, y, bins);
            for (int b = 0; b < 3 * bins; ++b) {
                EXPECT_EQ(hist.At(b, y, x), direct[b]) << "bin " << b << at;
                // And the renderer's 1-spp histograms, summed: the same up to float rounding
                // of the sample.
                double sum = 0;
                for (const io::Frame &f : in) sum += f.Get("hist").At(b, y, x);
                EXPECT_NEAR(hist.At(b, y, x), sum, 1e-4) << "bin " << b << at;
            }
            EXPECT_EQ(hist.At(3 * bins, y, x), float(frames)) << at;
            EXPECT_EQ(acc.Get("spp").At(0, y, x), float(frames)) << at;
            for (int c = 0; c < 3; ++c) {
                auto [sum, sumSq, magnitude, lo, hi, halves] = StatsOf(in, c, x, y);
                double mean = sum / frames;
                double variance = (sumSq - frames * mean * mean) / (frames - 1) / frames;
                ExpectClose(acc.Get("color").At(c, y, x), mean, "color" + at);
                EXPECT_NEAR(acc.Get("variance").At(c, y, x), std::max(0.0, variance),
                            1e-5 * std::max(1.0, mean * mean))
                    << "variance" << at;
                EXPECT_EQ(acc.Get("min").At(c, y, x), float(lo)) << at;
                EXPECT_EQ(acc.Get("max").At(c, y, x), float(hi)) << at;
                ExpectClose(acc.Get("half0.color").At(c, y, x), halves[0] / 3, "half0" + at);
                ExpectClose(acc.Get("half1.color").At(c, y, x), halves[1] / 2, "half1" + at);
                double albedo = 0;
                for (const io::Frame &f : in) albedo += f.Get("albedo").At(c, y, x);
                ExpectClose(acc.Get("albedo").At(c, y, x), albedo / frames, "albedo" + at);
                // The split's parts: the variances of their means as color's.
                for (const char *layer : {"direct", "indirect"}) {
                    double partSum = 0, partSq = 0;
                    for (const io::Frame &f : in) {
                        double v = f.Get(layer).At(c, y, x);
                        partSum += v, partSq += v * v;
                    }
                    double partMean = partSum / frames;
                    double partVariance =
                        (partSq - frames * partMean * partMean) / (frames - 1) / frames;
                    EXPECT_NEAR(acc.Get(std::string(layer) + ".variance").At(c, y, x),
                                std::max(0.0, partVariance),
                                1e-5 * std::max(1.0, partMean * partMean))
                        << layer << ".variance" << at;
                }
            }
            EXPECT_EQ(acc.Get("objectId").At(0, y, x), in[0].Get("objectId").At(0, y, x));
        }
}

// half0's own layers: each half0.<layer> is that layer of the even frames (1, 3, 5 here)
// accumulated alone, to the bit, written and read back under its own name (the frame's
// layer of that name untouched); --no-half0-layers writes half0.color alone, the rest the
// same bits.
TEST_F(CliAccumulate, WritesHalf0sOwnLayersFromItsFramesAlone) {
    const std::string inputs = RenderFrames(5, 2);
    ASSERT_FALSE(HasFailure());
    ToolResult r = Run("accumulate" + inputs + " -o acc.exr");
    ASSERT_EQ(r.code, 0) << r.All();
    ASSERT_EQ(Run("accumulate f1.exr f3.exr f5.exr -o even.exr").code, 0);
    r = Run("accumulate" + inputs + " --no-half0-layers -o plain.exr");
    ASSERT_EQ(r.code, 0) << r.All();
    io::Frame acc = io::ReadFrame(Path("acc.exr")), even = io::ReadFrame(Path("even.exr")),
              plain = io::ReadFrame(Path("plain.exr"));
    int own = 0;
    for (const std::string &name : io::Half0Layers()) {
        if (!even.Has(name)) continue;
        ++own;
        ASSERT_TRUE(acc.Has("half0." + name)) << name;
        EXPECT_EQ(acc.Get("half0." + name).channels, even.Get(name).channels) << name;
        EXPECT_EQ(acc.Get("half0." + name).data, even.Get(name).data) << name;
        EXPECT_FALSE(plain.Has("half0." + name)) << name;
        EXPECT_EQ(acc.Get(name).data, plain.Get(name).data) << name;
    }
    // Features, statistics and the split's parts: every layer of --layers all but the ids.
    EXPECT_EQ(own, 13);
    EXPECT_NE(acc.Get("half0.albedo").data, acc.Get("albedo").data);
    EXPECT_NE(acc.Get("half0.hist").data, acc.Get("hist").data);
    for (int c = 0; c < 3; ++c)
        for (int i = 0; i < 14 * 10; ++i)
            ExpectClose(acc.Get("half0.color").Plane(c)[i], even.Get("color").Plane(c)[i],
                        "half0.color");
    EXPECT_EQ(acc.Get("half0.color").data, plain.Get("half0.color").data);
    EXPECT_FALSE(acc.Has("half0.objectId"));
    // One frame: no halves to keep apart; two: half0 holds one frame, whose variances are 0.
    io::Accumulator one, two, three;
    one.Add(io::ReadFrame(Path("f1.exr")));
    EXPECT_FALSE(one.Finish().Has("half0.albedo"));
    for (int k = 1; k <= 3; ++k) {
        io::Frame frame = io::ReadFrame(Path(fmt::format("f{}.exr", k)));
        if (k <= 2) two.Add(frame);
        three.Add(frame);
    }
    io::Frame twoOut = two.Finish(), threeOut = three.Finish();
    EXPECT_FALSE(twoOut.Has("half0.variance"));
    EXPECT_FALSE(twoOut.Has("half0.albedo"));
    EXPECT_TRUE(threeOut.Has("half0.variance"));
    EXPECT_TRUE(threeOut.Has("half0.albedo"));
}

TEST_F(CliAccumulate, RefusesMismatchedFramesNamingTheFile) {
    ASSERT_EQ(Run("render --size 12x8 --spp 1 --seed 1 -o a.exr").code, 0);
    ASSERT_EQ(Run("render --size 12x8 --spp 1 --seed 2 -o b.exr").code, 0);
    ASSERT_EQ(Run("render --size 12x9 --spp 1 --seed 3 -o small.exr").code, 0);
    ASSERT_EQ(Run("render --size 12x8 --spp 1 --seed 4 --layers pivot -o more.exr").code, 0);
    ToolResult r = Run("accumulate a.exr b.exr small.exr -o acc.exr");
    EXPECT_EQ(r.code, int(tool::ExitStatus::InvalidArgument));
    EXPECT_TRUE(Contains(r.err, "'small.exr' is 12x9")) << r.err;
    r = Run("accumulate a.exr more.exr b.exr -o acc.exr");
    EXPECT_EQ(r.code, int(tool::ExitStatus::InvalidArgument));
    EXPECT_TRUE(Contains(r.err, "'more.exr' has layers")) << r.err;
    EXPECT_FALSE(fs::exists(Path("acc.exr")));

    // The library refuses too, and its sums stay as they were.
    io::Accumulator accumulator;
    accumulator.Add(io::ReadFrame(Path("a.exr")));
    io::Frame small = io::ReadFrame(Path("small.exr"));
    EXPECT_TRUE(ThrowsError(
        ErrorKind::InvalidArgument, [&] { accumulator.Add(small); }, "small.exr"));
    EXPECT_EQ(accumulator.Frames(), 1);
}

TEST_F(CliAccumulate, RefusesWritingOntoAnInput) {
    ASSERT_EQ(Run("render --size 12x8 --spp 1 --seed 1 -o a.exr").code, 0);
    ASSERT_EQ(Run("render --size 12x8 --spp 1 --seed 2 -o b.exr").code, 0);
    io::Frame before = io::ReadFrame(Path("b.exr"));
    ToolResult r = Run("accumulate a.exr b.exr -o ./b.exr");
    EXPECT_EQ(r.code, int(tool::ExitStatus::InvalidArgument));
    EXPECT_TRUE(Contains(r.err, "b.exr")) << r.err;
    EXPECT_EQ(io::ReadFrame(Path("b.exr")).Get("color").data, before.Get("color").data);
}

// A NaN in one frame's color and an Inf in another's albedo: counted per layer, and the
// pixel's statistics are those of the other frames, its count and spp one fewer.
TEST_F(CliAccumulate, CountsNonFiniteAndLeavesThemOut) {
    const int w = 4, h = 3;
    for (int k = 0; k < 3; ++k) {
        Image color(w, h, 3), albedo(w, h, 3);
        for (size_t i = 0; i < color.data.size(); ++i)
            color.data[i] = float(k + 1), albedo.data[i] = 0.5f;
        if (k == 1) color.At(1, 2, 3) = std::numeric_limits<float>::quiet_NaN();
        if (k == 2) albedo.At(0, 0, 0) = std::numeric_limits<float>::infinity();
        io::WriteExr(Path(fmt::format("n{}.exr", k)), {{"color", &color}, {"albedo", &albedo}},
                     {{"mcd:spp", "4"}});
    }
    ToolResult r = Run("accumulate n0.exr n1.exr n2.exr -o acc.exr");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(Contains(r.out, "1 NaN/Inf pixel values in layer color")) << r.out;
    EXPECT_TRUE(Contains(r.out, "1 NaN/Inf pixel values in layer albedo")) << r.out;
    io::Frame acc = io::ReadFrame(Path("acc.exr"));
    EXPECT_EQ(acc.metadata["mcd:spp"], "12");
    for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(acc.Get("color").At(c, 2, 3), 2.f);         // (1 + 3) / 2
        EXPECT_EQ(acc.Get("variance").At(c, 2, 3), 2.f / 2);  // s^2 = 2, over 2 frames
        EXPECT_EQ(acc.Get("color").At(c, 0, 0), 2.f);         // (1 + 2 + 3) / 3
        EXPECT_NEAR(acc.Get("variance").At(c, 0, 0), 1.f / 3, 1e-7);
        EXPECT_EQ(acc.Get("albedo").At(c, 0, 0), 0.5f);
        EXPECT_EQ(acc.Get("half1.color").At(c, 2, 3), 0.f);  // its only frame was NaN
    }
    EXPECT_EQ(acc.Get("spp").At(0, 2, 3), 8.f);
    EXPECT_EQ(acc.Get("spp").At(0, 0, 0), 12.f);
    EXPECT_EQ(acc.Get("hist").At(60, 2, 3), 2.f);
}

// Frames that state no sample count are counted 1 spp each, which is said once on stderr;
// frames with a count in their metadata, or an spp layer, say nothing of it.
TEST_F(CliAccumulate, WarnsOnceWhenTheFramesStateNoSampleCount) {
    for (int k = 0; k < 3; ++k) {
        Image color(4, 3, 3, float(k + 1)), spp(4, 3, 1, 8.f);
        io::WriteExr(Path(fmt::format("u{}.exr", k)), {{"color", &color}});
        io::WriteExr(Path(fmt::format("s{}.exr", k)), {{"color", &color}}, {{"mcd:spp", "4"}});
        io::WriteExr(Path(fmt::format("l{}.exr", k)), {{"color", &color}, {"spp", &spp}});
    }
    const std::string warning = "the frames state no sample count";
    ToolResult r = Run("accumulate u0.exr u1.exr u2.exr -o u.exr");
    ASSERT_EQ(r.code, 0) << r.All();
    size_t at = r.err.find(warning);
    ASSERT_NE(at, std::string::npos) << r.err;
    EXPECT_EQ(r.err.find(warning, at + 1), std::string::npos) << "said twice: " << r.err;
    EXPECT_TRUE(Contains(r.err, "counts 1 spp per frame, so the spp layer is 3")) << r.err;
    EXPECT_TRUE(Contains(r.err, "mcd:spp")) << r.err;
    EXPECT_EQ(io::ReadFrame(Path("u.exr")).Get("spp").At(0, 2, 3), 3.f);
    for (const char *set : {"s", "l"}) {
        r = Run(fmt::format("accumulate {0}0.exr {0}1.exr {0}2.exr -o {0}.exr", set));
        ASSERT_EQ(r.code, 0) << r.All();
        EXPECT_FALSE(Contains(r.All(), warning)) << set << ": " << r.All();
    }
}

// Layers the frames have that the result does not carry are named, whether accumulate
// read them (a renderer's pass) or not (partials); those made anew (variance) are not.
TEST_F(CliAccumulate, NamesTheLayersItDoesNotCarry) {
    for (int k = 0; k < 2; ++k) {
        Image color(3, 2, 3), variance(3, 2, 3), partial(3, 2, 3), emission(3, 2, 3);
        for (size_t i = 0; i < color.data.size(); ++i) color.data[i] = float(k + i);
        io::WriteExr(Path(fmt::format("p{}.exr", k)), {{"color", &color},
                                                       {"variance", &variance},
                                                       {"partial0.color", &partial},
                                                       {"Emission", &emission}});
    }
    ToolResult r = Run("accumulate p0.exr p1.exr -o acc.exr");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(Contains(r.out, "not carried: Emission, partial0.color\n")) << r.out;
    io::Frame acc = io::ReadFrame(Path("acc.exr"));
    EXPECT_FALSE(acc.Has("partial0.color"));
    EXPECT_EQ(acc.Get("color").At(0, 0, 0), 0.5f);
}

// Frames of one 7x5 view: albedo, normal and depth drawn from `geometrySeed`, color from
// `colorSeed` (Cycles' unjittered 1-spp frames: the same first hits, other paths).
io::Frame RayFrame(unsigned geometrySeed, unsigned colorSeed,
                   const std::vector<std::string> &geometry = {"albedo", "normal", "depth"}) {
    const int w = 7, h = 5;
    std::mt19937 rng(geometrySeed);
    std::uniform_real_distribution<float> u(-1.f, 4.f);
    io::Frame frame;
    frame.path = fmt::format("frame{}.exr", colorSeed);
    frame.width = w, frame.height = h;
    for (const std::string &name : geometry) {
        Image image(w, h, name == "depth" ? 1 : 3);
        for (float &v : image.data) v = u(rng);
        frame.layers[name] = std::move(image);
    }
    rng.seed(1000 + colorSeed);
    Image color(w, h, 3);
    for (float &v : color.data) v = u(rng);
    frame.layers["color"] = std::move(color);
    return frame;
}

io::CameraRays Accumulate(const std::vector<io::Frame> &frames, io::Frame *out = nullptr) {
    io::Accumulator accumulator;
    for (const io::Frame &frame : frames) accumulator.Add(frame);
    io::Frame result = accumulator.Finish();
    if (out) *out = std::move(result);
    return accumulator.SharedCameraRays();
}

// The same albedo, normal and depth bits in every frame and other colors: shared rays,
// with the layers compared named and the output marked.
TEST(IoTestAccumulateRays, SameGeometryOtherColorsShareRays) {
    io::Accumulator accumulator;
    for (unsigned k = 0; k < 4; ++k) accumulator.Add(RayFrame(7, k));
    EXPECT_EQ(accumulator.SharedCameraRays(), io::CameraRays::Shared);
    EXPECT_EQ(accumulator.RayLayers(), (std::vector<std::string>{"albedo", "normal", "depth"}));
    EXPECT_EQ(accumulator.Finish().metadata["mcd:sharedCameraRays"], "1");

    // Color that differs at one pixel of the last frame only is enough.
    std::vector<io::Frame> frames = {RayFrame(7, 0), RayFrame(7, 0), RayFrame(7, 0)};
    frames[2].layers["color"].At(1, 4, 6) += 1.f;
    EXPECT_EQ(Accumulate(frames), io::CameraRays::Shared);
    // One geometry layer is enough to tell; NaN depth at the same pixel (same bits) in every
    // frame does not stop it.
    frames = {RayFrame(7, 0, {"depth"}), RayFrame(7, 1, {"depth"})};
    for (io::Frame &f : frames) f.layers["depth"].At(0, 2, 3) = std::nanf("");
    io::Accumulator depthOnly;
    for (const io::Frame &f : frames) depthOnly.Add(f);
    EXPECT_EQ(depthOnly.SharedCameraRays(), io::CameraRays::Shared);
    EXPECT_EQ(depthOnly.RayLayers(), std::vector<std::string>{"depth"});
}

// One depth value of one frame one ulp off (last frame, last pixel), or one normal, or
// +0 against -0: the rays differ, and the output says so.
TEST(IoTestAccumulateRays, OneValueDifferentIsDistinct) {
    std::vector<io::Frame> frames = {RayFrame(7, 0), RayFrame(7, 1), RayFrame(7, 2)};
    float &depth = frames[2].layers["depth"].At(0, 4, 6);
    depth = std::nextafter(depth, INFINITY);
    io::Frame out;
    EXPECT_EQ(Accumulate(frames, &out), io::CameraRays::Distinct);
    EXPECT_EQ(out.metadata["mcd:sharedCameraRays"], "0");

    frames = {RayFrame(7, 0), RayFrame(7, 1), RayFrame(7, 2)};
    frames[1].layers["normal"].At(2, 0, 0) += 0.5f;
    EXPECT_EQ(Accumulate(frames), io::CameraRays::Distinct);

    frames = {RayFrame(7, 0, {"depth"}), RayFrame(7, 1, {"depth"})};
    frames[0].layers["depth"].At(0, 1, 1) = 0.f;
    frames[1].layers["depth"].At(0, 1, 1) = -0.f;
    EXPECT_EQ(Accumulate(frames), io::CameraRays::Distinct);
    // Frames whose geometry differs everywhere (a jittered camera).
    EXPECT_EQ(Accumulate({RayFrame(1, 0), RayFrame(2, 1)}), io::CameraRays::Distinct);
}

// No albedo, normal or depth and colors that differ, or a single frame: it cannot tell,
// and writes no metadata.
TEST(IoTestAccumulateRays, WithoutGeometryCannotTell) {
    io::Accumulator accumulator;
    accumulator.Add(RayFrame(7, 0, {}));
    accumulator.Add(RayFrame(7, 1, {}));
    EXPECT_EQ(accumulator.SharedCameraRays(), io::CameraRays::Unknown);
    EXPECT_TRUE(accumulator.RayLayers().empty());
    EXPECT_EQ(accumulator.Finish().metadata.count("mcd:sharedCameraRays"), 0u);

    io::Accumulator one;
    one.Add(RayFrame(7, 0));
    EXPECT_EQ(one.SharedCameraRays(), io::CameraRays::Unknown);
    EXPECT_EQ(one.Finish().metadata.count("mcd:sharedCameraRays"), 0u);
}

// Frames equal in color too are one render repeated: Identical (they share their rays, so
// the output says 1), with or without geometry layers; a color that differs anywhere
// makes them Shared.
TEST(IoTestAccumulateRays, IdenticalFramesAreIdentical) {
    io::Frame out;
    EXPECT_EQ(Accumulate({RayFrame(7, 3), RayFrame(7, 3), RayFrame(7, 3)}, &out),
              io::CameraRays::Identical);
    EXPECT_EQ(out.metadata["mcd:sharedCameraRays"], "1");
    EXPECT_EQ(Accumulate({RayFrame(7, 3, {}), RayFrame(7, 3, {})}), io::CameraRays::Identical);
    std::vector<io::Frame> frames = {RayFrame(7, 3), RayFrame(7, 3)};
    frames[1].layers["color"].At(0, 0, 0) =
        std::nextafter(frames[1].layers["color"].At(0, 0, 0), 0.f);
    EXPECT_EQ(Accumulate(frames), io::CameraRays::Shared);
}

// The tool warns about shared rays naming the frames, the layers, the cause and the cure,
// and marks the output; our renderer's jittered frames get no such warning.
TEST_F(CliAccumulate, WarnsAboutSharedCameraRays) {
    std::string inputs;
    for (unsigned k = 0; k < 3; ++k) {
        io::Frame f = RayFrame(7, k);
        std::string name = fmt::format("r{}.exr", k);
        io::WriteExr(Path(name),
                     {{"color", &f.Get("color")},
                      {"albedo", &f.Get("albedo")},
                      {"normal", &f.Get("normal")},
                      {"depth", &f.Get("depth")}},
                     {{"mcd:spp", "1"}});
        inputs += " " + name;
    }
    ToolResult r = Run("accumulate" + inputs + " -o acc.exr");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(Contains(r.out,
                         "warning: the 3 frames share their camera rays (albedo, "
                         "normal, depth the same at every pixel"))
        << r.out;
    for (const char *part : {"point-sampled (aliased at edges)", "pixel-filtered",
                             "sample 0 through the pixel centre whatever the seed",
                             "scripts/blender/common.py --jitter", "one frame of 3 spp"})
        EXPECT_TRUE(Contains(r.out, part)) << part << "\n" << r.out;
    EXPECT_EQ(io::ReadFrame(Path("acc.exr")).metadata["mcd:sharedCameraRays"], "1");

    // Without the geometry layers it says it cannot tell.
    for (unsigned k = 0; k < 2; ++k) {
        io::Frame f = RayFrame(7, k, {});
        io::WriteExr(Path(fmt::format("c{}.exr", k)), {{"color", &f.Get("color")}});
    }
    r = Run("accumulate c0.exr c1.exr -o plain.exr");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_FALSE(Contains(r.out, "share their camera rays (")) << r.out;
    EXPECT_TRUE(Contains(r.out, "cannot check whether the frames share their camera rays"))
        << r.out;

    for (int k = 1; k <= 2; ++k)
        ASSERT_EQ(Run(fmt::format(
                          "render --size 12x8 --spp 1 --seed {} --layers all -o g{}.exr", k, k))
                      .code,
                  0);
    r = Run("accumulate g1.exr g2.exr -o jittered.exr");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_FALSE(Contains(r.out, "camera rays")) << r.out;
    EXPECT_EQ(io::ReadFrame(Path("jittered.exr")).metadata["mcd:sharedCameraRays"], "0");
}

// Real Cycles frames (tests/data/README.md says how they were made): copied into the
// test's directory so that the tool's arguments are plain names.
std::string CopyFixtures(const ToolDir &tool, const std::vector<std::string> &names) {
    std::string inputs;
    for (const std::string &name : names) {
        fs::copy_file(fs::path(MCD_SOURCE_DIR) / "tests/data" / name, tool.Path(name),
                      fs::copy_options::overwrite_existing);
        inputs += " " + name;
    }
    return inputs;
}

// Four jittered 1-spp Cycles frames (independent camera rays) accumulate to the
// statistics of their samples as ReadFrame reads them (color from Combined, direct and
// indirect composed from the light passes, spp from Debug Sample Count), with no
// shared-ray warning.
TEST_F(CliAccumulate, RealCyclesFramesGiveTheirSamplesStatistics) {
    const int frames = 4, bins = 20, w = 24, h = 24;
    std::vector<std::string> names;
    for (int k = 1; k <= frames; ++k)
        names.push_back(fmt::format("cycles_cornell_24_1spp_j{}.exr", k));
    std::string inputs = CopyFixtures(tool, names);
    ToolResult r = Run("accumulate" + inputs + " -o acc.exr");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(Contains(r.out, "4 frames 24x24")) << r.out;
    EXPECT_FALSE(Contains(r.out, "camera rays")) << r.out;
    EXPECT_FALSE(Contains(r.out, "NaN/Inf")) << r.out;

    std::vector<io::Frame> in;
    for (const std::string &name : names) {
        in.push_back(io::ReadFrame(Path(name)));
        ASSERT_EQ(in.back().width, w);
        ASSERT_EQ(in.back().height, h);
        EXPECT_TRUE(Contains(in.back().metadata[io::kConventionKey],
                             "read as Blender Cycles multilayer"))
            << name;
    }
    io::Frame acc = io::ReadFrame(Path("acc.exr"));
    for (const char *layer :
         {"color", "variance", "spp", "min", "max", "hist", "albedo", "normal", "depth",
          "direct", "indirect", "direct.variance", "indirect.variance", "objectId", "partId",
          "half0.color", "half1.color"})
        ASSERT_TRUE(acc.Has(layer)) << layer;
    EXPECT_EQ(acc.metadata["mcd:sharedCameraRays"], "0");
    EXPECT_EQ(acc.metadata["mcd:spp"], "4");  // cycles.ViewLayer.samples = 1 per frame
    const Image &hist = acc.Get("hist");
    ASSERT_EQ(hist.channels, 3 * bins + 1);

    int idsDiffer = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            std::string at = fmt::format(" at ({}, {})", x, y);
            std::vector<float> direct = BinnedSamples(in, x, y, bins);
            for (int b = 0; b < 3 * bins; ++b)
                EXPECT_EQ(hist.At(b, y, x), direct[b]) << "bin " << b << at;
            EXPECT_EQ(hist.At(3 * bins, y, x), float(frames)) << at;
            // Each frame's Debug Sample Count (1) x its 1 sample.
            EXPECT_EQ(acc.Get("spp").At(0, y, x), float(frames)) << at;
            for (int c = 0; c < 3; ++c) {
                auto [sum, sumSq, magnitude, lo, hi, halves] = StatsOf(in, c, x, y);
                // Two passes here, Welford's running sums in the accumulator.
                double mean = sum / frames, squares = 0;
                for (const io::Frame &f : in) {
                    double v = f.Get("color").At(c, y, x);
                    squares += (v - mean) * (v - mean);
                }
                ExpectFloatOf(acc.Get("color").At(c, y, x), mean, magnitude, "color" + at);
                ExpectFloatOf(acc.Get("variance").At(c, y, x), squares / (frames - 1) / frames,
                              sumSq, "variance" + at);
                EXPECT_EQ(acc.Get("min").At(c, y, x), float(lo)) << at;
                EXPECT_EQ(acc.Get("max").At(c, y, x), float(hi)) << at;
                ExpectFloatOf(acc.Get("half0.color").At(c, y, x), halves[0] / 2, magnitude,
                              "half0" + at);
                ExpectFloatOf(acc.Get("half1.color").At(c, y, x), halves[1] / 2, magnitude,
                              "half1" + at);
                // The guides and the composed light passes: means of what each frame reads.
                for (const char *layer : {"albedo", "normal", "direct", "indirect"}) {
                    double layerSum = 0, layerMagnitude = 0;
                    for (const io::Frame &f : in) {
                        layerSum += f.Get(layer).At(c, y, x);
                        layerMagnitude += std::abs(f.Get(layer).At(c, y, x));
                    }
                    ExpectFloatOf(acc.Get(layer).At(c, y, x), layerSum / frames, layerMagnitude,
                                  layer + at);
                }
                // The composed parts' variances of the mean, as color's.
                for (const std::string layer : {"direct", "indirect"}) {
                    double layerMean = 0;
                    for (const io::Frame &f : in) layerMean += f.Get(layer).At(c, y, x);
                    layerMean /= frames;
                    double layerSquares = 0, layerSumSq = 0;
                    for (const io::Frame &f : in) {
                        double v = f.Get(layer).At(c, y, x);
                        layerSquares += (v - layerMean) * (v - layerMean), layerSumSq += v * v;
                    }
                    ExpectFloatOf(acc.Get(layer + ".variance").At(c, y, x),
                                  layerSquares / (frames - 1) / frames, layerSumSq,
                                  layer + ".variance" + at);
                }
            }
            double depth = 0;
            for (const io::Frame &f : in) depth += f.Get("depth").At(0, y, x);
            ExpectFloatOf(acc.Get("depth").At(0, y, x), depth / frames, depth, "depth" + at);
            for (const char *layer : {"objectId", "partId"}) {
                EXPECT_EQ(acc.Get(layer).At(0, y, x), in[0].Get(layer).At(0, y, x))
                    << layer << at;
                for (const io::Frame &f : in)
                    idsDiffer += f.Get(layer).At(0, y, x) != in[0].Get(layer).At(0, y, x);
            }
        }
    // The jitter moves edges across pixels: "from the first frame" is not "from any".
    EXPECT_GT(idsDiffer, 0);
}

// Per frame, ReadFrame's direct is Cycles' direct light passes composed
// (sum of XDir XCol + Emit + Env + VolumeDir) and direct + indirect is Combined.
TEST(IoTestCyclesFixtures, DirectAndIndirectComposeTheLightPasses) {
    const double eps = std::numeric_limits<float>::epsilon();
    for (int k = 1; k <= 4; ++k) {
        std::string name = fmt::format("cycles_cornell_24_1spp_j{}.exr", k);
        io::Frame f = io::ReadFrame(std::string(MCD_SOURCE_DIR) + "/tests/data/" + name);
        const Image &color = f.Get("color"), &direct = f.Get("direct"),
                    &indirect = f.Get("indirect");
        double directTotal = 0;
        for (size_t i = 0; i < color.Size(); ++i) {
            // Composed here in double: the reader's float sum of 6 products is within a
            // few float roundings of its terms' magnitude.
            double want = 0, magnitude = 0;
            for (const char *x : {"Diff", "Gloss", "Trans"}) {
                double term = double(f.Get(std::string(x) + "Dir").data[i]) *
                              f.Get(std::string(x) + "Col").data[i];
                want += term, magnitude += std::abs(term);
            }
            for (const char *pass : {"Emit", "Env", "VolumeDir"})
                want += f.Get(pass).data[i], magnitude += std::abs(f.Get(pass).data[i]);
            EXPECT_NEAR(direct.data[i], want, 8 * eps * magnitude) << name << " value " << i;
            // indirect gets color - direct - (its passes) added: one rounding per term.
            EXPECT_NEAR(double(direct.data[i]) + indirect.data[i], color.data[i],
                        4 * eps * (std::abs(direct.data[i]) + std::abs(color.data[i])))
                << name << " value " << i;
            directTotal += direct.data[i];
        }
        EXPECT_GT(directTotal, 0) << name;  // the box is lit: the check is not 0 = 0
    }
}

// Two unjittered 1-spp Cycles frames (seeds 1, 2) share every camera ray: the same
// albedo, normal and depth bits, another colour. Accumulate warns and marks the output.
TEST_F(CliAccumulate, WarnsAboutRealCyclesFramesSharingCameraRays) {
    std::vector<std::string> names = {"cycles_cornell_24_1spp_s1.exr",
                                      "cycles_cornell_24_1spp_s2.exr"};
    std::string inputs = CopyFixtures(tool, names);
    io::Frame a = io::ReadFrame(Path(names[0])), b = io::ReadFrame(Path(names[1]));
    for (const char *layer : {"albedo", "normal", "depth"})
        EXPECT_EQ(std::memcmp(a.Get(layer).data.data(), b.Get(layer).data.data(),
                              a.Get(layer).data.size() * sizeof(float)),
                  0)
            << layer;
    EXPECT_NE(a.Get("color").data, b.Get("color").data);

    ToolResult r = Run("accumulate" + inputs + " -o acc.exr");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(Contains(r.out,
                         "warning: the 2 frames share their camera rays (albedo, "
                         "normal, depth the same at every pixel, the color not)"))
        << r.out;
    EXPECT_TRUE(Contains(r.out, "or render one frame of 2 spp")) << r.out;
    io::Frame acc = io::ReadFrame(Path("acc.exr"));
    EXPECT_EQ(acc.metadata["mcd:sharedCameraRays"], "1");
    // The mean of two equal values is that value: the guides come through unchanged.
    EXPECT_EQ(acc.Get("albedo").data, a.Get("albedo").data);
}

// The accumulator's binning is the renderer's, value for value.
TEST(IoAccumulate, BinsAsTheRenderer) {
    for (int bins : {3, 20}) {
        for (double v : {-1.0, 0.0, 1e-6, 0.01, 0.3, 1.0, 2.5, 6.0, 15.0, 1e4}) {
            double color[3] = {v, v * 0.5, v * 2};
            std::vector<float> ours(3 * bins, 0.f), renderer(3 * bins, 0.f);
            io::AddToRhfHistogram(color, bins, ours.data());
            render::AddToHistogram(color, bins, renderer.data());
            EXPECT_EQ(ours, renderer) << v << " with " << bins << " bins";
        }
    }
}

}  // namespace
}  // namespace mcd::test
