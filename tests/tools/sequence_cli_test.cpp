// Issue #19, sequences: `denoise` over a list of frames or a frame.####.exr pattern. The
// pattern rules on their own (expansion, --frames, matching files, list numbering, the
// plan), then the tool as a user runs it on 16x16 frames: every frame as a single call
// makes it, a failing frame in the middle, --frames, and no output onto an input.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "harness/errors.h"
#include "harness/tool.h"
#include "host/io/frame.h"
#include "host/metrics.h"
#include "tools/mcdenoise/exit_status.h"
#include "tools/mcdenoise/sequence.h"

namespace mcd::test {
namespace {

namespace fs = std::filesystem;
using tool::ExpandFramePattern;
using tool::FindPatternFiles;
using tool::HasFramePlaceholder;
using tool::IsSequence;
using tool::ListFrameNumbers;
using tool::ParseFrameRange;
using tool::PlanSequence;
using tool::SequenceFrame;

TEST(CliSequencePattern, ExpandsHashesAndPrintf) {
    EXPECT_EQ(ExpandFramePattern("f.####.exr", 7), "f.0007.exr");
    EXPECT_EQ(ExpandFramePattern("out/f_%04d.exr", 12), "out/f_0012.exr");
    EXPECT_EQ(ExpandFramePattern("f.%d.exr", 7), "f.7.exr");
    EXPECT_EQ(ExpandFramePattern("f.#.exr", 123), "f.123.exr");
    EXPECT_EQ(ExpandFramePattern("f.##.exr", 12345), "f.12345.exr") << "wider: written whole";
    EXPECT_EQ(ExpandFramePattern("#", 0), "0");
    EXPECT_TRUE(HasFramePlaceholder("a.%02d.png"));
    for (const char *plain : {"f.exr", "100%.exr", "a%b.exr", "%0xd.exr", "%5d.exr"})
        EXPECT_FALSE(HasFramePlaceholder(plain)) << plain;
    EXPECT_TRUE(ThrowsError(
        ErrorKind::InvalidArgument, [] { ExpandFramePattern("f.exr", 1); },
        "'f.exr' has no frame number placeholder"));
    EXPECT_TRUE(ThrowsError(
        ErrorKind::InvalidArgument, [] { ExpandFramePattern("s##/f.####.exr", 1); },
        "has 2 frame number placeholders"));
}

TEST(CliSequencePattern, ParsesFrameRanges) {
    EXPECT_EQ(ParseFrameRange("3"), std::vector<int>{3});
    EXPECT_EQ(ParseFrameRange("1-4"), (std::vector<int>{1, 2, 3, 4}));
    EXPECT_EQ(ParseFrameRange("7,1-3,2"), (std::vector<int>{1, 2, 3, 7}));
    EXPECT_EQ(ParseFrameRange("0-0"), std::vector<int>{0});
    for (const char *bad : {"", "a", "-2", "1-", "1--3", "2,", "1.5", "+3", "1-x"})
        EXPECT_TRUE(ThrowsError(
            ErrorKind::InvalidArgument, [&] { ParseFrameRange(bad); }, "is not a frame number"))
            << "'" << bad << "'";
    EXPECT_TRUE(ThrowsError(
        ErrorKind::InvalidArgument, [] { ParseFrameRange("9-3"); },
        "range '9-3' ends before it starts"));
    EXPECT_TRUE(ThrowsError(
        ErrorKind::InvalidArgument, [] { ParseFrameRange("0-99999999"); }, "more than"));
}

TEST(CliSequencePattern, NumbersListsByTheirFileNames) {
    EXPECT_EQ(ListFrameNumbers({"a/s2_0010.exr", "b/s2_0012.exr"}), (std::vector<int>{10, 12}));
    EXPECT_EQ(ListFrameNumbers({"f.0002.bad.exr", "g7.exr"}), (std::vector<int>{2, 7}));
    // No number in a name, or a number twice: the positions.
    EXPECT_EQ(ListFrameNumbers({"x.exr", "y1.exr"}), (std::vector<int>{1, 2}));
    EXPECT_EQ(ListFrameNumbers({"a/f5.exr", "b/f5.exr", "c/f6.exr"}),
              (std::vector<int>{1, 2, 3}));
}

class CliSequencePlan : public InToolDir {
  protected:
    CliSequencePlan() : InToolDir("mcd_sequence_plan") {}
};

TEST_F(CliSequencePlan, FindsTheFilesOfAPattern) {
    for (const char *name : {"f.0001.exr", "f.0002.exr", "f.0010.exr", "f.1.exr", "f.00003.exr",
                             "g.0004.exr", "f.0005.exr.tmp", "f.00x6.exr"})
        Touch(name);
    std::vector<std::pair<int, std::string>> want = {
        {1, "f.0001.exr"}, {2, "f.0002.exr"}, {10, "f.0010.exr"}};
    EXPECT_EQ(FindPatternFiles("f.####.exr"), want);
    EXPECT_EQ(FindPatternFiles("f.%04d.exr"), want);
    EXPECT_EQ(FindPatternFiles("f.%d.exr"),
              (std::vector<std::pair<int, std::string>>{{1, "f.1.exr"}}));
    fs::create_directory("sub");
    Touch("sub/f.0003.exr");
    EXPECT_EQ(FindPatternFiles("sub/f.####.exr"),
              (std::vector<std::pair<int, std::string>>{{3, "sub/f.0003.exr"}}));
    EXPECT_TRUE(ThrowsError(
        ErrorKind::InvalidArgument, [] { FindPatternFiles("s.##/f.exr"); },
        "must be in the file name"));
    // A file whose name holds '#' is one frame, as it always was.
    Touch("take#2.exr");
    EXPECT_FALSE(IsSequence({"take#2.exr"}));
    EXPECT_TRUE(IsSequence({"f.####.exr"}));
    EXPECT_TRUE(IsSequence({"f.0001.exr", "f.0002.exr"}));
    EXPECT_FALSE(IsSequence({"f.0001.exr"}));
}

TEST_F(CliSequencePlan, PairsEachFrameWithItsOutputs) {
    for (const char *name : {"f.0001.exr", "f.0002.exr", "f.0003.exr"}) Touch(name);
    auto outputs = [](const std::vector<SequenceFrame> &frames) {
        std::vector<std::string> list;
        for (const SequenceFrame &f : frames)
            list.push_back(fmt::format("{} {} {} {} {}", f.number, f.input, f.output, f.preview,
                                       f.reference));
        return list;
    };
    EXPECT_EQ(outputs(PlanSequence({{"f.####.exr"}, "d.%02d.exr", "p/", "ref.exr", ""})),
              (std::vector<std::string>{"1 f.0001.exr d.01.exr p/f.0001.png ref.exr",
                                        "2 f.0002.exr d.02.exr p/f.0002.png ref.exr",
                                        "3 f.0003.exr d.03.exr p/f.0003.png ref.exr"}));
    // --frames on a pattern: every number, present or not; on a list: those it has.
    std::vector<SequenceFrame> mapped =
        PlanSequence({{"f.####.exr"}, "out/", "", "", "2-3", "maps/m.####.png"});
    ASSERT_EQ(mapped.size(), 2u);
    EXPECT_EQ(mapped[0].map, "maps/m.0002.png");
    EXPECT_EQ(mapped[1].map, "maps/m.0003.png");
    EXPECT_EQ(outputs(PlanSequence({{"f.####.exr"}, "out/", "", "r.####.exr", "3-4"})),
              (std::vector<std::string>{"3 f.0003.exr out/f.0003.exr  r.0003.exr",
                                        "4 f.0004.exr out/f.0004.exr  r.0004.exr"}));
    EXPECT_EQ(outputs(PlanSequence({{"f.0001.exr", "f.0003.exr"}, "o.#.png", "", "", "3-9"})),
              (std::vector<std::string>{"3 f.0003.exr o.3.png  "}));
    EXPECT_TRUE(ThrowsError(
        ErrorKind::InvalidArgument,
        [] {
            PlanSequence({{"f.0001.exr", "f.0003.exr"}, "o/", "", "", "2"});
        },
        "--frames '2' selects none of the 2 input files (their numbers run 1 to 3)"));
    EXPECT_TRUE(ThrowsError(
        ErrorKind::InvalidArgument,
        [] {
            PlanSequence({{"f.0001.exr", "f.0002.exr"}, "out.exr", "", "", ""});
        },
        "-o 'out.exr': a sequence needs an output pattern"));
    EXPECT_TRUE(ThrowsError(
        ErrorKind::Io,
        [] {
            PlanSequence({{"g.####.exr"}, "o/", "", "", ""});
        },
        "input pattern 'g.####.exr': no file matches it"));
}

// The tool on a sequence of 16x16 frames rendered with different seeds.
class CliSequence : public ::testing::Test {
  protected:
    void SetUp() override {
        for (int i = 1; i <= 3; ++i) {
            ToolResult r = tool.Run(fmt::format(
                "render --size 16x16 --spp 4 --seed {} -o f.{:04d}.exr", i + 10, i));
            ASSERT_EQ(r.code, 0) << r.All();
        }
    }
    std::set<std::string> Listing(const std::string &sub = "") const {
        std::set<std::string> names;
        if (!fs::exists(tool.Path(sub))) return names;
        for (const fs::directory_entry &e : fs::directory_iterator(tool.Path(sub)))
            names.insert(e.path().filename().string());
        return names;
    }
    Image Color(const std::string &name) const {
        return io::ReadFrame(tool.Path(name).string()).Get("color");
    }
    static bool BitIdentical(const Image &a, const Image &b) {
        return a.SameShape(b) &&
               std::equal(a.data.begin(), a.data.end(), b.data.begin(),
                          [](float x, float y) { return std::memcmp(&x, &y, sizeof x) == 0; });
    }

    ToolDir tool{"mcd_sequence"};
};

TEST_F(CliSequence, DenoisesAPatternAsSingleCallsWould) {
    ToolResult r = tool.Run(
        "denoise 'f.####.exr' -o 'out/d.####.exr' --preview prev/ --auto-map 'maps/m.%02d.png' "
        "--explain --no-temporal");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_EQ(Listing("out"),
              (std::set<std::string>{"d.0001.exr", "d.0002.exr", "d.0003.exr"}));
    EXPECT_EQ(Listing("prev"),
              (std::set<std::string>{"f.0001.png", "f.0002.png", "f.0003.png"}));
    // auto's map, one per frame.
    EXPECT_EQ(Listing("maps"), (std::set<std::string>{"m.01.png", "m.02.png", "m.03.png"}));
    EXPECT_TRUE(Contains(r.out, "wrote the map of the largest weights to maps/m.03.png"))
        << r.out;
    EXPECT_TRUE(Contains(r.out, "3 frames in")) << r.out;
    EXPECT_TRUE(Contains(r.out, "3 written, 0 failed")) << r.out;
    // stderr is not a terminal here: one progress line per frame, with the time left.
    EXPECT_TRUE(Contains(r.err, "denoise: frame 1/3 (f.0001.exr) written, ")) << r.err;
    EXPECT_TRUE(Contains(r.err, "denoise: frame 3/3 (f.0003.exr) written, 0.0 s left"))
        << r.err;
    // One device for all frames gives what one process per frame gives, bit for bit.
    for (int i = 1; i <= 3; ++i) {
        ToolResult single = tool.Run(fmt::format("denoise f.{0:04d}.exr -o s.{0:04d}.exr", i));
        ASSERT_EQ(single.code, 0) << single.All();
        EXPECT_TRUE(BitIdentical(Color(fmt::format("out/d.{:04d}.exr", i)),
                                 Color(fmt::format("s.{:04d}.exr", i))))
            << "frame " << i;
    }
    // The frames differ (different seeds), so a mix-up of frames would show.
    EXPECT_FALSE(BitIdentical(Color("out/d.0001.exr"), Color("out/d.0002.exr")));
}

// The temporal mode, a sequence's default: each frame gathered with its neighbours (a still
// camera here), nearer the reference than the frame alone; one frame, or a sequence of one,
// as it always was.
TEST_F(CliSequence, GathersEachFrameWithItsNeighbours) {
    ToolResult ref = tool.Run("render --size 16x16 --spp 2048 --seed 99 -o ref.exr");
    ASSERT_EQ(ref.code, 0) << ref.All();
    ToolResult r = tool.Run("denoise 'f.####.exr' -o t/ --method bayes --explain");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(Contains(r.out, "t/f.0002.exr: bayes in ")) << r.out;
    EXPECT_TRUE(Contains(r.out, "gathered with 2 neighbours (-1,+1)")) << r.out;
    EXPECT_TRUE(Contains(r.out, "temporal: gathered with 2 neighbours (accepted: -1 "))
        << r.out;
    EXPECT_TRUE(Contains(r.out, "a still camera (no motion vectors)")) << r.out;
    ToolResult alone = tool.Run("denoise 'f.####.exr' -o a/ --method bayes --no-temporal");
    ASSERT_EQ(alone.code, 0) << alone.All();
    EXPECT_FALSE(Contains(alone.out, "gathered")) << alone.out;
    Image reference = Color("ref.exr");
    for (int i = 1; i <= 3; ++i) {
        std::string name = fmt::format("f.{:04d}.exr", i);
        double gathered = CompareImages(Color("t/" + name), reference).relMse;
        double single = CompareImages(Color("a/" + name), reference).relMse;
        EXPECT_LT(gathered, single) << name;
        EXPECT_EQ(io::ReadFrame(tool.Path("t/" + name).string()).metadata.at("mcd:temporal"),
                  i == 1   ? "+1,+2"
                  : i == 2 ? "-1,+1"
                           : "-1,-2");
    }
    // One frame, and a sequence of one frame (no neighbour): the frame alone, bit for bit.
    r = tool.Run("denoise f.0002.exr -o single.exr --method bayes");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(BitIdentical(Color("single.exr"), Color("a/f.0002.exr")));
    r = tool.Run("denoise 'f.####.exr' --frames 2 -o one/ --method bayes");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(BitIdentical(Color("one/f.0002.exr"), Color("a/f.0002.exr")));
    // --temporal-radius 0 is each frame alone too.
    r = tool.Run("denoise 'f.####.exr' -o zero/ --method bayes --temporal-radius 0");
    ASSERT_EQ(r.code, 0) << r.All();
    for (int i = 1; i <= 3; ++i)
        EXPECT_TRUE(BitIdentical(Color(fmt::format("zero/f.{:04d}.exr", i)),
                                 Color(fmt::format("a/f.{:04d}.exr", i))));
}

// A moving camera (the renderer's camera path and motion vectors): each frame gathered
// through the vectors, nearer its own reference than the frame alone on every frame.
TEST_F(CliSequence, FollowsAMovingCameraThroughItsMotionVectors) {
    for (int i = 1; i <= 3; ++i) {
        for (auto [name, spp, seed] :
             {std::tuple{"m", 4, i}, std::tuple{"mref", 1024, 90 + i}}) {
            ToolResult r = tool.Run(fmt::format(
                "render --size 24x24 --spp {} --seed {} --layers gbuffer --camera-move "
                "0.6,0,0 --frame {} -o {}.{:04d}.exr",
                spp, seed, i, name, i));
            ASSERT_EQ(r.code, 0) << r.All();
        }
    }
    ToolResult r = tool.Run("denoise 'm.####.exr' -o t/ --method bayes --explain");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(Contains(r.out, "positions through the motion vectors")) << r.out;
    EXPECT_TRUE(Contains(r.out, "features compared: normal, depth, albedo, object id"))
        << r.out;
    ToolResult alone = tool.Run("denoise 'm.####.exr' -o a/ --method bayes --no-temporal");
    ASSERT_EQ(alone.code, 0) << alone.All();
    for (int i = 1; i <= 3; ++i) {
        std::string name = fmt::format("m.{:04d}.exr", i);
        Image reference = Color(fmt::format("mref.{:04d}.exr", i));
        double gathered = CompareImages(Color("t/" + name), reference).relMse;
        double single = CompareImages(Color("a/" + name), reference).relMse;
        EXPECT_LT(gathered, single) << name;
    }
}

TEST_F(CliSequence, ListAndFramesSelectWhatIsDenoised) {
    // bayes: its pipelines build in a tenth of auto's time; its warnings name the frame.
    ToolResult r = tool.Run("denoise f.0003.exr f.0001.exr -o 'o.%02d.exr' --method bayes");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(Contains(r.err, "warning: f.0003.exr: bayes: ")) << r.err;
    EXPECT_TRUE(fs::exists(tool.Path("o.01.exr")) && fs::exists(tool.Path("o.03.exr")));
    EXPECT_FALSE(fs::exists(tool.Path("o.02.exr")));
    // A farm task's share: two frames of the pattern, then one (as $SLURM_ARRAY_TASK_ID).
    r = tool.Run("denoise 'f.%04d.exr' --frames 2-3 -o part/ --method bayes");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_EQ(Listing("part"), (std::set<std::string>{"f.0002.exr", "f.0003.exr"}));
    r = tool.Run("denoise 'f.####.exr' --frames 1 -o 'one.####.exr' --method bayes");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(Contains(r.out, "1 frames in")) << r.out;
    EXPECT_TRUE(fs::exists(tool.Path("one.0001.exr")));
    // --frames is for sequences; one frame stays the single-frame command.
    r = tool.Run("denoise f.0001.exr --frames 1 -o x.exr");
    EXPECT_EQ(r.code, int(tool::ExitStatus::InvalidArgument));
    EXPECT_TRUE(Contains(r.err, "--frames selects frames of a sequence")) << r.err;
}

TEST_F(CliSequence, AFailingFrameIsReportedAndTheOthersGoOn) {
    // Frame 2 is not an image, frame 4 has a NaN (refused by default, not filled from its
    // neighbours), frame 5 is missing; the neighbours of each are gathered up to them.
    std::ofstream(tool.Path("f.0002.exr")) << "not an image";
    io::Frame frame = io::ReadFrame(tool.Path("f.0003.exr").string());
    Image color = frame.Get("color");
    color.data[5] = std::numeric_limits<float>::quiet_NaN();
    io::WriteExr(tool.Path("f.0004.exr").string(), {{"color", &color}});
    fs::copy_file(tool.Path("f.0001.exr"), tool.Path("f.0006.exr"));
    ToolResult r = tool.Run("denoise 'f.####.exr' --frames 1-6 -o out/ --method bayes");
    // The run's exit status is its first failed frame's: frame 2 could not be read.
    EXPECT_EQ(r.code, int(tool::ExitStatus::Io)) << r.All();
    EXPECT_EQ(Listing("out"), (std::set<std::string>{"f.0001.exr", "f.0003.exr", "f.0006.exr"}))
        << "no output and no temporary file for a failed frame";
    EXPECT_TRUE(Contains(r.err, "mcdenoise: error: frame 2 (f.0002.exr): ")) << r.err;
    EXPECT_TRUE(Contains(r.err, "mcdenoise: error: frame 4 (f.0004.exr): ")) << r.err;
    EXPECT_TRUE(Contains(r.err, "NaN")) << r.err;
    EXPECT_TRUE(Contains(r.err, "mcdenoise: error: frame 5 (f.0005.exr): ")) << r.err;
    EXPECT_TRUE(Contains(r.err, "denoise: frame 2/6 (f.0002.exr) FAILED")) << r.err;
    EXPECT_TRUE(Contains(r.err,
                         "mcdenoise: error: 3 of 6 frames failed: f.0002.exr, f.0004.exr, "
                         "f.0005.exr"))
        << r.err;
    EXPECT_TRUE(Contains(r.out, "6 frames in")) << r.out;
    EXPECT_TRUE(Contains(r.out, "3 written, 3 failed")) << r.out;
    EXPECT_TRUE(
        Contains(r.err,
                 "warning: f.0003.exr: temporal: neighbour 2 (f.0002.exr) left out, and "
                 "those beyond it: "))
        << r.err;
    // Frame 4 lacks the layers frame 3 gathers: frame 3 is denoised alone.
    EXPECT_TRUE(
        Contains(r.err,
                 "warning: f.0003.exr: temporal: the frame at offset 1 is left out, and "
                 "those beyond it: it has no "))
        << r.err;
    EXPECT_FALSE(Contains(r.out, "gathered")) << r.out;
    // A run's first frame, read while the device opens, fails as any other: the rest are
    // written.
    r = tool.Run("denoise 'f.####.exr' --frames 2-3 -o out2/ --method bayes");
    EXPECT_EQ(r.code, int(tool::ExitStatus::Io)) << r.All();
    EXPECT_EQ(Listing("out2"), (std::set<std::string>{"f.0003.exr"}));
    EXPECT_TRUE(Contains(r.err, "mcdenoise: error: frame 2 (f.0002.exr): ")) << r.err;
    // From frame 4 on, the first failure is frame 4's NaN.
    r = tool.Run("denoise 'f.####.exr' --frames 4-6 -o out4/ --method bayes");
    EXPECT_EQ(r.code, int(tool::ExitStatus::NonFiniteInput)) << r.All();
    EXPECT_TRUE(Contains(r.err, "mcdenoise: error: 2 of 3 frames failed")) << r.err;
}

TEST_F(CliSequence, AFrameOfAnotherSizeIsNoNeighbour) {
    // Frame 2 of another size: every frame is written, frames 1 and 3 without it.
    ToolResult r = tool.Run("render --size 24x16 --spp 4 --seed 40 -o f.0002.exr");
    ASSERT_EQ(r.code, 0) << r.All();
    r = tool.Run("denoise 'f.####.exr' -o out/ --method bayes");
    EXPECT_EQ(r.code, 0) << r.All();
    EXPECT_EQ(Listing("out"),
              (std::set<std::string>{"f.0001.exr", "f.0002.exr", "f.0003.exr"}));
    for (const char *frame : {"f.0001.exr", "f.0003.exr"})
        EXPECT_TRUE(
            Contains(r.err, fmt::format("warning: {}: temporal: neighbour 2 (f.0002.exr) "
                                        "left out, and those beyond it: it is 24x16, "
                                        "this frame 16x16",
                                        frame)))
            << r.err;
    EXPECT_EQ(Color("out/f.0002.exr").width, 24);
}

TEST_F(CliSequence, RefusesToWriteOverAnInput) {
    fs::create_directory(tool.Path("sub"));
    std::set<std::string> before = Listing();
    for (const char *output : {"'f.####.exr'", "'./sub/../f.%04d.exr'", "./", "sub/.."}) {
        ToolResult r = tool.Run(std::string("denoise 'f.####.exr' -o ") + output);
        EXPECT_EQ(r.code, int(tool::ExitStatus::InvalidArgument)) << output << "\n" << r.All();
        EXPECT_TRUE(Contains(r.err, "would overwrite input 'f.0001.exr'")) << r.err;
        EXPECT_TRUE(Contains(r.err, "nothing was written")) << r.err;
    }
    // A shifted range lands on frame 3; a preview onto an input; a reference as output.
    ToolResult r = tool.Run("denoise f.0001.exr f.0002.exr -o 'f.%04d.exr' --frames 1");
    EXPECT_TRUE(Contains(r.err, "would overwrite input 'f.0001.exr'")) << r.err;
    r = tool.Run("denoise 'f.####.exr' -o 'new/f.####.exr' --reference 'new/f.####.exr'");
    EXPECT_TRUE(Contains(r.err, "-o 'new/f.0001.exr' would overwrite --reference")) << r.err;
    r = tool.Run("denoise 'f.####.exr' -o 'out.####.exr' --preview 'out.####.exr'");
    EXPECT_TRUE(Contains(r.err, "-o 'out.0001.exr' and --preview 'out.0001.exr' are the same"))
        << r.err;
    // One map file for every frame would be written over frame after frame.
    r = tool.Run("denoise 'f.####.exr' -o 'out.####.exr' --auto-map map.png");
    EXPECT_TRUE(Contains(r.err, "--auto-map 'map.png': a sequence needs an output pattern"))
        << r.err;
    r = tool.Run("denoise 'f.####.exr' -o 'out.####.exr' --auto-map 'f.####.exr'");
    EXPECT_TRUE(Contains(r.err, "would overwrite input 'f.0001.exr'")) << r.err;
    r = tool.Run("denoise 'f.####.exr' -o 'out.####.exr' --overwrite-input");
    EXPECT_TRUE(Contains(r.err, "--overwrite-input is for one frame")) << r.err;
    EXPECT_EQ(Listing(), before) << "a refusal writes nothing, not even a directory";
}

}  // namespace
}  // namespace mcd::test
