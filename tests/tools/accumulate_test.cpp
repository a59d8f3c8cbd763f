// `mcdenoise accumulate` (issue #16) and host/io/accumulate.h: 1-spp frames from the
// renderer with different seeds accumulate to exactly the statistics of their samples
// (computed here directly); mismatched frames are refused naming the file; NaN/Inf are
// counted and left out; the output may not be an input.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "harness/tool.h"
#include "host/error.h"
#include "host/image.h"
#include "host/io/accumulate.h"
#include "host/io/frame.h"
#include "tools/render/renderer.h"

namespace mcd::test {
namespace {

namespace fs = std::filesystem;

bool Contains(const std::string &text, const std::string &part) {
    return text.find(part) != std::string::npos;
}

// Relative closeness for float results of double sums.
void ExpectClose(float got, double want, const std::string &what) {
    EXPECT_LE(std::abs(got - want), 1e-5 * std::max(1.0, std::abs(want))) << what;
}

class CliAccumulate : public ::testing::Test {
  protected:
    ToolResult Run(const std::string &args) { return tool.Run(args); }
    std::string Path(const std::string &name) const { return tool.Path(name).string(); }
    ToolDir tool{"mcd_accumulate_cli"};
};

// Five 1-spp frames are five samples per pixel: the accumulated frame must hold their
// mean, unbiased variance / 5, range, per-sample histograms (as the renderer bins them)
// and the carried layers.
TEST_F(CliAccumulate, OneSppFramesGiveTheirSamplesStatistics) {
    const int frames = 5, bins = 20;
    std::string inputs;
    for (int k = 1; k <= frames; ++k) {
        ToolResult r = Run(fmt::format(
            "render --scene cornell --size 14x10 --spp 1 --seed {} --layers all -o f{}.exr", k,
            k));
        ASSERT_EQ(r.code, 0) << r.All();
        inputs += fmt::format(" f{}.exr", k);
    }
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
          "pivot", "direct", "indirect", "objectId", "partId", "half0.color", "half1.color"})
        ASSERT_TRUE(acc.Has(layer)) << layer;
    EXPECT_EQ(acc.metadata["mcd:spp"], "5");
    const Image &hist = acc.Get("hist");
    ASSERT_EQ(hist.channels, 3 * bins + 1);

    for (int y = 0; y < 10; ++y)
        for (int x = 0; x < 14; ++x) {
            std::string at = fmt::format(" at ({}, {})", x, y);
            // The histogram of the samples, binned by the renderer's own rule.
            std::vector<float> direct(3 * bins, 0.f);
            for (const io::Frame &f : in) {
                double v[3];
                for (int c = 0; c < 3; ++c) v[c] = f.Get("color").At(c, y, x);
                render::AddToHistogram(v, bins, direct.data());
            }
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
                double sum = 0, sumSq = 0, lo = INFINITY, hi = -INFINITY, halves[2] = {};
                for (int k = 0; k < frames; ++k) {
                    double v = in[k].Get("color").At(c, y, x);
                    sum += v, sumSq += v * v, halves[k % 2] += v;
                    lo = std::min(lo, v), hi = std::max(hi, v);
                }
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
            }
            EXPECT_EQ(acc.Get("objectId").At(0, y, x), in[0].Get("objectId").At(0, y, x));
        }
}

TEST_F(CliAccumulate, RefusesMismatchedFramesNamingTheFile) {
    ASSERT_EQ(Run("render --size 12x8 --spp 1 --seed 1 -o a.exr").code, 0);
    ASSERT_EQ(Run("render --size 12x8 --spp 1 --seed 2 -o b.exr").code, 0);
    ASSERT_EQ(Run("render --size 12x9 --spp 1 --seed 3 -o small.exr").code, 0);
    ASSERT_EQ(Run("render --size 12x8 --spp 1 --seed 4 --layers pivot -o more.exr").code, 0);
    ToolResult r = Run("accumulate a.exr b.exr small.exr -o acc.exr");
    EXPECT_EQ(r.code, 1);
    EXPECT_TRUE(Contains(r.err, "'small.exr' is 12x9")) << r.err;
    r = Run("accumulate a.exr more.exr b.exr -o acc.exr");
    EXPECT_EQ(r.code, 1);
    EXPECT_TRUE(Contains(r.err, "'more.exr' has layers")) << r.err;
    EXPECT_FALSE(fs::exists(Path("acc.exr")));

    // The library refuses too, and its sums stay as they were.
    io::Accumulator accumulator;
    accumulator.Add(io::ReadFrame(Path("a.exr")));
    try {
        accumulator.Add(io::ReadFrame(Path("small.exr")));
        ADD_FAILURE() << "a 12x9 frame was accepted after a 12x8 one";
    } catch (const Error &e) {
        EXPECT_TRUE(Contains(e.what(), "small.exr")) << e.what();
    }
    EXPECT_EQ(accumulator.Frames(), 1);
}

TEST_F(CliAccumulate, RefusesWritingOntoAnInput) {
    ASSERT_EQ(Run("render --size 12x8 --spp 1 --seed 1 -o a.exr").code, 0);
    ASSERT_EQ(Run("render --size 12x8 --spp 1 --seed 2 -o b.exr").code, 0);
    io::Frame before = io::ReadFrame(Path("b.exr"));
    ToolResult r = Run("accumulate a.exr b.exr -o ./b.exr");
    EXPECT_EQ(r.code, 1);
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
