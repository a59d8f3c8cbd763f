// The OpenImageIO module (libmcdenoise_oiio): PNG read and written through it, EXR read and
// written without it (OpenEXR's headers in OpenImageIO's terms), and its absence a typed
// error naming the file.
#include <Imath/half.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenImageIO/imageio.h>
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "harness/tool.h"
#include "host/image.h"
#include "host/io/exr_read.h"
#include "host/io/frame.h"
#include "host/io/image_file.h"
#include "tools/mcdenoise/exit_status.h"

namespace mcd::io {
namespace {

namespace fs = std::filesystem;

class IoTestModule : public ::testing::Test {
  protected:
    IoTestModule() : dir("mcd_io_module") {}
    std::string Path(const std::string &name) const { return dir.Path(name).string(); }
    test::ToolDir dir;
};

// A colour and variance frame `awr` denoises; values from a seeded generator.
void WriteNoisyFrame(const std::string &path, unsigned seed) {
    std::mt19937 random(seed);
    std::uniform_real_distribution<float> value(0.1f, 2.f);
    Image color(24, 16, 3), variance(24, 16, 3);
    for (float &v : color.data) v = value(random);
    for (float &v : variance.data) v = 0.01f * value(random);
    WriteExr(path, {{"color", &color}, {"variance", &variance}});
}

TEST_F(IoTestModule, PngIsReadAndWrittenThroughTheModule) {
    Image rgb(4, 3, 3);
    for (size_t i = 0; i < rgb.data.size(); ++i) rgb.data[i] = float(i % 11) / 10.f;
    WritePng(Path("preview.png"), rgb);
    EXPECT_TRUE(IoModuleLoaded());

    // The module's bytes as OpenImageIO reads them: sRGB of the values.
    auto in = OIIO::ImageInput::open(Path("preview.png"));
    ASSERT_TRUE(in) << OIIO::geterror();
    ASSERT_EQ(in->spec().nchannels, 3);
    std::vector<uint8_t> bytes(4 * 3 * 3);
    ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeUInt8, bytes.data()));
    // Read back through the module: linear again, within 8-bit steps.
    Image back = ReadImage(Path("preview.png"));
    ASSERT_EQ(back.channels, 3);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < 3; ++y)
            for (int x = 0; x < 4; ++x) {
                float v = rgb.At(c, y, x);
                float srgb =
                    v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1 / 2.4f) - 0.055f;
                EXPECT_EQ(bytes[(size_t(y) * 4 + x) * 3 + c], std::lround(srgb * 255.f));
                EXPECT_NEAR(back.At(c, y, x), v, 0.01f) << c << " " << x << "," << y;
            }
}

TEST_F(IoTestModule, ExrDenoiseNeedsNoModuleAndPngSaysWhatIsMissing) {
    WriteNoisyFrame(Path("in.exr"), 7);
    fs::create_directories(dir.Path("empty"));
    const std::string noModule =
        fmt::format("MCD_OIIO_MODULE_DIR={} ", dir.Path("empty").string());
    test::ToolResult r = dir.Run("denoise in.exr --method awr -o out.exr", noModule);
    EXPECT_EQ(r.code, 0) << r.All();
    r = dir.Run("info out.exr", noModule);
    EXPECT_EQ(r.code, 0) << r.All();

    // A PNG output and a PNG input need the module: an I/O error naming the file and it.
    r = dir.Run("denoise in.exr --method awr -o out.png", noModule);
    EXPECT_EQ(r.code, int(tool::ExitStatus::Io)) << r.All();
    EXPECT_NE(r.err.find("out.png"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("libmcdenoise_oiio.so"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir.Path("out.png")));
    r = dir.Run("denoise in.exr --method awr -o out.png");  // the build's module
    EXPECT_EQ(r.code, 0) << r.All();
    r = dir.Run("info out.png", noModule);
    EXPECT_EQ(r.code, int(tool::ExitStatus::Io)) << r.All();
    EXPECT_NE(r.err.find("out.png"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("libmcdenoise_oiio.so"), std::string::npos) << r.err;
    r = dir.Run("info out.png");
    EXPECT_EQ(r.code, 0) << r.All();
}

TEST_F(IoTestModule, ExrFramesNeverLoadTheModule) {
#ifndef __GLIBC__
    GTEST_SKIP() << "needs glibc's loader trace (LD_DEBUG)";
#endif
    // Fresh processes with the module in reach: glibc's loader lists every object it opens.
    WriteNoisyFrame(Path("in.exr"), 11);
    WriteNoisyFrame(Path("over.exr"), 12);
    const std::string trace = "LD_DEBUG=files ";
    auto loaded = [](const test::ToolResult &r, const char *name) {
        return r.err.find(name) != std::string::npos;
    };
    for (const char *args : {"denoise in.exr --method awr -o out.exr", "info out.exr",
                             "denoise over.exr --method awr -o over.exr --overwrite-input"}) {
        test::ToolResult r = dir.Run(args, trace);
        EXPECT_EQ(r.code, 0) << args << "\n" << r.All();
        EXPECT_FALSE(loaded(r, "libmcdenoise_oiio")) << args;
        EXPECT_FALSE(loaded(r, "libOpenImageIO")) << args;
    }
    // A PNG does load it, and the trace sees that.
    for (const char *args : {"denoise in.exr --method awr -o out.png", "info out.png"}) {
        test::ToolResult r = dir.Run(args, trace);
        EXPECT_EQ(r.code, 0) << args << "\n" << r.All();
        EXPECT_TRUE(loaded(r, "libmcdenoise_oiio")) << args;
        EXPECT_TRUE(loaded(r, "libOpenImageIO")) << args;
    }
}

TEST_F(IoTestModule, AModuleThatWillNotLoadSaysWhy) {
    WriteNoisyFrame(Path("in.exr"), 9);
    fs::create_directories(dir.Path("broken"));
    std::ofstream(dir.Path("broken") / "libmcdenoise_oiio.so") << std::string(4096, 'x');
    const std::string broken =
        fmt::format("MCD_OIIO_MODULE_DIR={} ", dir.Path("broken").string());
    test::ToolResult r = dir.Run("denoise in.exr --method awr -o out.png", broken);
    EXPECT_EQ(r.code, int(tool::ExitStatus::Io)) << r.All();
    EXPECT_NE(r.err.find("out.png"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("cannot load"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("not found"), std::string::npos) << r.err;
    // The loader's own words: the file is no ELF object.
    EXPECT_NE(r.err.find("ELF"), std::string::npos) << r.err;
}

TEST_F(IoTestModule, ModuleErrorsComeBackAsErrors) {
    // A C++ exception inside the module (a null path makes std::string throw) is an error
    // return with a message, not one crossing the C interface.
    const McdOiioApi &api = IoModule(Path("any.png"), "read");
    char error[256] = {};
    const McdOiioHeader *header = nullptr;
    EXPECT_EQ(api.open(nullptr, &header, error, sizeof error), nullptr);
    EXPECT_NE(error[0], 0);
    error[0] = 0;
    const unsigned char pixel[3] = {1, 2, 3};
    EXPECT_EQ(api.writeUInt8(nullptr, "png", 1, 1, 3, pixel, 0, error, sizeof error), 0);
    EXPECT_NE(error[0], 0);

    // A tiled file whose tiles are damaged fails to read, and fails again on a retry.
    OIIO::ImageSpec spec(64, 64, 3, OIIO::TypeFloat);
    spec.tile_width = spec.tile_height = 16;
    spec.attribute("compression", "zip");
    std::string path = Path("tiled.tif");
    auto out = OIIO::ImageOutput::create(path);
    ASSERT_TRUE(out && out->open(path, spec)) << OIIO::geterror();
    std::mt19937 random(5);
    std::vector<float> pixels(64 * 64 * 3);
    for (float &v : pixels) v = float(random() % 1000) / 1000.f;
    ASSERT_TRUE(out->write_image(OIIO::TypeFloat, pixels.data()));
    out->close();
    {
        std::fstream file(path, std::ios::in | std::ios::out | std::ios::binary);
        std::vector<char> bytes((std::istreambuf_iterator<char>(file)), {});
        for (size_t k = bytes.size() / 3; k < 2 * bytes.size() / 3; ++k) bytes[k] ^= 0x5a;
        file.seekp(0);
        file.write(bytes.data(), std::streamsize(bytes.size()));
    }
    ModuleImage image(path);
    ASSERT_TRUE(image.Header().tiled);
    std::vector<float> rows(64 * 3);
    EXPECT_THROW(image.ReadRows(0, 1, rows.data()), Error);
    EXPECT_THROW(image.ReadRows(0, 1, rows.data()), Error);
}

TEST_F(IoTestModule, AFailedPngWriteIsAnError) {
    // A full disk: /dev/full takes the open and fails every write with ENOSPC. The format's
    // own file writes let that pass; the module's writes must report it.
    if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
    const McdOiioApi &api = IoModule(Path("any.png"), "write");
    std::vector<unsigned char> pixels(64 * 64 * 3);
    for (size_t i = 0; i < pixels.size(); ++i) pixels[i] = static_cast<unsigned char>(i * 7);
    char error[256] = {};
    EXPECT_EQ(
        api.writeUInt8("/dev/full", "png", 64, 64, 3, pixels.data(), 0, error, sizeof error),
        0);
    EXPECT_NE(std::string(error).find("No space"), std::string::npos) << error;

    // The same write to a file succeeds and reads back.
    std::string path = Path("ok.png");
    error[0] = 0;
    ASSERT_EQ(
        api.writeUInt8(path.c_str(), "png", 64, 64, 3, pixels.data(), 0, error, sizeof error),
        1)
        << error;
    Image back = ReadImage(path);
    EXPECT_EQ(back.width, 64);
    EXPECT_EQ(back.height, 64);
}

// Channel names from a seeded generator: layers, RGBA and other suffixes in any case.
std::vector<std::string> RandomChannels(std::mt19937 &random) {
    const std::vector<std::string> layers = {"",
                                             "ViewLayer.Combined.",
                                             "ViewLayer.Noisy Image.",
                                             "albedo.",
                                             "a.b.",
                                             "Z.",
                                             "half0.color.",
                                             "x"};
    const std::vector<std::string> suffixes = {"R", "G",     "B",        "A",     "Y",
                                               "Z", "alpha", "red",      "u",     "v",
                                               "0", "1",     "Bin_0003", "depth", "X"};
    std::set<std::string> names;
    int count = 2 + int(random() % 12);
    while (int(names.size()) < count)
        names.insert(layers[random() % layers.size()] + suffixes[random() % suffixes.size()]);
    std::vector<std::string> list(names.begin(), names.end());
    std::shuffle(list.begin(), list.end(), random);
    return list;
}

TEST_F(IoTestModule, ExrHeadersAreOpenImageIOs) {
    std::mt19937 random(32);
    const OIIO::TypeDesc types[] = {OIIO::TypeHalf, OIIO::TypeFloat, OIIO::TypeUInt32};
    for (int round = 0; round < 60; ++round) {
        std::vector<std::string> names = RandomChannels(random);
        OIIO::ImageSpec spec(5, 4, int(names.size()), OIIO::TypeFloat);
        spec.channelnames = names;
        spec.channelformats.clear();
        for (size_t c = 0; c < names.size(); ++c)
            spec.channelformats.push_back(types[random() % 3]);
        spec.x = int(random() % 5), spec.y = int(random() % 5);
        if (round % 3 == 0) spec.tile_width = spec.tile_height = 16;
        spec.attribute("mcd:spp", fmt::format("{}", random() % 1000));
        spec.attribute("DateTime", "2026:12:01 08:00:00");
        spec.attribute("ImageDescription", "a test");
        spec.attribute("samplesPerPixel", int(random() % 100));
        spec.attribute("exposure", 0.25f * float(random() % 9));
        std::string path = Path(fmt::format("h{}.exr", round));
        auto out = OIIO::ImageOutput::create(path);
        ASSERT_TRUE(out && out->open(path, spec)) << OIIO::geterror();
        std::vector<float> pixels(size_t(spec.image_pixels()) * names.size(), 1.f);
        ASSERT_TRUE(out->write_image(OIIO::TypeFloat, pixels.data()));
        out->close();

        auto in = OIIO::ImageInput::open(path);
        ASSERT_TRUE(in);
        const OIIO::ImageSpec &theirs = in->spec();
        ImageHeader ours = ReadExrHeader(path);
        EXPECT_EQ(ours.channelNames, theirs.channelnames) << path;
        for (int c = 0; c < theirs.nchannels; ++c) {
            OIIO::TypeDesc type = theirs.channelformat(c);
            std::string name = type == OIIO::TypeUInt32 ? "uint32" : type.c_str();  // "uint"
            EXPECT_EQ(ours.typeNames[c], name) << c;
        }
        EXPECT_EQ(ours.x, theirs.x);
        EXPECT_EQ(ours.y, theirs.y);
        EXPECT_EQ(ours.width, theirs.width);
        EXPECT_EQ(ours.height, theirs.height);
        EXPECT_EQ(ours.tiled, theirs.tile_width > 0);
        // Every string, int and float attribute OpenImageIO reports but its own hints.
        size_t compared = 0;
        for (const OIIO::ParamValue &a : theirs.extra_attribs) {
            std::string name = a.name().string();
            if (name.starts_with("oiio:")) continue;
            if (a.type() == OIIO::TypeString) {
                EXPECT_EQ(ours.strings[name], a.get_string()) << name;
            } else if (a.type() == OIIO::TypeInt) {
                EXPECT_EQ(ours.ints[name], a.get_int()) << name;
            } else if (a.type() == OIIO::TypeFloat) {
                EXPECT_EQ(ours.floats[name], a.get_float()) << name;
            } else {
                continue;
            }
            ++compared;
        }
        EXPECT_EQ(compared, ours.strings.size() + ours.ints.size() + ours.floats.size());
    }
}

TEST_F(IoTestModule, ExrWritesKeepChannelTypesAndAttributes) {
    // WriteExr: float channels, zip, the metadata as string attributes by their names.
    Image color(6, 5, 3), depth(6, 5, 1);
    for (size_t i = 0; i < color.data.size(); ++i) color.data[i] = 0.1f * float(i);
    for (size_t i = 0; i < depth.data.size(); ++i) depth.data[i] = float(i);
    std::string path = Path("w.exr");
    WriteExr(path, {{"color", &color}, {"depth", &depth}},
             {{"mcd:method", "awr"}, {"DateTime", "2026:01:02 03:04:05"}, {"Copyright", "me"}});
    auto in = OIIO::ImageInput::open(path);
    ASSERT_TRUE(in) << OIIO::geterror();
    const OIIO::ImageSpec &spec = in->spec();
    EXPECT_EQ(spec.channelnames, (std::vector<std::string>{"R", "G", "B", "depth.Z"}));
    for (int c = 0; c < spec.nchannels; ++c) EXPECT_EQ(spec.channelformat(c), OIIO::TypeFloat);
    EXPECT_EQ(spec.get_string_attribute("compression"), "zip");
    EXPECT_EQ(spec.get_string_attribute("mcd:method"), "awr");
    EXPECT_EQ(spec.get_string_attribute("DateTime"), "2026:01:02 03:04:05");
    EXPECT_EQ(spec.get_string_attribute("Copyright"), "me");
    Frame frame = ReadFrame(path);
    EXPECT_EQ(frame.Get("color").data, color.data);
    EXPECT_EQ(frame.Get("depth").data, depth.data);

    // WriteDenoisedOver on a half/float/uint frame with int and float attributes: every
    // channel keeps its type, every attribute stays, the colour is replaced.
    OIIO::ImageSpec mixed(6, 5, 5, OIIO::TypeHalf);
    mixed.channelnames = {"R", "G", "B", "A", "id"};
    mixed.channelformats = {OIIO::TypeHalf, OIIO::TypeHalf, OIIO::TypeHalf, OIIO::TypeFloat,
                            OIIO::TypeUInt32};
    mixed.attribute("samplesPerPixel", 64);
    mixed.attribute("exposure", 1.5f);
    mixed.attribute("renderer", "test");
    std::string frameFile = Path("mixed.exr");
    auto out = OIIO::ImageOutput::create(frameFile);
    ASSERT_TRUE(out && out->open(frameFile, mixed));
    std::vector<float> pixels(6 * 5 * 5, 1.f);
    for (size_t p = 0; p < 30; ++p) pixels[p * 5 + 4] = float(p) / 4294967295.f;
    ASSERT_TRUE(out->write_image(OIIO::TypeFloat, pixels.data()));
    out->close();
    const Image ids = ReadFrame(frameFile).Get("id");
    Image denoised(6, 5, 3);
    for (size_t i = 0; i < denoised.data.size(); ++i)
        denoised.data[i] = 0.5f + 0.25f * float(i % 3);
    WriteDenoisedOver(frameFile, denoised, {{"mcd:method", "awr"}});
    auto after = OIIO::ImageInput::open(frameFile);
    ASSERT_TRUE(after) << OIIO::geterror();
    const OIIO::ImageSpec &s = after->spec();
    std::vector<std::string> names = {
        "R", "G", "B", "A", "id", "color.noisy.R", "color.noisy.G", "color.noisy.B"};
    EXPECT_EQ(std::set<std::string>(s.channelnames.begin(), s.channelnames.end()),
              std::set<std::string>(names.begin(), names.end()));
    for (int c = 0; c < s.nchannels; ++c) {
        const std::string &n = s.channelnames[c];
        OIIO::TypeDesc want = n == "A"    ? OIIO::TypeFloat
                              : n == "id" ? OIIO::TypeUInt32
                                          : OIIO::TypeHalf;
        EXPECT_EQ(s.channelformat(c), want) << n;
    }
    EXPECT_EQ(s.get_int_attribute("samplesPerPixel"), 64);
    EXPECT_EQ(s.get_float_attribute("exposure"), 1.5f);
    EXPECT_EQ(s.get_string_attribute("renderer"), "test");
    EXPECT_EQ(s.get_string_attribute("mcd:method"), "awr");
    // R,G,B hold the result; ReadFrame takes the render's colour, kept in color.noisy.
    Image rgb(6, 5, 3);
    ASSERT_TRUE(
        ReadExrChannels(frameFile, 0, 0, 6, 5,
                        {{"R", rgb.Plane(0)}, {"G", rgb.Plane(1)}, {"B", rgb.Plane(2)}}));
    EXPECT_EQ(rgb.data, denoised.data);
    Frame back = ReadFrame(frameFile);
    EXPECT_EQ(back.Get("color").data, std::vector<float>(6 * 5 * 3, 1.f));
    EXPECT_EQ(back.Get("id").data, ids.data);
}

// A channel's samples as half bits, read back by OpenImageIO.
std::vector<uint16_t> HalfBits(const std::string &path, const std::string &channel) {
    auto in = OIIO::ImageInput::open(path);
    if (!in) return {};
    const OIIO::ImageSpec &spec = in->spec();
    int c = spec.channelindex(channel);
    if (c < 0) return {};
    std::vector<uint16_t> bits(size_t(spec.width) * spec.height);
    if (!in->read_image(0, 0, c, c + 1, OIIO::TypeHalf, bits.data())) return {};
    return bits;
}

TEST_F(IoTestModule, OverwriteKeepsEveryChannelOfAnyLineOrder) {
    // 40x100 half frames stored bottom-up (scanlines) and in random tile order: the
    // colour is replaced, every other channel and the noisy copies keep their bits.
    std::mt19937 random(41);
    std::uniform_real_distribution<float> value(-4.f, 4.f);
    const std::vector<std::string> channels = {"R", "G", "B", "A", "Z"};
    for (const char *order : {"decreasingY", "randomY"}) {
        OIIO::ImageSpec spec(40, 100, 5, OIIO::TypeHalf);
        spec.channelnames = channels;
        spec.attribute("openexr:lineOrder", order);
        if (std::string(order) == "randomY") spec.tile_width = spec.tile_height = 16;
        std::string path = Path(fmt::format("{}.exr", order));
        auto out = OIIO::ImageOutput::create(path);
        ASSERT_TRUE(out && out->open(path, spec)) << OIIO::geterror();
        std::vector<float> pixels(size_t(40) * 100 * 5);
        for (float &v : pixels) v = value(random);
        ASSERT_TRUE(out->write_image(OIIO::TypeFloat, pixels.data()));
        out->close();
        // OpenImageIO does not report the order: ask OpenEXR that it was stored so.
        Imf::LineOrder stored = Imf::InputFile(path.c_str()).header().lineOrder();
        ASSERT_EQ(stored, std::string(order) == "randomY" ? Imf::RANDOM_Y : Imf::DECREASING_Y);

        std::map<std::string, std::vector<uint16_t>> before;
        for (const std::string &c : channels) before[c] = HalfBits(path, c);
        Image denoised(40, 100, 3);
        for (float &v : denoised.data) v = value(random);
        WriteDenoisedOver(path, denoised, {{"mcd:method", "awr"}});
        for (int c = 0; c < 3; ++c) {
            std::vector<uint16_t> want;
            for (int y = 0; y < 100; ++y)
                for (int x = 0; x < 40; ++x)
                    want.push_back(Imath::half(denoised.At(c, y, x)).bits());
            EXPECT_EQ(HalfBits(path, channels[c]), want) << order << " " << channels[c];
            EXPECT_EQ(HalfBits(path, "color.noisy." + channels[c]), before[channels[c]])
                << order << " " << channels[c];
        }
        EXPECT_EQ(HalfBits(path, "A"), before["A"]) << order;
        EXPECT_EQ(HalfBits(path, "Z"), before["Z"]) << order;
    }
}

}  // namespace
}  // namespace mcd::io
