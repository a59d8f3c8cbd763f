// Issue #29's checks on Blender frames, as a user runs the tool: a Cycles frame rendered on
// transparent film keeps its background (colour and alpha) through `denoise` with every
// method and auto; `--overwrite-input` keeps the frame's channel names and adds only
// Cycles' Noisy Image; a method the frame cannot feed says what to enable in Blender.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "harness/errors.h"
#include "harness/tool.h"
#include "host/image.h"
#include "host/io/frame.h"
#include "mcdenoise/mcdenoise.h"
#include "tools/mcdenoise/exit_status.h"

namespace mcd::test {
namespace {

namespace fs = std::filesystem;

const std::string kData = std::string(MCD_SOURCE_DIR) + "/tests/data/";
const std::string kFrame = kData + "cycles_transparent_24_16spp_s1.exr";

bool SameBits(float a, float b) {
    return std::memcmp(&a, &b, sizeof a) == 0;
}

// A file's channels by name, as floats (the Cycles frames are float32 throughout).
std::map<std::string, std::vector<float>> Channels(const std::string &path) {
    std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(path);
    EXPECT_TRUE(in) << OIIO::geterror();
    if (!in) return {};
    const OIIO::ImageSpec &spec = in->spec();
    std::vector<float> pixels(size_t(spec.width) * spec.height * spec.nchannels);
    EXPECT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeFloat, pixels.data()));
    std::map<std::string, std::vector<float>> channels;
    for (int c = 0; c < spec.nchannels; ++c)
        for (size_t p = 0; p < size_t(spec.width) * spec.height; ++p)
            channels[spec.channelnames[c]].push_back(pixels[p * spec.nchannels + c]);
    return channels;
}

class CliBlender : public ::testing::Test {
  protected:
    ToolResult Run(const std::string &args) { return tool.Run(args); }
    std::string Path(const std::string &name) const { return tool.Path(name).string(); }

    // The background the renderer left fully transparent (alpha 0) keeps the input's colour
    // bits. With `farOnly` (the default --alpha-rim, which moves a share of the silhouette
    // into its empty rim) only the far background counts, pixels of alpha 0 without a
    // covered 4-neighbour, whose written alpha must stay 0 too. Returns how many background
    // values the method changed (0 when it kept them).
    int ChangedBackground(const io::Frame &input, const std::string &output,
                          const std::string &what, bool farOnly = false) {
        io::Frame out = io::ReadFrame(output);
        const Image &color = input.Get("color"), &denoised = out.Get("color");
        EXPECT_TRUE(denoised.SameShape(color)) << what;
        if (!denoised.SameShape(color)) return -1;
        const Image &alpha = input.Get("alpha");
        const int w = alpha.width, h = alpha.height;
        auto covered = [&](int x, int y) {
            return x >= 0 && y >= 0 && x < w && y < h && !(alpha.At(0, y, x) == 0.f);
        };
        int changed = 0;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                if (alpha.At(0, y, x) != 0.f) continue;
                if (farOnly) {
                    if (covered(x + 1, y) || covered(x - 1, y) || covered(x, y + 1) ||
                        covered(x, y - 1))
                        continue;
                    EXPECT_TRUE(out.Has("alpha")) << what;
                    if (!out.Has("alpha")) return -1;
                    changed += !SameBits(out.Get("alpha").At(0, y, x), 0.f);
                }
                for (int c = 0; c < 3; ++c)
                    changed += !SameBits(denoised.At(c, y, x), color.At(c, y, x));
            }
        return changed;
    }
    void ExpectAlphaKept(const io::Frame &input, const std::string &output,
                         const std::string &what) {
        io::Frame out = io::ReadFrame(output);
        ASSERT_TRUE(out.Has("alpha")) << what;
        const Image &a = input.Get("alpha"), &b = out.Get("alpha");
        ASSERT_TRUE(a.SameShape(b)) << what;
        for (size_t i = 0; i < a.Size(); ++i)
            ASSERT_TRUE(SameBits(a.data[i], b.data[i])) << what << " pixel " << i;
    }

    ToolDir tool{"mcd_blender_cli"};
};

// The plain Cycles frame runs bayes, pivot and auto (awr and rhf need statistics, and say
// so); two of them accumulated run every method. With the defaults none touches the far
// transparent background (alpha 0, no covered 4-neighbour: --alpha-rim gives only the
// silhouette's rim a share), colour or alpha; with --alpha-rim 0 none touches any of it.
// Without alpha the same frame's background is denoised like any pixel: the check above
// would see it.
TEST_F(CliBlender, TransparentBackgroundIsKeptByEveryMethod) {
    ToolResult r = Run("accumulate " + kFrame + " " + kData +
                       "cycles_transparent_24_16spp_s2.exr -o acc.exr");
    ASSERT_EQ(r.code, 0) << r.All();
    io::Frame plain = io::ReadFrame(kFrame), accumulated = io::ReadFrame(Path("acc.exr"));
    ASSERT_TRUE(accumulated.Has("alpha") && accumulated.Has("hist"));
    io::Frame bare = accumulated;
    bare.layers.erase("alpha");
    std::vector<std::pair<std::string, const Image *>> layers;
    for (const auto &[name, image] : bare.layers) layers.push_back({name, &image});
    io::WriteExr(Path("noalpha.exr"), layers);

    std::vector<std::string> methods = MethodNames();
    methods.push_back("auto");
    int changedWithoutAlpha = 0;
    std::string counts;
    for (const std::string &m : methods) {
        r = Run("denoise " + kFrame + " --method " + m + " -o plain_" + m + ".exr");
        if (Method(m).Missing(plain).empty()) {
            ASSERT_EQ(r.code, 0) << m << ": " << r.All();
            EXPECT_EQ(ChangedBackground(plain, Path("plain_" + m + ".exr"), m, true), 0) << m;
        } else {
            EXPECT_EQ(r.code, int(tool::ExitStatus::MissingLayer)) << m;
            EXPECT_TRUE(Contains(r.err, "Blender Cycles writes no sample statistics")) << r.err;
        }
        r = Run("denoise acc.exr --method " + m + " -o acc_" + m + ".exr --explain");
        ASSERT_EQ(r.code, 0) << m << ": " << r.All();
        EXPECT_TRUE(Contains(r.out, "fully transparent pixel(s) (alpha 0) keep")) << r.out;
        EXPECT_TRUE(Contains(r.out, "pixel(s) of alpha 0 beside covered ones took")) << r.out;
        EXPECT_EQ(ChangedBackground(accumulated, Path("acc_" + m + ".exr"), m, true), 0) << m;

        r = Run("denoise noalpha.exr --method " + m + " -o bare_" + m + ".exr");
        ASSERT_EQ(r.code, 0) << m << ": " << r.All();
        int changed = ChangedBackground(accumulated, Path("bare_" + m + ".exr"), m);
        changedWithoutAlpha += changed;
        counts += " " + m + " " + std::to_string(changed);
    }
    EXPECT_GT(changedWithoutAlpha, 0) << "background values changed without alpha:" << counts;

    r = Run("denoise acc.exr -o acc_kept.exr --alpha-rim 0");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_EQ(ChangedBackground(accumulated, Path("acc_kept.exr"), "--alpha-rim 0"), 0);
    ExpectAlphaKept(accumulated, Path("acc_kept.exr"), "--alpha-rim 0");
}

// By default the background's pixels beside the silhouette (alpha 0, a covered 4-neighbour)
// take a share of their neighbours' colour and alpha, written beside the colour; the rest
// of the background keeps its bits, and the colour and alpha summed over the frame are the
// run's with --alpha-rim 0.
TEST_F(CliBlender, TransparentRimTakesColourAndAlphaAlike) {
    ToolResult r = Run("denoise " + kFrame + " -o rim.exr --explain");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(Contains(r.out, "pixel(s) of alpha 0 beside covered ones took 0.02")) << r.out;
    r = Run("denoise " + kFrame + " -o kept.exr --alpha-rim 0");
    ASSERT_EQ(r.code, 0) << r.All();
    io::Frame input = io::ReadFrame(kFrame), rim = io::ReadFrame(Path("rim.exr")),
              kept = io::ReadFrame(Path("kept.exr"));
    ASSERT_TRUE(rim.Has("alpha") && kept.Has("alpha"));
    const Image &alpha = input.Get("alpha"), &rimAlpha = rim.Get("alpha");
    const Image &color = input.Get("color"), &rimColor = rim.Get("color"),
                &keptColor = kept.Get("color");
    const int w = alpha.width, h = alpha.height;
    auto covered = [&](int x, int y) {
        return x >= 0 && y >= 0 && x < w && y < h && alpha.At(0, y, x) > 0.f;
    };
    int receivers = 0;
    double sums[2][2] = {};  // colour and alpha, of rim.exr and of kept.exr / the input
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            sums[0][1] += rimAlpha.At(0, y, x), sums[1][1] += alpha.At(0, y, x);
            for (int c = 0; c < 3; ++c)
                sums[0][0] += rimColor.At(c, y, x), sums[1][0] += keptColor.At(c, y, x);
            if (alpha.At(0, y, x) > 0.f) continue;
            bool rimPixel = covered(x + 1, y) || covered(x - 1, y) || covered(x, y + 1) ||
                            covered(x, y - 1);
            receivers += rimPixel;
            if (rimPixel) {
                EXPECT_GT(rimAlpha.At(0, y, x), 0.f) << x << ", " << y;
                continue;
            }
            EXPECT_EQ(rimAlpha.At(0, y, x), 0.f) << x << ", " << y;
            for (int c = 0; c < 3; ++c)
                ASSERT_TRUE(SameBits(rimColor.At(c, y, x), color.At(c, y, x)))
                    << x << ", " << y;
        }
    EXPECT_GT(receivers, 0);
    EXPECT_NEAR(sums[0][0], sums[1][0], 1e-5 * sums[1][0]);
    EXPECT_NEAR(sums[0][1], sums[1][1], 1e-5 * sums[1][1]);
}

// The Cycles frame written over keeps every channel under its name and bits, the denoised
// colour in Combined (as written to another file with --alpha-rim 0: the file keeps its
// alpha, so no coverage moves), Combined's alpha; Noisy Image (R, G, B, A) is the one
// channel set added. A second run reads Noisy Image, Cycles' noisy colour,
// so it writes the same Combined and keeps the channel names.
TEST_F(CliBlender, OverwriteInputKeepsTheChannelNamesAndAddsNoisyImage) {
    fs::copy_file(kFrame, Path("f.exr"));
    std::map<std::string, std::vector<float>> before = Channels(Path("f.exr"));
    ToolResult r = Run("denoise f.exr --method bayes -o d.exr --alpha-rim 0");
    ASSERT_EQ(r.code, 0) << r.All();
    r = Run("denoise f.exr --method bayes -o f.exr --overwrite-input");
    ASSERT_EQ(r.code, 0) << r.All();

    std::map<std::string, std::vector<float>> after = Channels(Path("f.exr"));
    std::vector<std::string> added;
    for (const auto &[name, values] : after)
        if (!before.count(name)) added.push_back(name);
    EXPECT_EQ(added,
              (std::vector<std::string>{"ViewLayer.Noisy Image.A", "ViewLayer.Noisy Image.B",
                                        "ViewLayer.Noisy Image.G", "ViewLayer.Noisy Image.R"}));
    const Image denoised = io::ReadImage(Path("d.exr"));
    for (const auto &[name, values] : before) {
        ASSERT_TRUE(after.count(name)) << name << " was lost";
        std::string pass = name.substr(0, name.rfind('.'));
        char c = name.back();
        if (pass == "ViewLayer.Combined" && c != 'A') {
            int k = c == 'R' ? 0 : c == 'G' ? 1 : 2;
            std::vector<float> want(denoised.Plane(k),
                                    denoised.Plane(k) + denoised.PixelCount());
            EXPECT_EQ(after[name], want) << name;
            EXPECT_EQ(after["ViewLayer.Noisy Image." + std::string(1, c)], values) << name;
        } else {
            EXPECT_EQ(after[name], values) << name;
        }
    }
    EXPECT_EQ(after["ViewLayer.Noisy Image.A"], before["ViewLayer.Combined.A"]);
    EXPECT_NE(after["ViewLayer.Combined.R"], before["ViewLayer.Combined.R"]);

    r = Run("denoise f.exr --method bayes -o f.exr --overwrite-input");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_EQ(Channels(Path("f.exr")), after);
    EXPECT_FALSE(Contains(r.err, "--alpha-rim")) << r.err;  // the default: said in --help
    // A share the command line asks for is left out too, with a warning that says why.
    r = Run("denoise f.exr --method bayes -o f.exr --overwrite-input --alpha-rim 0.05");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_EQ(Channels(Path("f.exr")), after);
    EXPECT_TRUE(Contains(r.err,
                         "warning: --alpha-rim 0.05 left out (0): --overwrite-input "
                         "keeps the file's alpha"))
        << r.err;
}

// A method the Cycles frame cannot feed is refused with what to do in Blender or with
// accumulate, not with our renderer's options, and nothing is written.
TEST_F(CliBlender, MissingLayersSayWhatToEnableInBlender) {
    ToolResult r = Run("denoise " + kFrame + " --method rhf -o r.exr");
    EXPECT_EQ(r.code, int(tool::ExitStatus::MissingLayer));
    EXPECT_TRUE(Contains(r.err, "rhf needs layers the frame lacks: no histogram channels"))
        << r.err;
    EXPECT_TRUE(Contains(r.err, "`mcdenoise accumulate`")) << r.err;
    EXPECT_FALSE(Contains(r.err, "--layers")) << r.err;
    EXPECT_FALSE(fs::exists(Path("r.exr")));
    r = Run("denoise " + kFrame + " --method awr -o a.exr");
    EXPECT_TRUE(Contains(r.err, "Blender Cycles writes no sample statistics")) << r.err;
    // auto says why it left them out.
    r = Run("denoise " + kFrame + " --explain -o auto.exr");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(Contains(r.out,
                         "left out rhf: no histogram channels (Bin_0000..) (Blender "
                         "Cycles writes no sample statistics"))
        << r.out;
}

}  // namespace
}  // namespace mcd::test
