// Issue #33, the command line as a new user meets it: the help with no arguments, one line
// per command, `denoise --help` grouped, usage errors (exit 2, "mcdenoise: error:", the
// nearest valid name for a typo, ranges written readably), a directory given as an input
// or as one frame's output, progress lines when stderr is not a terminal, one warning line
// per frame, `compare` on an image with NaN. Then the text helpers on their own.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "harness/errors.h"
#include "harness/inputs.h"
#include "harness/tool.h"
#include "host/io/frame.h"
#include "tools/mcdenoise/exit_status.h"
#include "tools/mcdenoise/usage.h"

namespace mcd::test {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> Lines(const std::string &text) {
    std::vector<std::string> lines;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    return lines;
}

// A usage error: exit status 2 and stderr starting with "mcdenoise: error:".
::testing::AssertionResult IsUsageError(const ToolResult &r, const std::string &part) {
    if (r.code != 2)
        return ::testing::AssertionFailure() << "exit code " << r.code << ", expected 2:\n"
                                             << r.All();
    if (r.err.rfind("mcdenoise: error: ", 0) != 0)
        return ::testing::AssertionFailure() << "stderr does not start with the prefix:\n"
                                             << r.err;
    if (!Contains(r.err, part))
        return ::testing::AssertionFailure() << "'" << part << "' not in:\n" << r.err;
    return ::testing::AssertionSuccess();
}

class CliUsage : public ::testing::Test {
  protected:
    ToolResult Run(const std::string &args, const std::string &env = "") {
        return tool.Run(args, env);
    }
    fs::path Path(const std::string &name) const { return tool.Path(name); }
    // A small frame with a variance layer.
    void WriteFrame(const std::string &name) {
        Image color = MakeInput(InputKind::Uniform, 19, 13, 3, SeedFromName("usage " + name));
        Image variance(19, 13, 1, 0.01f);
        io::WriteExr(Path(name).string(), {{"color", &color}, {"variance", &variance}});
    }

    ToolDir tool{"mcd_usage_test"};
};

// mcdenoise alone is a request for help: printed on stdout, exit 0, as cargo does; the
// same for a command that needs a subcommand. At most 40 lines, one per command, and
// auto, the default method, named.
TEST_F(CliUsage, BareCommandPrintsTheHelp) {
    ToolResult bare = Run("");
    ASSERT_EQ(bare.code, 0) << bare.All();
    EXPECT_TRUE(bare.err.empty()) << bare.err;
    ToolResult help = Run("--help");
    ASSERT_EQ(help.code, 0) << help.All();
    EXPECT_EQ(bare.out, help.out);
    EXPECT_LE(Lines(help.out).size(), 40u) << help.out;
    for (const char *command :
         {"denoise", "accumulate", "compare", "info", "render", "diff", "wavelet", "bench"}) {
        int lines = 0;
        for (const std::string &line : Lines(help.out))
            lines += line.rfind(std::string("  ") + command + " ", 0) == 0;
        EXPECT_EQ(lines, 1) << command << "\n" << help.out;
    }
    EXPECT_TRUE(Contains(help.out, "auto")) << help.out;
    for (const std::string &line : Lines(help.out)) EXPECT_LE(line.size(), 100u) << line;

    ToolResult bench = Run("bench");
    ASSERT_EQ(bench.code, 0) << bench.All();
    EXPECT_TRUE(Contains(bench.out, "mcdenoise bench")) << bench.out;
    EXPECT_TRUE(Contains(bench.out, "\n  quality ")) << bench.out;
}

// `denoise --help`: the summary names auto; the common options first, then the device's,
// the options of every method, auto's and each method's under its own heading.
TEST_F(CliUsage, DenoiseHelpIsGrouped) {
    ToolResult r = Run("denoise --help");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(Contains(r.out, "auto (the default)")) << r.out;
    std::vector<std::string> headings = {
        "Arguments:",  "Options:",      "Device:",       "Every method:", "Method auto:",
        "Method awr:", "Method bayes:", "Method pivot:", "Method rhf:"};
    size_t at = 0;
    for (const std::string &heading : headings) {
        size_t found = r.out.find("\n" + heading + "\n");
        ASSERT_NE(found, std::string::npos) << heading << "\n" << r.out;
        EXPECT_GT(found, at) << heading << " out of order\n" << r.out;
        at = found;
    }
    auto position = [&](const std::string &option) { return r.out.find("  " + option + " "); };
    for (const char *common : {"--method", "--explain", "--reference", "--preview"})
        EXPECT_LT(position(common), r.out.find("\nDevice:\n")) << common;
    EXPECT_GT(position("--kappa"), r.out.find("\nMethod rhf:\n"));
    EXPECT_GT(position("--sn"), r.out.find("\nMethod bayes:\n"));
    EXPECT_LT(position("--sn"), r.out.find("\nMethod pivot:\n"));
    for (const std::string &line : Lines(r.out)) EXPECT_LE(line.size(), 100u) << line;
}

// The check: a typo exits 2 and names the option meant; nothing is written.
TEST_F(CliUsage, TypoGetsTheNearestName) {
    WriteFrame("f.exr");
    ToolResult r = Run("denoise f.exr -o o.exr --kapa 1");
    EXPECT_TRUE(IsUsageError(r, "unknown option '--kapa'")) << r.All();
    EXPECT_TRUE(Contains(r.err, "did you mean '--kappa'?")) << r.err;
    EXPECT_TRUE(Contains(r.err, "mcdenoise denoise --help")) << r.err;
    EXPECT_FALSE(fs::exists(Path("o.exr")));
    // A swap of two letters, a value attached, a prefix, a command.
    EXPECT_TRUE(IsUsageError(Run("denoise f.exr -o o.exr --auto-radisu 3"),
                             "did you mean '--auto-radius'?"));
    EXPECT_TRUE(IsUsageError(Run("denoise f.exr -o o.exr --kapa=1"), "'--kappa'"));
    EXPECT_TRUE(IsUsageError(Run("denoise f.exr -o o.exr --auto-comb mean"),
                             "did you mean '--auto-combine'?"));
    EXPECT_TRUE(IsUsageError(Run("denoize f.exr"), "did you mean 'denoise'?"));
    EXPECT_TRUE(IsUsageError(Run("bench qualty"), "did you mean 'quality'?"));
    // The typo is named even when a required option is missing too.
    EXPECT_TRUE(IsUsageError(Run("denoise f.exr --kapa 1"), "'--kappa'"));
    // Nothing near: no guess.
    r = Run("denoise f.exr -o o.exr --zzzzzzzz");
    EXPECT_TRUE(IsUsageError(r, "unknown option '--zzzzzzzz'"));
    EXPECT_FALSE(Contains(r.err, "did you mean")) << r.err;
    EXPECT_TRUE(IsUsageError(Run("compare f.exr f.exr f.exr"), "unexpected argument 'f.exr'"));
}

// Every other parse error exits 2 too, with the prefix; ranges are written as a reader
// says them, not as 40 digits.
TEST_F(CliUsage, ParseErrorsExitTwoWithReadableRanges) {
    WriteFrame("f.exr");
    ToolResult r = Run("denoise f.exr -o o.exr --kappa -1");
    EXPECT_TRUE(IsUsageError(r, "--kappa: -1 is out of range (at least 0)")) << r.err;
    EXPECT_FALSE(std::regex_search(r.err, std::regex("[0-9]{10}"))) << r.err;
    EXPECT_TRUE(IsUsageError(Run("denoise f.exr -o o.exr --awr-spins 9"),
                             "--awr-spins: 9 is out of range (1 to 8)"));
    // A bound of 1e29 or more is none to a reader: past it, the value must be finite.
    EXPECT_TRUE(
        IsUsageError(Run("denoise f.exr -o o.exr --bright-pool 1e40"),
                     "--bright-pool: 1e40 is out of range (a finite number, at least 0)"));
    EXPECT_TRUE(
        IsUsageError(Run("denoise f.exr -o o.exr --bright-veto nan"),
                     "--bright-veto: nan is out of range (a finite number, at least 0)"));
    EXPECT_TRUE(
        IsUsageError(Run("denoise f.exr -o o.exr --kappa abc"), "'abc' is not a number"));
    EXPECT_TRUE(
        IsUsageError(Run("denoise f.exr -o o.exr --awr-spins 1.5"), "'1.5' is not an integer"));
    EXPECT_TRUE(IsUsageError(Run("denoise f.exr"), "--output is required"));
    EXPECT_TRUE(
        IsUsageError(Run("render --tf-radius 3 -o x.exr"), "requires --tracing-filter"));
    EXPECT_TRUE(
        IsUsageError(Run("accumulate --hist-bins 2 f.exr f.exr -o c.exr"), "(3 to 1000)"));
    EXPECT_FALSE(fs::exists(Path("o.exr")));
    r = Run("denoise --help");
    EXPECT_TRUE(Contains(r.out, "(at least 0)")) << r.out;
    EXPECT_FALSE(std::regex_search(r.out, std::regex("[0-9]{10}")));
}

TEST_F(CliUsage, DirectoryAsInputSaysSo) {
    WriteFrame("f.exr");
    fs::create_directory(Path("d"));
    for (const char *args : {"denoise d -o o.exr", "denoise d/ -o o.exr", "info d",
                             "compare d f.exr", "wavelet d", "diff d"}) {
        ToolResult r = Run(args);
        EXPECT_EQ(r.code, int(tool::ExitStatus::InvalidArgument)) << args << "\n" << r.All();
        EXPECT_TRUE(Contains(r.err, "'d") && Contains(r.err, "is a directory")) << r.err;
        EXPECT_FALSE(Contains(r.err, "format reader")) << r.err;
    }
    ToolResult r = Run("denoise f.exr -o o.exr --reference d");
    EXPECT_TRUE(Contains(r.err, "--reference 'd' is a directory")) << r.err;
}

// One frame's -o must be a file name with an image extension.
TEST_F(CliUsage, DirectoryAsOneFramesOutputSaysSo) {
    WriteFrame("f.exr");
    fs::create_directory(Path("out"));
    for (const char *out : {"out/", "out", "new/"}) {
        ToolResult r = Run(std::string("denoise f.exr -o ") + out);
        EXPECT_EQ(r.code, int(tool::ExitStatus::InvalidArgument)) << out << "\n" << r.All();
        EXPECT_TRUE(Contains(r.err, "is a directory")) << r.err;
        EXPECT_TRUE(Contains(r.err, "file name ending in .exr or .png")) << r.err;
    }
    ToolResult r = Run("denoise f.exr -o denoised");
    EXPECT_TRUE(Contains(r.err, "'denoised' has no extension; give a file name ending in .exr"))
        << r.err;
    EXPECT_TRUE(fs::is_empty(Path("out")));
    EXPECT_FALSE(fs::exists(Path("new")));
}

// Progress on stderr when it is a file: plain lines (no carriage returns) with the fraction
// done and the time left, every $MCD_PROGRESS_SECONDS; none for a run shorter than that.
TEST_F(CliUsage, ProgressLinesWhenNotATerminal) {
    // Two row strips of pivot's planefit (65536 pixels each): a fraction under 100%.
    ASSERT_EQ(Run("render --size 320x220 --spp 1 --layers pivot -o p.exr").code, 0);
    ToolResult r = Run("denoise p.exr --method pivot -o d.exr", "MCD_PROGRESS_SECONDS=0 ");
    ASSERT_EQ(r.code, 0) << r.All();
    std::regex line("pivot: .+ [0-9]+% after [0-9.]+ s(, about [0-9.]+ s left in this stage)?");
    int progressLines = 0;
    for (const std::string &l : Lines(r.err)) progressLines += std::regex_match(l, line);
    EXPECT_GE(progressLines, 2) << r.err;
    EXPECT_TRUE(Contains(r.err, "left in this stage")) << r.err;
    EXPECT_EQ(r.err.find('\r'), std::string::npos);

    r = Run("render --size 16x12 --spp 2 -o r.exr", "MCD_PROGRESS_SECONDS=0 ");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(std::regex_search(r.err, std::regex("render cornell 16x12 at 2 spp [0-9]+% "
                                                    "after [0-9.]+ s, about [0-9.]+ s left")))
        << r.err;
    // The default interval (seconds): a short run prints none.
    r = Run("render --size 16x12 --spp 2 -o r2.exr");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(r.err.empty()) << r.err;
}

// bayes on a frame with black pixels: one warning line for them, worded for a user.
TEST_F(CliUsage, BlackPixelsWarnOnceInWords) {
    Image color(16, 12, 3, 0.5f);
    for (int x = 0; x < 16; ++x)
        for (int c = 0; c < 3; ++c) color.At(c, 0, x) = 0, color.At(c, 1, x) = 1e-9f;
    io::WriteExr(Path("black.exr").string(), {{"color", &color}});
    ToolResult r = Run("denoise black.exr --method bayes -o b.exr");
    ASSERT_EQ(r.code, 0) << r.All();
    std::vector<std::string> warnings;
    for (const std::string &line : Lines(r.err))
        if (line.rfind("warning: ", 0) == 0) warnings.push_back(line);
    ASSERT_EQ(warnings.size(), 1u) << r.err;
    EXPECT_TRUE(Contains(warnings[0], "96 black or nearly black values")) << warnings[0];
    EXPECT_TRUE(Contains(warnings[0], "the 48 black ones too (--zeros denoise)"))
        << warnings[0];
}

// compare leaves nothing out silently: an image with NaN/Inf is refused, naming the count
// and the first pixel; the line it prints has the brightness beside the error.
TEST_F(CliUsage, CompareRefusesNonFiniteValues) {
    Image color(8, 6, 3, 0.5f), reference(8, 6, 3, 0.5f);
    color.At(1, 2, 3) = NAN;
    color.At(0, 4, 5) = INFINITY;
    io::WriteExr(Path("nan.exr").string(), {{"color", &color}});
    io::WriteExr(Path("ref.exr").string(), {{"color", &reference}});
    ToolResult r = Run("compare nan.exr ref.exr");
    EXPECT_EQ(r.code, int(tool::ExitStatus::NonFiniteInput)) << r.All();
    EXPECT_TRUE(Contains(r.err,
                         "image 'nan.exr' has 2 NaN/Inf values in layer color (the first at "
                         "pixel (3, 2), channel 1)"))
        << r.err;
    // The first in raster order, and the reference named as the image is.
    r = Run("compare ref.exr nan.exr");
    EXPECT_EQ(r.code, int(tool::ExitStatus::NonFiniteInput)) << r.All();
    EXPECT_TRUE(Contains(r.err,
                         "reference 'nan.exr' has 2 NaN/Inf values in layer color (the first "
                         "at pixel (3, 2), channel 1)"))
        << r.err;
    r = Run("denoise nan.exr -o out.exr --method bayes");
    EXPECT_EQ(r.code, int(tool::ExitStatus::NonFiniteInput)) << r.All();
    EXPECT_TRUE(Contains(r.err, "has 2 NaN/Inf values, the first at pixel (3, 2), channel 1"))
        << r.err;
    EXPECT_FALSE(Contains(r.out, "relMSE")) << r.out;
    r = Run("compare ref.exr ref.exr");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(Contains(r.out, "relMSE 0, PSNR inf dB, SSIM 1.0000, mean brightness 1.0000"))
        << r.out;
    // The brightness beside the error: an image at 0.4 of the reference's values.
    Image dark = reference;
    for (float &v : dark.data) v *= 0.4f;
    io::WriteExr(Path("dark.exr").string(), {{"color", &dark}});
    r = Run("compare dark.exr ref.exr");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(Contains(r.out, "mean brightness 0.4000 of the reference's")) << r.out;
}

TEST(CliUsageText, EditDistanceCountsTypos) {
    using tool::EditDistance;
    EXPECT_EQ(EditDistance("--kapa", "--kappa"), 1);
    EXPECT_EQ(EditDistance("--kappa", "--kappa"), 0);
    EXPECT_EQ(EditDistance("radisu", "radius"), 1);  // a swap
    EXPECT_EQ(EditDistance("", "abc"), 3);
    EXPECT_EQ(EditDistance("kitten", "sitting"), 3);
}

TEST(CliUsageText, NearestNameTakesPrefixesAndNearTypos) {
    using tool::NearestName;
    std::vector<std::string> names = {
        "--kappa", "--knn",   "--auto-combine", "--auto-noise", "--auto-noise-limit",
        "-o",      "--output"};
    EXPECT_EQ(NearestName("--kapa", names), "--kappa");
    EXPECT_EQ(NearestName("--kapa=0.3", names), "--kappa");
    EXPECT_EQ(NearestName("-kappa", names), "--kappa");
    EXPECT_EQ(NearestName("--auto-comb", names), "--auto-combine");
    EXPECT_EQ(NearestName("--auto-noise-lim", names), "--auto-noise-limit");
    EXPECT_EQ(NearestName("--outptu", names), "--output");
    EXPECT_EQ(NearestName("--frobnicate", names), "");
    EXPECT_EQ(NearestName("--", names), "");
}

TEST(CliUsageText, RangesAndSpeedsReadAsWords) {
    EXPECT_EQ(tool::RangeText(0, 1e30), "at least 0");
    EXPECT_EQ(tool::RangeText(double(1e30f) * -1, 5), "at most 5");
    EXPECT_EQ(tool::RangeText(1, 8), "1 to 8");
    EXPECT_EQ(tool::RangeText(1e-6, 1e6), "1e-06 to 1e+06");
    EXPECT_EQ(tool::SpeedText(2.4), "2.40x faster");
    EXPECT_EQ(tool::SpeedText(0.9), "1.11x slower");
    EXPECT_EQ(tool::SpeedText(1), "1.00x faster");
}

TEST(CliUsageText, WrapKeepsLinesAndIndents) {
    std::string wrapped = tool::WrapText("aaa bbb ccc ddd\n  eee fff ggg", 8);
    EXPECT_EQ(wrapped, "aaa bbb\nccc ddd\n  eee\n    fff\n    ggg");
    EXPECT_EQ(tool::WrapText("a-very-long-word b", 4), "a-very-long-word\nb");
    EXPECT_EQ(tool::WrapText("one\n\ntwo\n", 80), "one\n\ntwo\n");
}

}  // namespace
}  // namespace mcd::test
