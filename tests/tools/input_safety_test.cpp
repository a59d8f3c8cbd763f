// Issue #21, "never destroy the user's input frame": the tool's path guard on its own
// (same file through links and spellings, an output pattern that expands onto an input),
// and every writing command refusing its inputs as a user runs it; `denoise
// --overwrite-input` keeping every layer and the noisy color; alpha and provenance carried
// into the output.
#include <OpenImageIO/imageio.h>
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <string>
#include <vector>

#include "harness/errors.h"
#include "harness/tool.h"
#include "host/error.h"
#include "host/image.h"
#include "host/io/exr_read.h"
#include "host/io/frame.h"
#include "mcdenoise/mcdenoise.h"
#include "tools/mcdenoise/exit_status.h"
#include "tools/mcdenoise/path_guard.h"

namespace mcd::test {
namespace {

namespace fs = std::filesystem;
using tool::RefuseInputsInDirectory;
using tool::RefuseOverwritingInputs;
using tool::RolePath;
using tool::SameFile;

std::string ReadBytes(const fs::path &path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// A refusal reported by main(): an invalid argument's exit status, "mcdenoise: error:",
// naming every part.
::testing::AssertionResult IsError(const ToolResult &r, const std::vector<std::string> &parts) {
    if (r.code != int(tool::ExitStatus::InvalidArgument))
        return ::testing::AssertionFailure() << "exit code " << r.code << ":\n" << r.All();
    if (r.err.rfind("mcdenoise: error:", 0) != 0)
        return ::testing::AssertionFailure() << "not a tool error:\n" << r.err;
    for (const std::string &part : parts)
        if (auto c = Contains(r.err, part); !c) return c;
    return ::testing::AssertionSuccess();
}

// The names in a directory, so a test sees that a refusal left no temporary file behind.
std::set<std::string> Listing(const fs::path &dir) {
    std::set<std::string> names;
    for (const fs::directory_entry &e : fs::directory_iterator(dir))
        names.insert(e.path().filename().string());
    return names;
}

bool BitIdentical(const Image &a, const Image &b) {
    return a.SameShape(b) &&
           std::equal(a.data.begin(), a.data.end(), b.data.begin(),
                      [](float x, float y) { return std::memcmp(&x, &y, sizeof x) == 0; });
}

class PathGuard : public InToolDir {
  protected:
    PathGuard() : InToolDir("mcd_path_guard") {}
};

TEST_F(PathGuard, SameFileThroughLinksAndSpellings) {
    Touch("frame.exr");
    fs::create_directory("a");
    fs::create_symlink("frame.exr", "link.exr");
    fs::create_hard_link("frame.exr", "hard.exr");
    EXPECT_TRUE(SameFile("frame.exr", "frame.exr"));
    EXPECT_TRUE(SameFile("frame.exr", "./a/../frame.exr"));
    EXPECT_TRUE(SameFile("frame.exr", (dir.Dir() / "frame.exr").string()));
    EXPECT_TRUE(SameFile("frame.exr", "link.exr"));
    EXPECT_TRUE(SameFile("link.exr", "frame.exr"));
    EXPECT_TRUE(SameFile("hard.exr", "frame.exr"));
    EXPECT_FALSE(SameFile("frame.exr", "a/frame.exr"));
    // Files yet to be written match by spelling.
    EXPECT_TRUE(SameFile("new.png", "a/../new.png"));
    EXPECT_TRUE(SameFile("a/new.png", "./a//new.png"));
    EXPECT_FALSE(SameFile("new.png", "new.exr"));
}

TEST_F(PathGuard, RefusesAnOutputThatIsAnInput) {
    Touch("frame.exr");
    Touch("ref.exr");
    fs::create_directory("a");
    std::vector<RolePath> inputs = {{"input", "frame.exr", "pass --overwrite-input"},
                                    {"--reference", "ref.exr"}};
    EXPECT_EQ(ErrorOf([&] {
                  RefuseOverwritingInputs(inputs, {{"-o", "out.exr"}});
              }),
              "<no error>");
    // Options not given are empty paths and never match.
    EXPECT_EQ(ErrorOf([&] {
                  RefuseOverwritingInputs(inputs, {{"-o", ""}, {"--preview", ""}});
              }),
              "<no error>");
    std::string error = ErrorOf([&] {
        RefuseOverwritingInputs(inputs, {{"-o", "./a/../frame.exr"}});
    });
    EXPECT_TRUE(Contains(error, "-o './a/../frame.exr' would overwrite input 'frame.exr'"));
    EXPECT_TRUE(Contains(error, "pass --overwrite-input"));
    EXPECT_TRUE(Contains(error, "nothing was written"));
    EXPECT_TRUE(ThrowsError(ErrorKind::InvalidArgument, [&] {
        RefuseOverwritingInputs(inputs, {{"-o", "./a/../frame.exr"}});
    }));
    error = ErrorOf([&] { RefuseOverwritingInputs(inputs, {{"--preview", "ref.exr"}}); });
    EXPECT_TRUE(Contains(error, "--preview 'ref.exr' would overwrite --reference 'ref.exr'"));
    EXPECT_FALSE(Contains(error, "--overwrite-input")) << "the hint is the input's own";
    // Two outputs on one file.
    error = ErrorOf([&] {
        RefuseOverwritingInputs(inputs, {{"-o", "p.png"}, {"--preview", "a/../p.png"}});
    });
    EXPECT_TRUE(Contains(error, "-o 'p.png' and --preview 'a/../p.png' are the same file"));
}

// Sequences do not exist yet: their commands will expand an output pattern per frame and
// hand the lists to this check, which must then refuse a pattern that lands on an input.
TEST_F(PathGuard, RefusesAnOutputPatternThatMatchesTheInputs) {
    std::vector<RolePath> inputs;
    for (int frame = 1; frame <= 4; ++frame) {
        std::string name = fmt::format("shot_{:04d}.exr", frame);
        Touch(name);
        inputs.push_back({"input", name});
    }
    fs::create_directory("out");
    auto expand = [](const std::string &pattern, int first, int last) {
        std::vector<RolePath> outputs;
        for (int frame = first; frame <= last; ++frame)
            outputs.push_back({"-o", fmt::format(fmt::runtime(pattern), frame)});
        return outputs;
    };
    EXPECT_EQ(
        ErrorOf([&] { RefuseOverwritingInputs(inputs, expand("out/shot_{:04d}.exr", 1, 4)); }),
        "<no error>");
    EXPECT_EQ(
        ErrorOf([&] { RefuseOverwritingInputs(inputs, expand("shot_{:04d}.dn.exr", 1, 4)); }),
        "<no error>");
    // The same pattern as the inputs, in another spelling, lands on frame 1 first.
    std::string error = ErrorOf(
        [&] { RefuseOverwritingInputs(inputs, expand("out/../shot_{:04d}.exr", 1, 4)); });
    EXPECT_TRUE(
        Contains(error, "-o 'out/../shot_0001.exr' would overwrite input 'shot_0001.exr'"));
    // A shifted range overlaps the inputs in frames 3 and 4 only.
    error =
        ErrorOf([&] { RefuseOverwritingInputs(inputs, expand("./shot_{:04d}.exr", 3, 8)); });
    EXPECT_TRUE(Contains(error, "input 'shot_0003.exr'"));
    // A pattern without the frame number writes every frame onto one file.
    error = ErrorOf([&] { RefuseOverwritingInputs(inputs, expand("out/denoised.exr", 1, 4)); });
    EXPECT_TRUE(Contains(error, "are the same file"));
    EXPECT_TRUE(ThrowsError(ErrorKind::InvalidArgument, [&] {
        RefuseOverwritingInputs(inputs, expand("out/denoised.exr", 1, 4));
    }));
}

TEST_F(PathGuard, RefusesAnInputInADumpDirectory) {
    fs::create_directory("dump");
    Touch("dump/stage.gpu.exr");
    Touch("dump/frame.exr");
    Touch("frame.exr");
    fs::create_symlink("dump/stage.gpu.exr", "link.exr");
    auto writes = [](const std::string &name) { return name.ends_with(".gpu.exr"); };
    EXPECT_EQ(ErrorOf([&] {
                  RefuseInputsInDirectory({{"input", "frame.exr"}, {"input", "dump/frame.exr"}},
                                          {"--dump", "dump"}, writes);
              }),
              "<no error>");
    EXPECT_EQ(
        ErrorOf([&] {
            RefuseInputsInDirectory({{"input", "dump/stage.gpu.exr"}}, {"--dump", ""}, writes);
        }),
        "<no error>");
    std::string error = ErrorOf([&] {
        RefuseInputsInDirectory({{"input", "dump/stage.gpu.exr"}}, {"--dump", "./dump/"},
                                writes);
    });
    EXPECT_TRUE(
        Contains(error, "--dump './dump/' would write over input 'dump/stage.gpu.exr'"));
    // A link elsewhere that leads into the directory.
    error = ErrorOf([&] {
        RefuseInputsInDirectory({{"input", "link.exr"}}, {"--dump", "dump"}, writes);
    });
    EXPECT_TRUE(Contains(error, "input 'link.exr'"));
    EXPECT_TRUE(ThrowsError(ErrorKind::InvalidArgument, [&] {
        RefuseInputsInDirectory({{"input", "link.exr"}}, {"--dump", "dump"}, writes);
    }));
}

class CliInputSafety : public ::testing::Test {
  protected:
    ToolResult Run(const std::string &args, const std::string &env = "") {
        return tool.Run(args, env);
    }
    fs::path Path(const std::string &name) const { return tool.Path(name); }
    // Every layer group, so a lost layer is lost data: histograms, variance, pivot, G-buffer.
    void RenderFrame(const std::string &name) {
        ToolResult r = Run("render --size 12x8 --spp 2 --layers all -o " + name);
        ASSERT_EQ(r.code, 0) << r.All();
    }

    ToolDir tool{"mcd_input_safety"};
};

TEST_F(CliInputSafety, DenoiseRefusesItsInputInEverySpelling) {
    RenderFrame("f.exr");
    ASSERT_EQ(Run("render --size 12x8 --spp 8 --seed 3 -o r.exr").code, 0);
    fs::create_directory(Path("sub"));
    fs::create_symlink("f.exr", Path("link.exr"));
    std::string bytes = ReadBytes(Path("f.exr"));
    std::set<std::string> before = Listing(tool.Dir());
    for (const char *output : {"f.exr", "./sub/../f.exr", "link.exr"}) {
        ToolResult r = Run(std::string("denoise f.exr -o ") + output);
        EXPECT_TRUE(IsError(r, {fmt::format("-o '{}' would overwrite input 'f.exr'", output),
                                "--overwrite-input"}))
            << output;
    }
    // The input through a link, and a PNG preview onto the frame.
    EXPECT_TRUE(IsError(Run("denoise link.exr -o f.exr"), {"input 'link.exr'", "-o 'f.exr'"}));
    EXPECT_TRUE(IsError(Run("denoise f.exr -o d.exr --preview f.png --reference f.png"),
                        {"--preview 'f.png'", "--reference 'f.png'"}));
    EXPECT_TRUE(IsError(Run("denoise f.exr -o r.exr --reference ./r.exr"),
                        {"-o 'r.exr' would overwrite --reference './r.exr'"}));
    EXPECT_TRUE(IsError(Run("denoise f.exr -o d.png --preview sub/../d.png"),
                        {"-o 'd.png' and --preview 'sub/../d.png' are the same file"}));
    EXPECT_EQ(ReadBytes(Path("f.exr")), bytes);
    EXPECT_TRUE(fs::is_symlink(Path("link.exr")));
    EXPECT_EQ(Listing(tool.Dir()), before) << "a refusal writes nothing";
}

TEST_F(CliInputSafety, OutputFormatsByExtensionInAnyCase) {
    // .EXR and .Png name the formats as .exr and .png do; .TIF stays refused.
    RenderFrame("f.exr");
    ASSERT_EQ(Run("denoise f.exr --method bayes -o U.EXR").code, 0);
    EXPECT_EQ(ReadBytes(Path("U.EXR")).substr(0, 4), std::string("\x76\x2f\x31\x01", 4));
    ASSERT_EQ(Run("denoise f.exr --method bayes -o P.Png").code, 0);
    EXPECT_EQ(ReadBytes(Path("P.Png")).substr(0, 4), "\x89PNG");
    EXPECT_TRUE(IsError(Run("denoise f.exr --method bayes -o T.TIF"),
                        {"unsupported extension '.TIF'"}));
    EXPECT_FALSE(fs::exists(Path("T.TIF")));
}

TEST_F(CliInputSafety, OverwriteInputKeepsEveryLayerAndTheNoisyColor) {
    RenderFrame("f.exr");
    fs::copy_file(Path("f.exr"), Path("copy.exr"));
    io::Frame before = io::ReadFrame(Path("f.exr").string());
    ASSERT_GE(before.layers.size(), 14u);
    ToolResult r = Run("denoise copy.exr --method awr -o d.exr");
    ASSERT_EQ(r.code, 0) << r.All();
    r = Run("denoise f.exr --method awr -o f.exr --overwrite-input");
    ASSERT_EQ(r.code, 0) << r.All();

    // The file's colour channels hold the result; ReadFrame takes color.noisy, the
    // render's colour, as the frame's colour, and the result as color.denoised.
    auto stored = [&] {
        Image rgb(before.width, before.height, 3);
        EXPECT_TRUE(io::ReadExrChannels(
            Path("f.exr").string(), 0, 0, before.width, before.height,
            {{"R", rgb.Plane(0)}, {"G", rgb.Plane(1)}, {"B", rgb.Plane(2)}}));
        return rgb;
    };
    io::Frame after = io::ReadFrame(Path("f.exr").string());
    EXPECT_EQ(after.layers.size(), before.layers.size() + 1);
    for (const auto &[name, image] : before.layers) {
        EXPECT_TRUE(BitIdentical(after.Get(name), image)) << name;
    }
    Image denoised = io::ReadImage(Path("d.exr").string());
    EXPECT_TRUE(BitIdentical(stored(), denoised));
    EXPECT_TRUE(BitIdentical(after.Get(io::kDenoisedColorLayer), denoised));
    EXPECT_FALSE(BitIdentical(denoised, before.Get("color")));
    // The render's metadata stays, the provenance is added.
    EXPECT_EQ(after.metadata["mcd:scene"], before.metadata["mcd:scene"]);
    EXPECT_EQ(after.metadata["mcd:method"], "awr");

    // Through a link: the file it leads to is updated and the link stays a link. A second
    // run denoises the render's colour again and keeps it.
    fs::create_symlink("f.exr", Path("link.exr"));
    r = Run("denoise link.exr --method awr -o ./link.exr --overwrite-input");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(fs::is_symlink(Path("link.exr")));
    io::Frame again = io::ReadFrame(Path("f.exr").string());
    EXPECT_EQ(again.layers.size(), before.layers.size() + 1);
    EXPECT_TRUE(BitIdentical(again.Get("color"), before.Get("color")));
    EXPECT_TRUE(BitIdentical(stored(), denoised));

    // A PNG cannot hold the layers: refused, and the PNG input is left alone.
    Image color(6, 4, 3, 0.25f);
    io::WritePng(Path("p.png").string(), color);
    std::string png = ReadBytes(Path("p.png"));
    EXPECT_TRUE(IsError(Run("denoise p.png -o p.png --overwrite-input"), {"needs an .exr"}));
    EXPECT_EQ(ReadBytes(Path("p.png")), png);
}

TEST_F(CliInputSafety, DenoiseKeepsAlphaAndSaysHowItWasMade) {
    Image color(16, 12, 3), variance(16, 12, 3, 0.01f), alpha(16, 12, 1);
    for (int y = 0; y < 12; ++y)
        for (int x = 0; x < 16; ++x) {
            for (int c = 0; c < 3; ++c)
                color.At(c, y, x) = 0.2f + 0.05f * ((x * 7 + y * 3 + c) % 5);
            alpha.At(0, y, x) = x < 4 ? 0.f : float(x) / 15.f;
        }
    io::WriteExr(Path("a.exr").string(),
                 {{"color", &color}, {"variance", &variance}, {"alpha", &alpha}});
    // The file holds R, G, B, A as compositors write them, and reads back as alpha.
    io::Frame in = io::ReadFrame(Path("a.exr").string());
    ASSERT_TRUE(in.Has("alpha"));
    EXPECT_TRUE(BitIdentical(in.Get("alpha"), alpha));

    // --alpha-rim 0: the background's rim (x 3) keeps its alpha (the shares: run_test.cpp).
    ToolResult r =
        Run("denoise a.exr --method awr --cs 2 -o d.exr --preview d.png --alpha-rim 0");
    ASSERT_EQ(r.code, 0) << r.All();
    io::Frame out = io::ReadFrame(Path("d.exr").string());
    ASSERT_TRUE(out.Has("alpha"));
    EXPECT_TRUE(BitIdentical(out.Get("alpha"), alpha));
    auto spec = OIIO::ImageInput::open(Path("d.exr").string());
    ASSERT_TRUE(spec);
    EXPECT_EQ(spec->spec().channelnames, (std::vector<std::string>{"R", "G", "B", "A"}));
    // Which method, every option's value (defaults too), the source and the version.
    EXPECT_EQ(out.metadata["mcd:method"], "awr");
    EXPECT_EQ(out.metadata["mcd:source"], "a.exr");
    EXPECT_EQ(out.metadata["mcd:version"], Version());
    const std::string &options = out.metadata["mcd:options"];
    EXPECT_TRUE(Contains(options, "cs=2"));
    EXPECT_TRUE(Contains(options, "non-finite=refuse"));
    EXPECT_TRUE(Contains(options, "alpha-rim=0") && !Contains(options, "alpha-rim=0."))
        << options;
    EXPECT_FALSE(Contains(options, "kappa=")) << "rhf's options are not awr's";
    Method awr("awr");
    for (const ParamInfo &info : awr.Params()) EXPECT_TRUE(Contains(options, info.name + "="));

    // The PNG preview carries alpha as 8-bit straight alpha.
    io::Frame preview = io::ReadFrame(Path("d.png").string());
    ASSERT_TRUE(preview.Has("alpha"));
    for (int x = 0; x < 16; ++x)
        EXPECT_NEAR(preview.Get("alpha").At(0, 5, x), alpha.At(0, 5, x), 0.5 / 255) << x;
    // auto, which combines its candidates, records every candidate's options and its own;
    // a frame without alpha gets none.
    Image plain(16, 12, 3, 0.5f);
    io::WriteExr(Path("plain.exr").string(), {{"color", &plain}, {"variance", &variance}});
    r = Run("denoise plain.exr -o e.exr");
    ASSERT_EQ(r.code, 0) << r.All();
    io::Frame e = io::ReadFrame(Path("e.exr").string());
    EXPECT_FALSE(e.Has("alpha"));
    EXPECT_EQ(e.metadata["mcd:method"], "auto");
    EXPECT_TRUE(Contains(e.metadata["mcd:options"], "cs=1"));
    EXPECT_TRUE(Contains(e.metadata["mcd:options"], "auto-radius="));
    EXPECT_TRUE(Contains(e.metadata["mcd:options"], "kappa="));
}

TEST_F(CliInputSafety, RenderWaveletAndDiffRefuseTheirInputs) {
    std::string cache = "XDG_CACHE_HOME=" + Path("cache").string() + " ";
    ToolResult r = Run("render --reference --spp 8 --size 10x6 -o ref.exr", cache);
    ASSERT_EQ(r.code, 0) << r.All();
    fs::path cached = Path("cache/mcdenoise/references");
    ASSERT_TRUE(fs::is_directory(cached));
    fs::path file = fs::directory_iterator(cached)->path();
    std::string bytes = ReadBytes(file);
    // Writing the reference onto its own cache entry, spelled another way.
    r = Run(fmt::format("render --reference --spp 8 --size 10x6 -o {}/../references/{}",
                        cached.string(), file.filename().string()),
            cache);
    EXPECT_TRUE(IsError(r, {"would overwrite the cached reference"}));
    EXPECT_EQ(ReadBytes(file), bytes);
    // Outputs onto each other.
    EXPECT_TRUE(
        IsError(Run("render --size 8x8 --spp 4 --adaptive awr -o f.exr --denoised ./f.exr"),
                {"-o 'f.exr' and --denoised './f.exr' are the same file"}));
    EXPECT_FALSE(fs::exists(Path("f.exr")));

    // wavelet: -o onto its input, and --dump onto a band file that is the input.
    RenderFrame("w.exr");
    bytes = ReadBytes(Path("w.exr"));
    EXPECT_TRUE(IsError(Run("wavelet w.exr -o ./w.exr"),
                        {"-o './w.exr' would overwrite input 'w.exr'"}));
    fs::create_directory(Path("bands"));
    fs::copy_file(Path("w.exr"), Path("bands/L1_HH.exr"));
    std::string band = ReadBytes(Path("bands/L1_HH.exr"));
    EXPECT_TRUE(IsError(Run("wavelet bands/L1_HH.exr --levels 2 --dump bands"),
                        {"--dump 'bands/L1_HH.exr' would overwrite input 'bands/L1_HH.exr'"}));
    EXPECT_EQ(ReadBytes(Path("bands/L1_HH.exr")), band);
    EXPECT_EQ(Listing(Path("bands")), (std::set<std::string>{"L1_HH.exr"}));
    ASSERT_EQ(Run("wavelet w.exr --levels 2 --dump bands -o w2.exr").code, 0);
    EXPECT_EQ(ReadBytes(Path("w.exr")), bytes);

    // diff: an input where --dump writes its stages.
    fs::create_directory(Path("stages"));
    fs::copy_file(Path("w.exr"), Path("stages/analysis.gpu.exr"));
    EXPECT_TRUE(IsError(Run("diff stages/analysis.gpu.exr --method awr --dump stages"),
                        {"--dump 'stages' would write over input 'stages/analysis.gpu.exr'"}));
    EXPECT_EQ(ReadBytes(Path("stages/analysis.gpu.exr")), bytes);
}

}  // namespace
}  // namespace mcd::test
