// EXR files as renderers and compositors write them, through the command line: a data
// window away from 0,0 inside a larger display window stays in what denoise and accumulate
// write; a multi-part file is read from the part that holds the colour and `info` lists
// every part; a second `denoise --overwrite-input` denoises the render's colour again.
#include <Imath/ImathBox.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfMultiPartOutputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfOutputPart.h>
#include <OpenEXR/ImfPartType.h>
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "harness/compare.h"
#include "harness/errors.h"
#include "harness/tool.h"
#include "host/image.h"
#include "host/io/exr_read.h"
#include "host/io/frame.h"
#include "tools/mcdenoise/exit_status.h"

namespace mcd::test {
namespace {

namespace fs = std::filesystem;

// One part of a file written with OpenEXR itself: float channels, each a plane of the data
// window's size.
struct Part {
    std::string name;
    Imath::Box2i data, display;
    std::vector<std::pair<std::string, std::vector<float>>> channels;
};

Imf::Header HeaderOf(const Part &part) {
    Imf::Header header(part.display, part.data);
    for (const auto &[name, values] : part.channels)
        header.channels().insert(name, Imf::Channel(Imf::FLOAT));
    return header;
}

Imf::FrameBuffer BufferOf(Part &part) {
    Imf::FrameBuffer buffer;
    size_t width = size_t(part.data.max.x - part.data.min.x + 1);
    for (auto &[name, values] : part.channels) {
        char *base = reinterpret_cast<char *>(values.data()) -
                     (std::ptrdiff_t(part.data.min.x) +
                      std::ptrdiff_t(part.data.min.y) * std::ptrdiff_t(width)) *
                         std::ptrdiff_t(sizeof(float));
        buffer.insert(name, Imf::Slice(Imf::FLOAT, base, sizeof(float), width * sizeof(float)));
    }
    return buffer;
}

int Rows(const Part &part) {
    return part.data.max.y - part.data.min.y + 1;
}

// Writes the parts as one file: a plain scanline file for one part, multi-part otherwise.
void WriteParts(const std::string &path, std::vector<Part> parts) {
    if (parts.size() == 1) {
        Imf::OutputFile out(path.c_str(), HeaderOf(parts[0]));
        out.setFrameBuffer(BufferOf(parts[0]));
        out.writePixels(Rows(parts[0]));
        return;
    }
    std::vector<Imf::Header> headers;
    for (const Part &part : parts) {
        headers.push_back(HeaderOf(part));
        headers.back().setName(part.name);
        headers.back().setType(Imf::SCANLINEIMAGE);
    }
    Imf::MultiPartOutputFile file(path.c_str(), headers.data(), int(headers.size()));
    for (size_t k = 0; k < parts.size(); ++k) {
        Imf::OutputPart out(file, int(k));
        out.setFrameBuffer(BufferOf(parts[k]));
        out.writePixels(Rows(parts[k]));
    }
}

// A noisy colour and its variance for a window of width x height: a ramp and seeded noise.
std::vector<std::pair<std::string, std::vector<float>>> NoisyChannels(int width, int height,
                                                                      unsigned seed) {
    std::mt19937 random(seed);
    std::normal_distribution<float> noise(0.f, 0.1f);
    std::vector<std::pair<std::string, std::vector<float>>> channels;
    for (const char *name : {"B", "G", "R"}) {
        std::vector<float> values(size_t(width) * height);
        for (size_t i = 0; i < values.size(); ++i)
            values[i] = 0.5f + 0.02f * float(i % width) + noise(random);
        channels.push_back({name, values});
    }
    for (const char *name : {"variance.B", "variance.G", "variance.R"})
        channels.push_back({name, std::vector<float>(size_t(width) * height, 0.01f)});
    return channels;
}

Imath::Box2i Box(int x0, int y0, int x1, int y1) {
    return Imath::Box2i(Imath::V2i(x0, y0), Imath::V2i(x1, y1));
}

// The data and display windows of a file's first part, as "data x0 y0 x1 y1 display ...".
std::string WindowsOf(const std::string &path) {
    Imf::InputFile in(path.c_str());
    const Imath::Box2i data = in.header().dataWindow(), display = in.header().displayWindow();
    return fmt::format("data {} {} {} {} display {} {} {} {}", data.min.x, data.min.y,
                       data.max.x, data.max.y, display.min.x, display.min.y, display.max.x,
                       display.max.y);
}

class CliExrFiles : public ::testing::Test {
  protected:
    ToolResult Run(const std::string &args) { return tool.Run(args); }
    std::string Path(const std::string &name) const { return tool.Path(name).string(); }
    ToolDir tool{"mcd_exr_files_cli"};
};

// A 12x8 data window at 7,-3 inside a 30x25 display window at 0,-5 (a crop, or one render
// region): denoise, --overwrite-input and accumulate write both windows as they were, and
// the pixels are those of the same frame written at 0,0.
TEST_F(CliExrFiles, DenoiseAndAccumulateKeepTheWindows) {
    const Imath::Box2i data = Box(7, -3, 18, 4), display = Box(0, -5, 29, 19);
    WriteParts(Path("crop.exr"), {{"", data, display, NoisyChannels(12, 8, 1)}});
    WriteParts(Path("crop2.exr"), {{"", data, display, NoisyChannels(12, 8, 2)}});
    WriteParts(Path("plain.exr"),
               {{"", Box(0, 0, 11, 7), Box(0, 0, 11, 7), NoisyChannels(12, 8, 1)}});
    fs::copy_file(Path("crop.exr"), Path("over.exr"));
    const std::string windows = "data 7 -3 18 4 display 0 -5 29 19";
    ASSERT_EQ(WindowsOf(Path("crop.exr")), windows);

    ToolResult r = Run("denoise crop.exr --method awr -o d.exr");
    ASSERT_EQ(r.code, 0) << r.All();
    ASSERT_EQ(Run("denoise plain.exr --method awr -o p.exr").code, 0);
    EXPECT_EQ(WindowsOf(Path("d.exr")), windows);
    EXPECT_TRUE(BitIdentical(io::ReadImage(Path("d.exr")), io::ReadImage(Path("p.exr"))));

    r = Run("denoise over.exr --method awr -o over.exr --overwrite-input");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_EQ(WindowsOf(Path("over.exr")), windows);

    r = Run("accumulate crop.exr crop2.exr -o acc.exr");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_EQ(WindowsOf(Path("acc.exr")), windows);
    // `info` says where the window is.
    r = Run("info acc.exr");
    EXPECT_TRUE(Contains(r.out, "data window 7 -3 18 4, display window 0 -5 29 19")) << r.out;

    // Frames of one size at other places are not one image's pixels.
    r = Run("accumulate crop.exr plain.exr -o acc2.exr");
    EXPECT_EQ(r.code, int(tool::ExitStatus::InvalidArgument)) << r.All();
    EXPECT_TRUE(Contains(r.err, "'plain.exr' has data window 0 0 11 7")) << r.err;
    EXPECT_FALSE(fs::exists(Path("acc2.exr")));
}

// A compositor's layout: the albedo in part 0, the beauty in part 1. The frame is read from
// part 1 with part 0's albedo joined to it, as the same channels in a one-part file are, and
// `info` lists both parts.
TEST_F(CliExrFiles, MultiPartFramesAreReadFromThePartWithTheColour) {
    std::vector<std::pair<std::string, std::vector<float>>> albedo;
    for (const char *name : {"albedo.B", "albedo.G", "albedo.R"})
        albedo.push_back({name, std::vector<float>(10 * 6, 0.25f)});
    const Imath::Box2i window = Box(0, 0, 9, 5);
    WriteParts(Path("multi.exr"), {{"aux", window, window, albedo},
                                   {"beauty", window, window, NoisyChannels(10, 6, 3)}});
    std::vector<std::pair<std::string, std::vector<float>>> all = NoisyChannels(10, 6, 3);
    all.insert(all.end(), albedo.begin(), albedo.end());
    WriteParts(Path("one.exr"), {{"", window, window, all}});

    ToolResult r = Run("info multi.exr");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(Contains(
        r.out, "part 0 'aux': 10x6, 3 channels (albedo.B,albedo.G,albedo.R)  <- joined\n"))
        << r.out;
    EXPECT_TRUE(Contains(r.out,
                         "part 1 'beauty': 10x6, 6 channels (B,G,R,variance.B,"
                         "variance.G,variance.R)  <- read: it holds the colour"))
        << r.out;
    EXPECT_TRUE(Contains(r.out,
                         "mcd:convention = part 1 (beauty) of 2, the colour's; joined: "
                         "part 0 (aux)\n"))
        << r.out;

    io::Frame multi = io::ReadFrame(Path("multi.exr")), one = io::ReadFrame(Path("one.exr"));
    ASSERT_TRUE(multi.Has("color") && multi.Has("variance") && multi.Has("albedo")) << r.out;
    for (const char *layer : {"color", "variance", "albedo"})
        EXPECT_TRUE(BitIdentical(multi.Get(layer), one.Get(layer))) << layer;

    r = Run("denoise multi.exr --method awr -o dm.exr");
    ASSERT_EQ(r.code, 0) << r.All();
    ASSERT_EQ(Run("denoise one.exr --method awr -o d1.exr").code, 0);
    EXPECT_TRUE(BitIdentical(io::ReadImage(Path("dm.exr")), io::ReadImage(Path("d1.exr"))));

    // Written over, a multi-part file is refused, and left as it was.
    r = Run("denoise multi.exr --method awr -o multi.exr --overwrite-input");
    EXPECT_NE(r.code, 0);
    EXPECT_TRUE(Contains(r.err, "it has 2 parts")) << r.err;
}

// Parts of the colour's data window are joined: an unprefixed part's channels under its name
// ("albedo" holding R,G,B), a prefixed one's as they are; a name the frame already has and a
// part of another window are not read, and `info` and mcd:convention say why. nfor, which
// reads albedo and normal, gives the one-part file's bits.
TEST_F(CliExrFiles, MultiPartLayersOfTheColoursWindowAreJoined) {
    const int width = 16, height = 12;
    const Imath::Box2i window = Box(0, 0, width - 1, height - 1);
    auto constant = [&](std::initializer_list<const char *> names, float first, int w, int h) {
        std::vector<std::pair<std::string, std::vector<float>>> channels;
        float value = first;
        for (const char *name : names) {
            std::vector<float> values(size_t(w) * h);
            for (size_t i = 0; i < values.size(); ++i) values[i] = value + 0.01f * float(i % 7);
            channels.push_back({name, values});
            value += 0.1f;
        }
        return channels;
    };
    auto albedo = constant({"B", "G", "R"}, 0.3f, width, height);
    auto aux =
        constant({"normal.X", "normal.Y", "normal.Z", "variance.R"}, 0.2f, width, height);
    WriteParts(Path("multi.exr"),
               {{"beauty", window, window, NoisyChannels(width, height, 5)},
                {"albedo", window, window, albedo},
                {"aux", window, window, aux},
                {"half", Box(0, 0, 4, 2), window, constant({"Y"}, 0.5f, 5, 3)}});
    std::vector<std::pair<std::string, std::vector<float>>> all =
        NoisyChannels(width, height, 5);
    for (auto &[name, values] : albedo) all.push_back({"albedo." + name, values});
    for (auto &[name, values] : aux)
        if (name != "variance.R") all.push_back({name, values});
    WriteParts(Path("one.exr"), {{"", window, window, all}});

    ToolResult r = Run("info multi.exr");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(Contains(r.out, "part 1 'albedo': 16x12, 3 channels (B,G,R)  <- joined\n"))
        << r.out;
    EXPECT_TRUE(Contains(r.out, "  <- joined (not read: the frame already has variance.R)\n"))
        << r.out;
    EXPECT_TRUE(Contains(r.out,
                         "part 3 'half': 5x3, 1 channel (Y) (not read: its data window 5x3 "
                         "at 0,0 is not the colour's 16x12 at 0,0)\n"))
        << r.out;
    EXPECT_TRUE(Contains(r.out,
                         "mcd:convention = part 0 (beauty) of 4, the colour's; joined: parts "
                         "1 (albedo), 2 (aux); not read: part 2 (aux)'s other channels: the "
                         "frame already has variance.R; part 3 (half): its data window"))
        << r.out;

    io::Frame multi = io::ReadFrame(Path("multi.exr")), one = io::ReadFrame(Path("one.exr"));
    for (const char *layer : {"color", "variance", "albedo", "normal"}) {
        ASSERT_TRUE(multi.Has(layer)) << layer;
        EXPECT_TRUE(BitIdentical(multi.Get(layer), one.Get(layer))) << layer;
    }
    EXPECT_FALSE(multi.Has("Y"));

    ASSERT_EQ(Run("denoise multi.exr --method nfor -o dm.exr").code, 0);
    ASSERT_EQ(Run("denoise one.exr --method nfor -o d1.exr").code, 0);
    EXPECT_TRUE(BitIdentical(io::ReadImage(Path("dm.exr")), io::ReadImage(Path("d1.exr"))));
    // nfor read the joined layers: without them its output differs.
    std::vector<std::pair<std::string, std::vector<float>>> bare =
        NoisyChannels(width, height, 5);
    WriteParts(Path("bare.exr"), {{"", window, window, bare}});
    ASSERT_EQ(Run("denoise bare.exr --method nfor -o db.exr").code, 0);
    EXPECT_FALSE(BitIdentical(io::ReadImage(Path("dm.exr")), io::ReadImage(Path("db.exr"))));

    // bench read reads what ReadFrame reads: the joined channels as the one-part file's.
    auto readCounts = [&](const std::string &file) {
        ToolResult b = Run("bench read " + file + " --method nfor --repeat 1");
        EXPECT_EQ(b.code, 0) << b.All();
        std::string counts;
        size_t layers = b.out.find(" layers,");
        if (size_t start = b.out.rfind(", ", layers); layers != std::string::npos)
            counts += b.out.substr(start, layers - start);
        for (size_t at = b.out.find("pixels, "); at != std::string::npos;
             at = b.out.find("pixels, ", at + 1))
            counts += "; " + b.out.substr(at, b.out.find(':', at) - at);
        return counts;
    };
    std::string multiCounts = readCounts("multi.exr");
    EXPECT_TRUE(Contains(multiCounts, "of 12 channels")) << multiCounts;
    EXPECT_EQ(multiCounts, readCounts("one.exr"));
}

// The first run writes the denoised colour into R,G,B and the render's into color.noisy;
// the second denoises color.noisy again (the same result, bit for bit, as one run) and adds
// no second copy.
TEST_F(CliExrFiles, OverwriteInputTwiceDenoisesTheRendersColour) {
    const Imath::Box2i window = Box(0, 0, 15, 11);
    WriteParts(Path("f.exr"), {{"", window, window, NoisyChannels(16, 12, 4)}});
    fs::copy_file(Path("f.exr"), Path("g.exr"));
    io::Frame before = io::ReadFrame(Path("f.exr"));
    ASSERT_EQ(Run("denoise g.exr --method awr -o once.exr").code, 0);
    Image once = io::ReadImage(Path("once.exr"));

    for (int run = 0; run < 2; ++run) {
        ToolResult r = Run("denoise f.exr --method awr -o f.exr --overwrite-input");
        ASSERT_EQ(r.code, 0) << r.All();
        Imf::InputFile in(Path("f.exr").c_str());
        int channels = 0;
        for (auto it = in.header().channels().begin(); it != in.header().channels().end(); ++it)
            ++channels;
        EXPECT_EQ(channels, 9) << "run " << run;

        Image rgb(16, 12, 3), noisy(16, 12, 3);
        ASSERT_TRUE(io::ReadExrChannels(Path("f.exr"), 0, 0, 16, 12,
                                        {{"R", rgb.Plane(0)},
                                         {"G", rgb.Plane(1)},
                                         {"B", rgb.Plane(2)},
                                         {"color.noisy.R", noisy.Plane(0)},
                                         {"color.noisy.G", noisy.Plane(1)},
                                         {"color.noisy.B", noisy.Plane(2)}}));
        EXPECT_TRUE(BitIdentical(rgb, once)) << "run " << run;
        EXPECT_TRUE(BitIdentical(noisy, before.Get("color"))) << "run " << run;
        // The frame's colour is the render's; the convention says why.
        io::Frame frame = io::ReadFrame(Path("f.exr"));
        EXPECT_TRUE(BitIdentical(frame.Get("color"), before.Get("color")));
        EXPECT_TRUE(Contains(frame.metadata["mcd:convention"], "color from color.noisy"));
    }
}

}  // namespace
}  // namespace mcd::test
