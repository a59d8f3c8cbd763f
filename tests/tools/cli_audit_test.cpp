// Issue #29's command-line audit, as a user runs the tool: `wavelet` on NaN/Inf input,
// `diff` on a frame too small for its method, `compare` on a Blender frame whose colour is
// denoised in place, the exit status of each kind of failure, and `render`'s refusals of
// options that make no sense. Tiny frames only.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <set>
#include <string>

#include "harness/errors.h"
#include "harness/tool.h"
#include "host/image.h"
#include "host/io/frame.h"
#include "tools/mcdenoise/exit_status.h"

namespace mcd::test {
namespace {

namespace fs = std::filesystem;

const std::string kBlenderFrame =
    std::string(MCD_SOURCE_DIR) + "/tests/data/cycles_transparent_24_16spp_s1.exr";

// A failure: the status, one "mcdenoise: error: " line naming `part`, nothing on stdout.
::testing::AssertionResult Fails(const ToolResult &r, tool::ExitStatus status,
                                 const std::string &part) {
    if (r.code != int(status))
        return ::testing::AssertionFailure()
               << "exit status " << r.code << ", expected " << int(status) << ":\n"
               << r.All();
    if (r.err.rfind("mcdenoise: error: ", 0) != 0)
        return ::testing::AssertionFailure() << "stderr lacks the prefix:\n" << r.err;
    return Contains(r.err, part);
}

class CliAudit : public ::testing::Test {
  protected:
    ToolResult Run(const std::string &args) { return tool.Run(args); }
    fs::path Path(const std::string &name) const { return tool.Path(name); }

    // An 8x6 RGB frame at 0.5 with a NaN at (3, 2) channel 1 and an Inf at (5, 4) channel 0.
    void WriteNonFiniteFrame(const std::string &name) {
        Image color(8, 6, 3, 0.5f);
        color.At(1, 2, 3) = NAN;
        color.At(0, 4, 5) = INFINITY;
        io::WriteExr(Path(name).string(), {{"color", &color}});
    }

    ToolDir tool{"mcd_cli_audit_test"};
};

// wavelet treats NaN/Inf as denoise does: refused by default (status 5, the layer, count
// and first pixel named, no output), replaced by 0 with a warning under --non-finite zero.
TEST_F(CliAudit, WaveletNonFiniteInputIsRefusedOrZeroed) {
    WriteNonFiniteFrame("nan.exr");
    ToolResult r = Run("wavelet nan.exr -o out.exr");
    EXPECT_TRUE(Fails(r, tool::ExitStatus::NonFiniteInput,
                      "layer 'color' of nan.exr has 2 NaN/Inf values, the first at pixel "
                      "(3, 2), channel 1 (--non-finite zero replaces them with 0)"));
    EXPECT_FALSE(Contains(r.out, "round trip")) << r.out;
    EXPECT_FALSE(fs::exists(Path("out.exr")));

    r = Run("wavelet nan.exr -o out.exr --non-finite zero --levels 2");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(Contains(r.err,
                         "warning: layer 'color' of nan.exr has 2 NaN/Inf values, the "
                         "first at pixel (3, 2), channel 1: replaced by 0"));
    Image back = io::ReadImage(Path("out.exr").string());
    for (float v : back.data) ASSERT_TRUE(std::isfinite(v));
    EXPECT_NEAR(back.At(1, 2, 3), 0.f, 1e-5f);
    EXPECT_NEAR(back.At(0, 0, 0), 0.5f, 1e-5f);

    EXPECT_EQ(Run("wavelet nan.exr --non-finite maybe").code, int(tool::ExitStatus::Usage));
}

// diff on a 1x1 frame with awr: one sentence naming the size and the minimum, and what to
// do, not the method's plan.
TEST_F(CliAudit, DiffOnAFrameTooSmallSaysSoInOneSentence) {
    Image color(1, 1, 3, 0.5f), variance(1, 1, 3, 0.01f);
    io::WriteExr(Path("one.exr").string(), {{"color", &color}, {"variance", &variance}});
    ToolResult r = Run("diff one.exr --method awr");
    EXPECT_TRUE(Fails(r, tool::ExitStatus::InvalidArgument,
                      "mcdenoise: error: diff: awr has nothing to compare on 'one.exr': a "
                      "1x1 frame is too small for its wavelet transform (at least 2 pixels "
                      "on a side); diff a larger frame\n"));
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "one line:\n" << r.err;
    EXPECT_LT(r.err.size(), 200u) << r.err;
}

// A Blender frame denoised in place holds the denoised colour in Combined and the noisy one
// in Noisy Image: compare measures Combined, the image the file shows, as denoise wrote it.
TEST_F(CliAudit, CompareMeasuresBlenderCombined) {
    fs::copy_file(kBlenderFrame, Path("frame.exr"));
    fs::copy_file(kBlenderFrame, Path("noisy.exr"));
    ASSERT_EQ(Run("denoise noisy.exr -o separate.exr --method bayes --alpha-rim 0").code, 0);
    ToolResult r = Run("denoise frame.exr -o frame.exr --overwrite-input --method bayes");
    ASSERT_EQ(r.code, 0) << r.All();

    // The in-place result equals the separate one, and it is not the noisy frame.
    r = Run("compare frame.exr separate.exr");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(Contains(r.out, "frame.exr (ViewLayer.Combined) vs separate.exr: relMSE 0,"));
    r = Run("compare frame.exr noisy.exr");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_FALSE(Contains(r.out, "relMSE 0,")) << r.out;
    // A frame without Noisy Image is measured on its colour (Combined) as before.
    r = Run("compare noisy.exr noisy.exr");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(Contains(r.out, "noisy.exr vs noisy.exr: relMSE 0,"));
    // The reader names the shown layer; info prints it.
    EXPECT_TRUE(Contains(Run("info frame.exr").out, "mcd:shownColor = ViewLayer.Combined"));
    EXPECT_FALSE(Contains(Run("info noisy.exr").out, "mcd:shownColor"));
}

// A frame of our names denoised in place holds the result in R,G,B and the render's colour in
// color.noisy: compare measures the result (color.denoised), not the colour denoise reads.
TEST_F(CliAudit, CompareMeasuresTheResultOfAFrameDenoisedInPlace) {
    Image color(8, 6, 3), variance(8, 6, 3, 0.01f);
    for (size_t i = 0; i < color.data.size(); ++i) color.data[i] = 0.2f + 0.1f * float(i % 7);
    io::WriteExr(Path("frame.exr").string(), {{"color", &color}, {"variance", &variance}});
    fs::copy_file(Path("frame.exr"), Path("noisy.exr"));
    ASSERT_EQ(Run("denoise noisy.exr -o separate.exr --method bayes").code, 0);
    ToolResult r = Run("denoise frame.exr -o frame.exr --overwrite-input --method bayes");
    ASSERT_EQ(r.code, 0) << r.All();

    r = Run("compare frame.exr separate.exr");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(Contains(r.out, "frame.exr (color.denoised) vs separate.exr: relMSE 0,"))
        << r.out;
    EXPECT_TRUE(Contains(Run("info frame.exr").out, "mcd:shownColor = color.denoised"));
    r = Run("compare frame.exr noisy.exr");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_FALSE(Contains(r.out, "relMSE 0,")) << r.out;
}

// The names in a directory (not recursive).
std::set<std::string> Listing(const fs::path &dir) {
    std::set<std::string> names;
    for (const fs::directory_entry &e : fs::directory_iterator(dir))
        names.insert(e.path().filename().string());
    return names;
}

// One representative failure per exit status of docs/usage.md's table that the command line
// can meet on a tiny frame: usage 2, invalid argument 1, missing layer 4, non-finite 5, I/O 8.
TEST_F(CliAudit, ExitStatusPerKindOfFailure) {
    Image color(4, 4, 3, 0.5f);
    io::WriteExr(Path("f.exr").string(), {{"color", &color}});
    WriteNonFiniteFrame("nan.exr");
    using tool::ExitStatus;
    EXPECT_TRUE(Fails(Run("compare f.exr f.exr --bogus"), ExitStatus::Usage, "--bogus"));
    EXPECT_TRUE(Fails(Run("wavelet f.exr --levels 99"), ExitStatus::Usage, "--levels"));
    EXPECT_TRUE(Fails(Run("diff f.exr --method auto"), ExitStatus::InvalidArgument, "'auto'"));
    EXPECT_TRUE(Fails(Run("wavelet f.exr -o out.txt"), ExitStatus::InvalidArgument, ".txt"));
    EXPECT_TRUE(
        Fails(Run("compare f.exr f.exr --layer nope"), ExitStatus::MissingLayer, "'nope'"));
    EXPECT_TRUE(Fails(Run("diff f.exr --method rhf"), ExitStatus::MissingLayer, "rhf"));
    EXPECT_TRUE(Fails(Run("compare nan.exr f.exr"), ExitStatus::NonFiniteInput, "nan.exr"));
    EXPECT_TRUE(Fails(Run("compare missing.exr f.exr"), ExitStatus::Io, "missing.exr"));
    EXPECT_TRUE(Fails(Run("diff missing.exr"), ExitStatus::Io, "missing.exr"));
    EXPECT_TRUE(
        Fails(Run("accumulate f.exr missing.exr -o a.exr"), ExitStatus::Io, "missing.exr"));
    EXPECT_TRUE(
        Fails(Run("render --size 4x4 --spp 1 -o nodir/r.exr"), ExitStatus::Io, "nodir"));
    EXPECT_EQ(Listing(tool.Dir()), (std::set<std::string>{"f.exr", "nan.exr"}));
}

// A --dump directory is checked before any work and made only when something is written
// into it: a refused run leaves no empty directory behind; a file in its place is refused.
TEST_F(CliAudit, DumpDirectoryIsMadeOnlyWhenWritten) {
    WriteNonFiniteFrame("nan.exr");
    Image tiny(1, 1, 3, 0.5f), variance(1, 1, 3, 0.01f);
    io::WriteExr(Path("one.exr").string(), {{"color", &tiny}, {"variance", &variance}});
    using tool::ExitStatus;
    EXPECT_TRUE(
        Fails(Run("wavelet nan.exr --dump bands"), ExitStatus::NonFiniteInput, "nan.exr"));
    EXPECT_TRUE(Fails(Run("wavelet f.exr --dump bands"), ExitStatus::Io, "f.exr"));
    EXPECT_TRUE(Fails(Run("diff one.exr --method awr --dump stages"),
                      ExitStatus::InvalidArgument, "too small"));
    EXPECT_FALSE(fs::exists(Path("bands")));
    EXPECT_FALSE(fs::exists(Path("stages")));
    EXPECT_TRUE(Fails(Run("wavelet nan.exr --non-finite zero --dump one.exr"), ExitStatus::Io,
                      "'one.exr' is a file, not a directory"));
    EXPECT_TRUE(Fails(Run("diff one.exr --method awr --dump one.exr/x"), ExitStatus::Io,
                      "is a file, not a directory"));
    // A run that writes makes the directory, with its parents.
    ToolResult r = Run("wavelet nan.exr --non-finite zero --levels 1 --dump deep/bands");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_FALSE(Listing(Path("deep/bands")).empty());
}

// Another method's option runs (a script may change --method alone) and is said to be
// unread; a sequence's option on one frame too. Options the method reads say nothing.
TEST_F(CliAudit, DenoiseSaysWhichOptionsItDoesNotRead) {
    Image color(8, 6, 3, 0.5f);
    io::WriteExr(Path("f.exr").string(), {{"color", &color}});
    ToolResult r = Run("denoise f.exr --method bayes --kappa 0.5 --temporal-radius 2 -o o.exr");
    EXPECT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(Contains(r.err, "warning: --kappa is rhf's option: not read by --method bayes"))
        << r.err;
    EXPECT_TRUE(Contains(r.err,
                         "warning: --temporal-radius is for sequences gathered in time: not "
                         "read on one frame"))
        << r.err;
    // Read: every method's option by auto (its candidates'), bayes's own by bayes, a
    // sequence's by a sequence.
    for (const char *args :
         {"denoise f.exr --kappa 0.5 -o o.exr",
          "denoise f.exr --method bayes --bayes-levels 3 -o o.exr",
          "denoise 'g.####.exr' --method bayes --temporal-radius 2 -o out/"}) {
        if (Contains(args, "g.####")) {
            fs::copy_file(Path("f.exr"), Path("g.0001.exr"),
                          fs::copy_options::overwrite_existing);
            fs::copy_file(Path("f.exr"), Path("g.0002.exr"),
                          fs::copy_options::overwrite_existing);
        }
        r = Run(args);
        EXPECT_EQ(r.code, 0) << args << "\n" << r.All();
        EXPECT_FALSE(Contains(r.err, "not read")) << args << "\n" << r.err;
    }
    // A sequence's option beside --no-temporal is not read either.
    r = Run("denoise 'g.####.exr' --method bayes --no-temporal --temporal-radius 2 -o out2/");
    EXPECT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(Contains(r.err,
                         "warning: --temporal-radius is for sequences gathered in time: "
                         "not read with --no-temporal"))
        << r.err;
}

// render refuses options that make no sense as a parse error (status 2), before any work and
// without writing anything; an unknown scene or layer group as an unknown method is (1).
TEST_F(CliAudit, RenderRefusesNonsenseBeforeWork) {
    using tool::ExitStatus;
    const std::string base = "render --size 4x4 --spp 1 -o r.exr ";
    struct Case {
        std::string args;
        ExitStatus status;
        std::string part;
    };
    const Case cases[] = {
        {"render --size 0x4 -o r.exr", ExitStatus::Usage, "--size: size '0x4'"},
        {"render --size -4x4 -o r.exr", ExitStatus::Usage, "--size: size '-4x4'"},
        {"render --size 4 -o r.exr", ExitStatus::Usage, "WIDTHxHEIGHT"},
        {"render --size 4x4 --spp 0 -o r.exr", ExitStatus::Usage, "--spp: 0 is out of range"},
        {"render --size 4x4 --spp -3 -o r.exr", ExitStatus::Usage, "--spp: -3"},
        {base + "--threads -2", ExitStatus::Usage, "--threads: -2 is out of range"},
        {base + "--seed -1", ExitStatus::Usage, "--seed: -1 is out of range"},
        {base + "--denoised d.exr", ExitStatus::Usage, "--denoised requires --adaptive"},
        {base + "--density d.png", ExitStatus::Usage, "--density requires --adaptive"},
        {base + "--reference --layers all", ExitStatus::Usage, "excludes"},
        {base + "--reference --seed 3", ExitStatus::Usage, "excludes"},
        {base + "--tracing-filter --reference", ExitStatus::Usage, "excludes"},
        {base + "--tracing-filter --adaptive awr", ExitStatus::Usage, "excludes"},
        {base + "--scene nope", ExitStatus::InvalidArgument, "unknown scene 'nope'"},
        {base + "--layers nope", ExitStatus::InvalidArgument, "unknown layer group 'nope'"},
        {base + "--frame 2", ExitStatus::InvalidArgument, "--camera-move"},
        {base + "--preview p.exr", ExitStatus::InvalidArgument, "'.exr'"},
    };
    for (const Case &c : cases) {
        SCOPED_TRACE(c.args);
        EXPECT_TRUE(Fails(Run(c.args), c.status, c.part));
    }
    EXPECT_TRUE(Listing(tool.Dir()).empty());
    // The same options, each where it belongs, render.
    ToolResult r = Run(base + "--threads 1 --seed 3");
    EXPECT_EQ(r.code, 0) << r.All();
}

}  // namespace
}  // namespace mcd::test
