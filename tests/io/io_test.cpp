// host/io: frame reading and writing, layer-name grouping, errors and atomic writes.
#include <OpenImageIO/deepdata.h>
#include <OpenImageIO/imageio.h>
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "harness/errors.h"
#include "host/error.h"
#include "host/image.h"
#include "host/io/conventions.h"
#include "host/io/exr_read.h"
#include "host/io/frame.h"

namespace mcd::io {
namespace {

namespace fs = std::filesystem;
using test::Contains;
using test::ErrorOf;
using test::ThrowsError;

std::string ReadBytes(const fs::path &path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// A test image whose values differ per channel and pixel.
Image Ramp(int width, int height, int channels, float offset) {
    Image image(width, height, channels);
    for (size_t i = 0; i < image.Size(); ++i) image.data[i] = offset + 0.37f * float(i) - 3.f;
    return image;
}

bool BitEqual(const Image &a, const Image &b) {
    return a.SameShape(b) && std::memcmp(a.data.data(), b.data.data(), a.Size() * 4) == 0;
}

// The value a raw test file holds in channel c at (x, y): tells channels apart.
float RawValue(int c, int x, int y) {
    return 1000.f * float(c) + 10.f * float(y) + float(x);
}

class IoTest : public ::testing::Test {
  protected:
    void SetUp() override {
        std::random_device random;
        dir = fs::temp_directory_path() /
              ("mcd_io_test_" + std::to_string(::getpid()) + "_" + std::to_string(random()));
        fs::create_directories(dir);
    }
    void TearDown() override {
        std::error_code ec;
        fs::remove_all(dir, ec);
    }

    std::string Path(const std::string &name) const { return (dir / name).string(); }

    std::vector<std::string> Listing() const {
        std::vector<std::string> names;
        for (const auto &entry : fs::directory_iterator(dir))
            names.push_back(entry.path().filename().string());
        std::sort(names.begin(), names.end());
        return names;
    }

    // Write a file with OIIO directly, with raw channel names; channel c holds RawValue.
    void WriteRaw(const std::string &path, int width, int height,
                  const std::vector<std::string> &channels,
                  OIIO::TypeDesc format = OIIO::TypeFloat, int tileSize = 0) {
        int n = int(channels.size());
        OIIO::ImageSpec spec(width, height, n, format);
        spec.channelnames = channels;
        if (tileSize) spec.tile_width = spec.tile_height = tileSize;
        std::vector<float> pixels(size_t(width) * height * n);
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x)
                for (int c = 0; c < n; ++c)
                    pixels[(size_t(y) * width + x) * n + c] = RawValue(c, x, y);
        auto out = OIIO::ImageOutput::create(path);
        ASSERT_TRUE(out) << OIIO::geterror();
        ASSERT_TRUE(out->open(path, spec)) << out->geterror();
        ASSERT_TRUE(out->write_image(OIIO::TypeFloat, pixels.data())) << out->geterror();
        ASSERT_TRUE(out->close());
    }

    // Check a layer holds the raw channels named, in that order.
    void ExpectLayer(const Frame &frame, const std::string &layer,
                     const std::vector<std::string> &fileChannels,
                     const std::vector<std::string> &written) {
        ASSERT_TRUE(frame.Has(layer)) << layer;
        const Image &image = frame.Get(layer);
        ASSERT_EQ(image.channels, int(fileChannels.size())) << layer;
        for (size_t k = 0; k < fileChannels.size(); ++k) {
            auto it = std::find(written.begin(), written.end(), fileChannels[k]);
            ASSERT_NE(it, written.end()) << fileChannels[k];
            int c = int(it - written.begin());
            for (int y = 0; y < image.height; ++y)
                for (int x = 0; x < image.width; ++x)
                    ASSERT_EQ(image.At(int(k), y, x), RawValue(c, x, y))
                        << layer << " channel " << k << " should be " << fileChannels[k];
        }
    }

    // Write a file whose channel values come from value(channel name, x, y), with header
    // attributes (another renderer's metadata).
    void WriteValues(const std::string &path, int width, int height,
                     const std::vector<std::string> &channels,
                     const std::function<float(const std::string &, int, int)> &value,
                     const std::vector<OIIO::ParamValue> &attributes = {},
                     OIIO::TypeDesc format = OIIO::TypeFloat) {
        int n = int(channels.size());
        OIIO::ImageSpec spec(width, height, n, format);
        spec.channelnames = channels;
        for (const OIIO::ParamValue &attribute : attributes)
            spec.extra_attribs.push_back(attribute);
        std::vector<float> pixels(size_t(width) * height * n);
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x)
                for (int c = 0; c < n; ++c)
                    pixels[(size_t(y) * width + x) * n + c] = value(channels[c], x, y);
        auto out = OIIO::ImageOutput::create(path);
        ASSERT_TRUE(out) << OIIO::geterror();
        ASSERT_TRUE(out->open(path, spec)) << out->geterror();
        ASSERT_TRUE(out->write_image(OIIO::TypeFloat, pixels.data())) << out->geterror();
        ASSERT_TRUE(out->close());
    }

    // Check a layer holds value(channel name, x, y) for the named channels, in order.
    void ExpectValues(const Frame &frame, const std::string &layer,
                      const std::vector<std::string> &fileChannels,
                      const std::function<float(const std::string &, int, int)> &value,
                      float tolerance = 0.f) {
        ASSERT_TRUE(frame.Has(layer)) << layer;
        const Image &image = frame.Get(layer);
        ASSERT_EQ(image.channels, int(fileChannels.size())) << layer;
        for (size_t k = 0; k < fileChannels.size(); ++k)
            for (int y = 0; y < image.height; ++y)
                for (int x = 0; x < image.width; ++x)
                    ASSERT_NEAR(image.At(int(k), y, x), value(fileChannels[k], x, y), tolerance)
                        << layer << " channel " << k << " at " << x << "," << y;
    }

    fs::path dir;
};

TEST_F(IoTest, ExrRoundTripIsBitExact) {
    const int w = 13, h = 70;  // more rows than one band
    Image color = Ramp(w, h, 3, 0.f);
    color.At(0, 0, 0) = std::numeric_limits<float>::quiet_NaN();
    color.At(1, 0, 0) = -0.f;
    color.At(2, 0, 0) = std::numeric_limits<float>::denorm_min();
    color.At(0, 1, 0) = std::numeric_limits<float>::infinity();
    color.At(1, 1, 0) = 3.4e38f;
    Image variance = Ramp(w, h, 3, 1.f), spp = Ramp(w, h, 1, 2.f), normal = Ramp(w, h, 3, 3.f);
    Image depth = Ramp(w, h, 1, 4.f), hist = Ramp(w, h, 3 * 20 + 1, 5.f);
    Image diffInd = Ramp(w, h, 3, 6.f), feature = Ramp(w, h, 12, 7.f);
    Image alpha = Ramp(w, h, 1, 8.f), noisy = Ramp(w, h, 3, 9.f);
    std::vector<std::pair<std::string, const Image *>> layers = {
        {"color", &color},      {"variance", &variance}, {"spp", &spp},
        {"normal", &normal},    {"depth", &depth},       {"hist", &hist},
        {"DiffInd", &diffInd},  {"feature", &feature},   {"alpha", &alpha},
        {"color.extra", &noisy}};
    std::map<std::string, std::string> metadata = {{"mcd:spp", "64"},
                                                   {"mcd:scene", "cornell box"}};
    std::string path = Path("frame.exr");
    WriteExr(path, layers, metadata);
    EXPECT_EQ(Listing(), std::vector<std::string>{"frame.exr"});

    Frame frame = ReadFrame(path);
    EXPECT_EQ(frame.path, path);
    EXPECT_EQ(frame.width, w);
    EXPECT_EQ(frame.height, h);
    EXPECT_EQ(frame.layers.size(), layers.size());
    for (const auto &[name, image] : layers) {
        ASSERT_TRUE(frame.Has(name)) << name;
        EXPECT_TRUE(BitEqual(frame.Get(name), *image)) << name;
    }
    for (const auto &[key, value] : metadata) EXPECT_EQ(frame.metadata[key], value) << key;

    // The file holds float32 channels under the ARCHITECTURE.md names.
    auto in = OIIO::ImageInput::open(path);
    ASSERT_TRUE(in);
    const OIIO::ImageSpec &spec = in->spec();
    for (int c = 0; c < spec.nchannels; ++c)
        EXPECT_EQ(spec.channelformat(c), OIIO::TypeFloat) << spec.channelnames[c];
    for (const char *name :
         {"R", "G", "B", "variance.R", "spp.Y", "normal.X", "normal.Z", "depth.Z", "Bin_0000",
          "Bin_0060", "DiffInd.B", "feature.11", "A", "color.extra.R"})
        EXPECT_NE(std::find(spec.channelnames.begin(), spec.channelnames.end(), name),
                  spec.channelnames.end())
            << name;
    EXPECT_EQ(spec.nchannels, 3 + 3 + 1 + 3 + 1 + 61 + 3 + 12 + 1 + 3);
}

TEST_F(IoTest, ReadsPfm) {
    // OIIO 2.4 reads PFM but cannot write it, so write the (simple) format by hand:
    // header, then little-endian floats with the bottom row first.
    auto writePfm = [](const std::string &path, const char *magic, int w, int h, int n) {
        std::FILE *f = std::fopen(path.c_str(), "wb");
        ASSERT_TRUE(f);
        std::fprintf(f, "%s\n%d %d\n-1.0\n", magic, w, h);
        for (int fileRow = 0; fileRow < h; ++fileRow)
            for (int x = 0; x < w; ++x)
                for (int c = 0; c < n; ++c) {
                    float v = RawValue(c, x, h - 1 - fileRow);
                    std::fwrite(&v, 4, 1, f);
                }
        std::fclose(f);
    };
    writePfm(Path("rgb.pfm"), "PF", 3, 2, 3);
    writePfm(Path("grey.pfm"), "Pf", 3, 2, 1);

    Frame rgb = ReadFrame(Path("rgb.pfm"));
    EXPECT_EQ(rgb.layers.size(), 1u);
    ExpectLayer(rgb, "color", {"R", "G", "B"}, {"R", "G", "B"});
    Frame grey = ReadFrame(Path("grey.pfm"));
    EXPECT_EQ(grey.layers.size(), 1u);
    ExpectLayer(grey, "color", {"Y"}, {"Y"});
}

TEST_F(IoTest, ReadsHdr) {
    // Values with one shared power-of-two exponent per pixel survive RGBE closely.
    OIIO::ImageSpec spec(2, 1, 3, OIIO::TypeFloat);
    float pixels[6] = {0.5f, 1.f, 2.f, 0.25f, 0.125f, 0.0625f};
    std::string path = Path("image.hdr");
    auto out = OIIO::ImageOutput::create(path);
    ASSERT_TRUE(out && out->open(path, spec));
    ASSERT_TRUE(out->write_image(OIIO::TypeFloat, pixels));
    out->close();

    Image color = ReadImage(path);
    ASSERT_EQ(color.channels, 3);
    ASSERT_EQ(color.width, 2);
    for (int x = 0; x < 2; ++x)
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(color.At(c, 0, x), pixels[x * 3 + c], pixels[x * 3 + c] * 0.01f);
}

TEST_F(IoTest, ReadsPngAsLinear) {
    auto srgbToLinear = [](double v) {
        return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
    };
    {  // 8-bit RGBA: values are sRGB-decoded, alpha is kept linear as layer "alpha".
        OIIO::ImageSpec spec(2, 1, 4, OIIO::TypeUInt8);
        spec.attribute("oiio:UnassociatedAlpha", 1);  // store these bytes as they are
        uint8_t pixels[8] = {0, 128, 255, 7, 64, 200, 1, 255};
        std::string path = Path("rgba.png");
        auto out = OIIO::ImageOutput::create(path);
        ASSERT_TRUE(out && out->open(path, spec));
        ASSERT_TRUE(out->write_image(OIIO::TypeUInt8, pixels));
        out->close();

        Frame frame = ReadFrame(path);
        EXPECT_EQ(frame.layers.size(), 2u);
        const Image &color = frame.Get("color");
        ASSERT_EQ(color.channels, 3);
        for (int x = 0; x < 2; ++x)
            for (int c = 0; c < 3; ++c)
                EXPECT_NEAR(color.At(c, 0, x), srgbToLinear(pixels[x * 4 + c] / 255.0), 1e-6);
        const Image &alpha = frame.Get("alpha");
        ASSERT_EQ(alpha.channels, 1);
        for (int x = 0; x < 2; ++x)
            EXPECT_NEAR(alpha.At(0, 0, x), pixels[x * 4 + 3] / 255.0, 1e-6);
    }
    {  // 16-bit grey: one color channel.
        OIIO::ImageSpec spec(3, 1, 1, OIIO::TypeUInt16);
        uint16_t pixels[3] = {0, 32768, 65535};
        std::string path = Path("grey16.png");
        auto out = OIIO::ImageOutput::create(path);
        ASSERT_TRUE(out && out->open(path, spec));
        ASSERT_TRUE(out->write_image(OIIO::TypeUInt16, pixels));
        out->close();

        Image color = ReadImage(path);
        ASSERT_EQ(color.channels, 1);
        for (int x = 0; x < 3; ++x)
            EXPECT_NEAR(color.At(0, 0, x), srgbToLinear(pixels[x] / 65535.0), 1e-6);
    }
}

TEST_F(IoTest, GroupsPbrtV4Channels) {
    std::vector<std::string> channels = {"R",
                                         "G",
                                         "B",
                                         "Albedo.R",
                                         "Albedo.G",
                                         "Albedo.B",
                                         "P.X",
                                         "P.Y",
                                         "P.Z",
                                         "dzdx",
                                         "dzdy",
                                         "N.X",
                                         "N.Y",
                                         "N.Z",
                                         "Ns.X",
                                         "Ns.Y",
                                         "Ns.Z",
                                         "u",
                                         "v",
                                         "Variance.R",
                                         "Variance.G",
                                         "Variance.B",
                                         "RelativeVariance.R",
                                         "RelativeVariance.G",
                                         "RelativeVariance.B"};
    std::string path = Path("pbrt.exr");
    WriteRaw(path, 4, 3, channels);
    Frame frame = ReadFrame(path);

    ExpectLayer(frame, "color", {"R", "G", "B"}, channels);
    ExpectLayer(frame, "albedo", {"Albedo.R", "Albedo.G", "Albedo.B"}, channels);
    ExpectLayer(frame, "normal", {"N.X", "N.Y", "N.Z"}, channels);  // N preferred to Ns
    ExpectLayer(frame, "Ns", {"Ns.X", "Ns.Y", "Ns.Z"}, channels);
    // No samplesPerPixel in the header: the samples' variance is no variance of the mean.
    ExpectLayer(frame, "Variance", {"Variance.R", "Variance.G", "Variance.B"}, channels);
    EXPECT_FALSE(frame.Has("variance"));
    EXPECT_TRUE(Contains(frame.metadata[kConventionKey], "NO variance layer"));
    ExpectLayer(frame, "RelativeVariance",
                {"RelativeVariance.R", "RelativeVariance.G", "RelativeVariance.B"}, channels);
    for (const char *single : {"dzdx", "dzdy", "u", "v"})
        ExpectLayer(frame, single, {single}, channels);
    EXPECT_FALSE(frame.Has("P"));
    EXPECT_EQ(frame.layers.size(), 10u);
}

TEST_F(IoTest, GroupsBlenderChannels) {
    std::vector<std::string> channels = {
        "ViewLayer.Combined.R",         "ViewLayer.Combined.G",
        "ViewLayer.Combined.B",         "ViewLayer.Combined.A",
        "ViewLayer.Denoising Albedo.R", "ViewLayer.Denoising Albedo.G",
        "ViewLayer.Denoising Albedo.B", "ViewLayer.Denoising Normal.X",
        "ViewLayer.Denoising Normal.Y", "ViewLayer.Denoising Normal.Z",
        "ViewLayer.Denoising Depth.Z",  "ViewLayer.Depth.Z",
        "ViewLayer.DiffInd.R",          "ViewLayer.DiffInd.G",
        "ViewLayer.DiffInd.B",          "ViewLayer.CryptoObject00.R",
        "ViewLayer.CryptoObject00.G",   "ViewLayer.CryptoObject00.B",
        "ViewLayer.CryptoObject00.A"};
    std::string path = Path("blender.exr");
    WriteRaw(path, 3, 2, channels);
    Frame frame = ReadFrame(path);

    ExpectLayer(frame, "color",
                {"ViewLayer.Combined.R", "ViewLayer.Combined.G", "ViewLayer.Combined.B"},
                channels);
    ExpectLayer(frame, "albedo",
                {"ViewLayer.Denoising Albedo.R", "ViewLayer.Denoising Albedo.G",
                 "ViewLayer.Denoising Albedo.B"},
                channels);
    ExpectLayer(frame, "normal",
                {"ViewLayer.Denoising Normal.X", "ViewLayer.Denoising Normal.Y",
                 "ViewLayer.Denoising Normal.Z"},
                channels);
    ExpectLayer(frame, "depth", {"ViewLayer.Denoising Depth.Z"}, channels);
    // The plainer depth pass loses "depth" and keeps its own name.
    ExpectLayer(frame, "ViewLayer.Depth", {"ViewLayer.Depth.Z"}, channels);
    ExpectLayer(frame, "DiffInd",
                {"ViewLayer.DiffInd.R", "ViewLayer.DiffInd.G", "ViewLayer.DiffInd.B"},
                channels);
    // Unknown layers are kept whole, alpha included.
    ExpectLayer(frame, "ViewLayer.CryptoObject00",
                {"ViewLayer.CryptoObject00.R", "ViewLayer.CryptoObject00.G",
                 "ViewLayer.CryptoObject00.B", "ViewLayer.CryptoObject00.A"},
                channels);
    // Combined's alpha is the frame's (film transparency).
    ExpectLayer(frame, "alpha", {"ViewLayer.Combined.A"}, channels);
    EXPECT_EQ(frame.layers.size(), 8u);
}

TEST_F(IoTest, BlenderNoisyImageWinsColorOverCombined) {
    std::vector<std::string> channels = {"ViewLayer.Combined.R",    "ViewLayer.Combined.G",
                                         "ViewLayer.Combined.B",    "ViewLayer.Noisy Image.R",
                                         "ViewLayer.Noisy Image.G", "ViewLayer.Noisy Image.B"};
    std::string path = Path("noisy.exr");
    WriteRaw(path, 2, 2, channels);
    Frame frame = ReadFrame(path);
    ExpectLayer(
        frame, "color",
        {"ViewLayer.Noisy Image.R", "ViewLayer.Noisy Image.G", "ViewLayer.Noisy Image.B"},
        channels);
    ExpectLayer(frame, "ViewLayer.Combined",
                {"ViewLayer.Combined.R", "ViewLayer.Combined.G", "ViewLayer.Combined.B"},
                channels);
}

// Our own names with a dot are layers of their own, not a view-layer prefix in front of
// another own name: direct.variance sorts before variance in an EXR's channel list, and
// read as view layer "direct" of variance it took that name and clashed with the real one.
TEST_F(IoTest, OwnDottedNamesAreTheirOwnLayers) {
    std::vector<std::string> channels;
    for (const char *layer :
         {"direct.variance", "half0.color", "half1.color", "indirect.variance", "variance"})
        for (const char *c : {"R", "G", "B"}) channels.push_back(std::string(layer) + "." + c);
    for (const char *c : {"B", "G", "R"}) channels.push_back(c);
    std::string path = Path("dotted.exr");
    WriteRaw(path, 3, 2, channels);
    Frame frame = ReadFrame(path);
    for (const char *layer :
         {"direct.variance", "half0.color", "half1.color", "indirect.variance", "variance"})
        ExpectLayer(
            frame, layer,
            {std::string(layer) + ".R", std::string(layer) + ".G", std::string(layer) + ".B"},
            channels);
    ExpectLayer(frame, "color", {"R", "G", "B"}, channels);
    EXPECT_EQ(frame.layers.size(), 6u);
    // Only when asked for, as every own layer.
    Frame some = ReadFrame(path, {{"color", "variance"}});
    EXPECT_FALSE(some.Has("direct.variance"));
    EXPECT_FALSE(some.Has("half0.color"));
}

TEST_F(IoTest, OrdersChannelsWithinLayers) {
    std::vector<std::string> channels = {
        "B",         "A",          "G",         "R",         "albedo.B",   "albedo.G",
        "albedo.R",  "normal.Z",   "normal.X",  "normal.Y",  "spp",        "depth",
        "partId.V",  "objectId.Y", "mystery.U", "mystery.V", "feature.10", "feature.2",
        "feature.0", "feature.1",  "feature.3", "feature.4", "feature.5",  "feature.6",
        "feature.7", "feature.8",  "feature.9"};
    std::string path = Path("order.exr");
    WriteRaw(path, 3, 2, channels);
    Frame frame = ReadFrame(path);
    ExpectLayer(frame, "color", {"R", "G", "B"}, channels);
    ExpectLayer(frame, "albedo", {"albedo.R", "albedo.G", "albedo.B"}, channels);
    ExpectLayer(frame, "normal", {"normal.X", "normal.Y", "normal.Z"}, channels);
    ExpectLayer(frame, "spp", {"spp"}, channels);
    ExpectLayer(frame, "depth", {"depth"}, channels);
    ExpectLayer(frame, "partId", {"partId.V"}, channels);
    ExpectLayer(frame, "objectId", {"objectId.Y"}, channels);
    ExpectLayer(frame, "mystery", {"mystery.U", "mystery.V"}, channels);
    std::vector<std::string> feature;
    for (int i = 0; i <= 10; ++i) feature.push_back("feature." + std::to_string(i));
    ExpectLayer(frame, "feature", feature, channels);
    ExpectLayer(frame, "alpha", {"A"}, channels);
    EXPECT_FALSE(frame.Has("A"));
    EXPECT_EQ(frame.layers.size(), 10u);
}

TEST_F(IoTest, ReadsHistogramBinsInNumericOrder) {
    // Unpadded numbers sort differently as text (Bin_10 before Bin_2).
    std::vector<std::string> channels;
    for (int b = 0; b < 3 * 4 + 1; ++b) channels.push_back("Bin_" + std::to_string(b));
    std::string path = Path("bins.exr");
    WriteRaw(path, 2, 3, channels);
    Frame frame = ReadFrame(path);
    ExpectLayer(frame, "hist", channels, channels);
    EXPECT_EQ(frame.layers.size(), 1u);
}

TEST_F(IoTest, RefusesMalformedHistograms) {
    std::vector<std::string> sixty;
    for (int b = 0; b < 60; ++b) sixty.push_back("Bin_" + std::to_string(b));
    WriteRaw(Path("sixty.exr"), 2, 2, sixty);
    EXPECT_TRUE(ThrowsError(
        ErrorKind::Io, [&] { ReadFrame(Path("sixty.exr")); }, Path("sixty.exr")));

    WriteRaw(Path("gap.exr"), 2, 2,
             {"R", "G", "B", "Bin_0000", "Bin_0001", "Bin_0003", "Bin_0004"});
    EXPECT_TRUE(ThrowsError(
        ErrorKind::Io, [&] { ReadFrame(Path("gap.exr")); }, Path("gap.exr")));

    // WriteExr refuses a "hist" layer that ReadFrame would refuse.
    Image bad(2, 2, 5);
    EXPECT_TRUE(ThrowsError(ErrorKind::InvalidArgument, [&] {
        WriteExr(Path("bad.exr"), {{"hist", &bad}});
    }));
    EXPECT_FALSE(fs::exists(Path("bad.exr")));
}

TEST_F(IoTest, ReadsIntegerIdsAndTiledExr) {
    {  // 32-bit unsigned EXR channels keep their integer values.
        OIIO::ImageSpec spec(3, 1, 1, OIIO::TypeDesc::UINT32);
        spec.channelnames = {"objectId.Y"};
        uint32_t ids[3] = {0, 17, 123456};
        std::string path = Path("ids.exr");
        auto out = OIIO::ImageOutput::create(path);
        ASSERT_TRUE(out && out->open(path, spec));
        ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT32, ids));
        out->close();
        Image objectId = ReadImage(path, "objectId");
        ASSERT_EQ(objectId.channels, 1);
        for (int x = 0; x < 3; ++x) EXPECT_EQ(objectId.At(0, 0, x), float(ids[x]));
    }
    {  // Tiled, with partial tiles at the right and bottom and more rows than one band.
        std::vector<std::string> channels = {"R", "G", "B", "spp.Y"};
        std::string path = Path("tiled.exr");
        WriteRaw(path, 37, 45, channels, OIIO::TypeFloat, 16);
        Frame frame = ReadFrame(path);
        ExpectLayer(frame, "color", {"R", "G", "B"}, channels);
        ExpectLayer(frame, "spp", {"spp.Y"}, channels);
    }
}

TEST_F(IoTest, CopiesStringMetadata) {
    OIIO::ImageSpec spec(1, 1, 3, OIIO::TypeFloat);
    spec.attribute("mcd:spp", "256");
    spec.attribute("renderer", "pbrt-v4");
    spec.attribute("someInt", 5);
    float pixel[3] = {1, 2, 3};
    std::string path = Path("meta.exr");
    auto out = OIIO::ImageOutput::create(path);
    ASSERT_TRUE(out && out->open(path, spec));
    ASSERT_TRUE(out->write_image(OIIO::TypeFloat, pixel));
    out->close();
    Frame frame = ReadFrame(path);
    EXPECT_EQ(frame.metadata["mcd:spp"], "256");
    EXPECT_EQ(frame.metadata["renderer"], "pbrt-v4");
    EXPECT_EQ(frame.metadata.count("someInt"), 0u);  // string attributes only
}

TEST_F(IoTest, ErrorsNameTheFileAndTheLayer) {
    std::string missing = Path("missing.exr");
    EXPECT_TRUE(ThrowsError(
        ErrorKind::Io, [&] { ReadFrame(missing); }, missing));

    std::string text = Path("text.exr");
    std::ofstream(text) << "not an image";
    EXPECT_TRUE(ThrowsError(
        ErrorKind::Io, [&] { ReadFrame(text); }, text));

    std::string path = Path("color.exr");
    Image color = Ramp(4, 4, 3, 0.f), spp = Ramp(4, 4, 1, 0.f);
    WriteExr(path, {{"color", &color}, {"spp", &spp}});
    Frame frame = ReadFrame(path);
    std::string error = ErrorOf([&] { frame.Get("normal"); });
    EXPECT_TRUE(ThrowsError(
        ErrorKind::MissingLayer, [&] { frame.Get("normal"); }, path));
    EXPECT_TRUE(Contains(error, "'normal'"));
    EXPECT_TRUE(Contains(error, "color, spp"));
    EXPECT_TRUE(ThrowsError(
        ErrorKind::MissingLayer, [&] { ReadImage(path, "albedo"); }, "'albedo'"));
}

TEST_F(IoTest, TruncatedFilesAreErrorsNotCrashes) {
    Image color = Ramp(64, 64, 3, 0.f), hist = Ramp(64, 64, 61, 0.f);
    WriteExr(Path("full.exr"), {{"color", &color}, {"hist", &hist}});
    WritePng(Path("full.png"), color);
    for (const char *name : {"full.exr", "full.png"}) {
        std::string full = ReadBytes(dir / name);
        for (double fraction : {0.1, 0.5, 0.95}) {
            std::string cut = Path(std::string("cut_") + name);
            std::ofstream(cut, std::ios::binary)
                << full.substr(0, size_t(full.size() * fraction));
            EXPECT_TRUE(ThrowsError(
                ErrorKind::Io, [&] { ReadFrame(cut); }, cut))
                << fraction;
        }
    }
}

// Bytes overwritten inside a ZIP chunk: an error naming the file, for every layer and for
// a few, not a crash and not silently wrong values.
TEST_F(IoTest, DamagedExrChunksAreErrorsNamingTheFile) {
    Image color = Ramp(64, 64, 3, 0.f), hist = Ramp(64, 64, 61, 0.f);
    WriteExr(Path("full.exr"), {{"color", &color}, {"hist", &hist}});
    std::string bytes = ReadBytes(dir / "full.exr");
    for (size_t i = bytes.size() * 6 / 10; i < bytes.size() * 6 / 10 + 200; ++i)
        bytes[i] = char(0xff);
    std::string damaged = Path("damaged.exr");
    std::ofstream(damaged, std::ios::binary) << bytes;
    EXPECT_TRUE(ThrowsError(
        ErrorKind::Io, [&] { ReadFrame(damaged); }, damaged));
    EXPECT_TRUE(ThrowsError(
        ErrorKind::Io, [&] { ReadFrame(damaged, {{"color"}}); }, damaged));
}

// A data window larger than the memory allowed is an error before any allocation; the
// limit counts only the layers read.
TEST_F(IoTest, RefusesADataWindowBeyondTheMemoryLimit) {
    Image color = Ramp(64, 64, 3, 0.f), hist = Ramp(64, 64, 61, 0.f);
    std::string path = Path("limit.exr");
    WriteExr(path, {{"color", &color}, {"hist", &hist}});
    // Every layer: 64 x 64 x 64 channels x 4 bytes = 1 MiB.
    EXPECT_TRUE(ThrowsError(
        ErrorKind::OutOfMemory,
        [&] {
            ReadFrame(path, {{}, (1 << 20) - 1});
        },
        "64 channel(s)"));
    EXPECT_NO_THROW(ReadFrame(path, {{}, 1 << 20}));
    // color alone: 48 KiB.
    EXPECT_NO_THROW(ReadFrame(path, {{"color"}, 64 * 64 * 3 * 4}));
    EXPECT_TRUE(ThrowsError(
        ErrorKind::OutOfMemory,
        [&] {
            ReadFrame(path, {{"color"}, 64 * 64 * 3 * 4 - 1});
        },
        "3 channel(s)"));
}

TEST_F(IoTest, RefusesUnsupportedChannelFormat) {
    OIIO::ImageSpec spec(2, 2, 1, OIIO::TypeDesc::INT16);
    int16_t pixels[4] = {-5, 0, 5, 100};
    std::string path = Path("signed.tif");
    auto out = OIIO::ImageOutput::create(path);
    ASSERT_TRUE(out && out->open(path, spec));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::INT16, pixels));
    out->close();
    EXPECT_TRUE(ThrowsError(
        ErrorKind::Io, [&] { ReadFrame(path); }, path));
}

TEST_F(IoTest, WriteExrRefusesMismatchedAndEmptyLayers) {
    Image color(8, 8, 3), variance(8, 7, 3), empty;
    std::string path = Path("out.exr");
    std::string error = ErrorOf([&] {
        WriteExr(path, {{"color", &color}, {"variance", &variance}});
    });
    EXPECT_TRUE(Contains(error, path));
    EXPECT_TRUE(Contains(error, "'variance'"));
    EXPECT_TRUE(ThrowsError(ErrorKind::InvalidArgument, [&] {
        WriteExr(path, {{"color", &color}, {"variance", &variance}});
    }));
    EXPECT_TRUE(ThrowsError(
        ErrorKind::InvalidArgument,
        [&] {
            WriteExr(path, {{"color", &empty}});
        },
        "'color'"));
    EXPECT_TRUE(ThrowsError(
        ErrorKind::InvalidArgument, [&] { WriteExr(path, {}); }, path));
    EXPECT_TRUE(Listing().empty());
}

TEST_F(IoTest, RefusesUnwritableDirectory) {
    // Root may write anywhere, so use directories that cannot hold a file at all.
    Image color(4, 4, 3, 0.5f);
    std::string noDir = Path("no/such/dir/out.exr");
    EXPECT_TRUE(ThrowsError(
        ErrorKind::Io,
        [&] {
            WriteExr(noDir, {{"color", &color}});
        },
        noDir));
    std::string noPng = Path("no/such/dir/out.png");
    EXPECT_TRUE(ThrowsError(
        ErrorKind::Io, [&] { WritePng(noPng, color); }, noPng));

    std::ofstream(Path("file")) << "a file, not a directory";
    std::string underFile = Path("file/out.exr");
    EXPECT_TRUE(ThrowsError(
        ErrorKind::Io,
        [&] {
            WriteExr(underFile, {{"color", &color}});
        },
        underFile));
    EXPECT_EQ(Listing(), std::vector<std::string>{"file"});
}

TEST_F(IoTest, FailedWritesLeaveTheOldFileIntact) {
    std::string path = Path("frame.exr");
    Image good = Ramp(6, 5, 3, 1.f);
    WriteExr(path, {{"color", &good}});
    std::string before = ReadBytes(path);
    ASSERT_FALSE(before.empty());

    // A write refused for its layers.
    Image color(6, 5, 3, 9.f), spp(5, 5, 1, 1.f);
    EXPECT_TRUE(ThrowsError(
        ErrorKind::InvalidArgument,
        [&] {
            WriteExr(path, {{"color", &color}, {"spp", &spp}});
        },
        path));
    EXPECT_EQ(ReadBytes(path), before);
    EXPECT_EQ(Listing(), std::vector<std::string>{"frame.exr"});

    // A write that fails after the temporary file is written: the rename onto a
    // non-empty directory fails, and the temporary file must go.
    fs::create_directory(dir / "taken.exr");
    std::ofstream(dir / "taken.exr" / "keep") << "x";
    EXPECT_TRUE(ThrowsError(
        ErrorKind::Io,
        [&] {
            WriteExr(Path("taken.exr"), {{"color", &color}});
        },
        Path("taken.exr")));
    EXPECT_TRUE(ThrowsError(
        ErrorKind::Io, [&] { WritePng(Path("taken.exr"), color); }, Path("taken.exr")));
    EXPECT_TRUE(fs::exists(dir / "taken.exr" / "keep"));
    EXPECT_EQ(Listing(), (std::vector<std::string>{"frame.exr", "taken.exr"}));

    // A good write replaces the file whole and leaves nothing else behind.
    WriteExr(path, {{"color", &color}});
    EXPECT_TRUE(BitEqual(ReadImage(path), color));
    EXPECT_EQ(Listing(), (std::vector<std::string>{"frame.exr", "taken.exr"}));
}

// A write onto a symbolic link replaces the file it leads to and leaves the link a link; an
// existing file keeps its permission bits (the temporary file's are the umask's).
TEST_F(IoTest, WritesThroughLinksAndKeepsPermissions) {
    fs::create_directory(dir / "real");
    const std::string target = Path("real/target.exr"), link = Path("link.exr");
    Image first = Ramp(6, 5, 3, 1.f), second(6, 5, 3, 4.f);
    WriteExr(target, {{"color", &first}});
    fs::permissions(target, fs::perms::owner_read | fs::perms::owner_write);
    fs::create_symlink(fs::path("real") / "target.exr", link);
    WriteExr(link, {{"color", &second}});
    EXPECT_TRUE(fs::is_symlink(link));
    EXPECT_TRUE(BitEqual(ReadImage(target), second));
    EXPECT_EQ(fs::status(target).permissions() & fs::perms::all,
              fs::perms::owner_read | fs::perms::owner_write);
    for (const auto &entry : fs::directory_iterator(dir / "real"))
        EXPECT_EQ(entry.path().filename(), "target.exr") << "a temporary file was left";
    // A PNG too, and a file of other bits.
    const std::string png = Path("real/image.png"), pngLink = Path("image.png");
    WritePng(png, first);
    fs::permissions(png,
                    fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
    fs::create_symlink(fs::path("real") / "image.png", pngLink);
    WritePng(pngLink, second);
    EXPECT_TRUE(fs::is_symlink(pngLink));
    EXPECT_EQ(fs::status(png).permissions() & fs::perms::all,
              fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
}

TEST_F(IoTest, WritePngShowsNonFiniteAsMagenta) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    Image rgb(5, 1, 3);
    float values[5][3] = {{nan, 0.5f, 0.5f},
                          {0.f, inf, 0.f},
                          {2.f, 1.f, 1.5f},
                          {-1.f, 0.f, -inf},
                          {1.f, 0.f, 0.f}};
    for (int x = 0; x < 5; ++x)
        for (int c = 0; c < 3; ++c) rgb.At(c, 0, x) = values[x][c];
    std::string path = Path("preview.png");
    WritePng(path, rgb, 0.5f);
    EXPECT_EQ(Listing(), std::vector<std::string>{"preview.png"});

    auto in = OIIO::ImageInput::open(path);
    ASSERT_TRUE(in) << OIIO::geterror();
    ASSERT_EQ(in->spec().nchannels, 3);
    ASSERT_EQ(in->spec().width, 5);
    uint8_t pixels[15];
    ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeUInt8, pixels));
    const uint8_t expected[5][3] = {
        {255, 0, 255}, {255, 0, 255}, {255, 188, 225}, {255, 0, 255}, {188, 0, 0}};
    for (int x = 0; x < 5; ++x)
        for (int c = 0; c < 3; ++c)
            EXPECT_EQ(int(pixels[x * 3 + c]), int(expected[x][c])) << x << "," << c;

    // A grey image with NaN also works, and ReadFrame can read the preview back.
    Image grey(3, 2, 1, 0.25f);
    grey.At(0, 1, 2) = nan;
    WritePng(Path("grey.png"), grey);
    Image back = ReadImage(Path("grey.png"));
    EXPECT_EQ(back.channels, 3);
    EXPECT_NEAR(back.At(0, 0, 0), 0.25f, 0.01f);
    EXPECT_EQ(back.At(1, 1, 2), 0.f);  // magenta: no green

    // With alpha: RGBA, the color as without it (not divided by alpha), alpha linear.
    Image alpha(5, 1, 1);
    for (int x = 0; x < 5; ++x) alpha.At(0, 0, x) = float(x) / 4.f;
    alpha.At(0, 0, 4) = 7.f;  // clamped
    WritePngWithAlpha(Path("rgba.png"), rgb, &alpha, 0.5f);
    auto rgba = OIIO::ImageInput::open(Path("rgba.png"));
    ASSERT_TRUE(rgba) << OIIO::geterror();
    ASSERT_EQ(rgba->spec().nchannels, 4);
    uint8_t pixels4[20];
    ASSERT_TRUE(rgba->read_image(0, 0, 0, 4, OIIO::TypeUInt8, pixels4));
    const uint8_t alphas[5] = {0, 64, 128, 191, 255};
    for (int x = 0; x < 5; ++x) EXPECT_EQ(int(pixels4[x * 4 + 3]), int(alphas[x])) << x;
    Frame back4 = ReadFrame(Path("rgba.png"));
    ASSERT_TRUE(back4.Has("alpha"));
    EXPECT_NEAR(back4.Get("alpha").At(0, 0, 1), 0.25f, 0.5f / 255);
    for (int c = 0; c < 3; ++c)  // half covered, the same color as without alpha
        EXPECT_EQ(back4.Get("color").At(c, 0, 2), ReadImage(path).At(c, 0, 2)) << c;
    EXPECT_TRUE(ThrowsError(ErrorKind::InvalidArgument,
                            [&] { WritePngWithAlpha(Path("bad.png"), rgb, &grey); }));
    EXPECT_EQ(back.At(0, 1, 2), 1.f);
}

// Blender light passes: a pass's value from its name, so Combined can be made from them.
float BlenderValue(const std::string &channel, int x, int y) {
    std::string pass = channel.substr(channel.find('.') + 1);
    pass = pass.substr(0, pass.rfind('.'));
    int c = int(std::string("RGBA").find(channel.back()));
    auto value = [&](const std::string &p) -> float {
        if (p.ends_with("Col")) return 0.5f + 0.1f * c + 0.01f * x;
        if (p.ends_with("Dir")) return (p[0] == 'D' ? 1.f : 0.5f) + 0.1f * x + 0.02f * c;
        if (p.ends_with("Ind")) return (p[0] == 'D' ? 0.25f : 0.125f) * (y + 1) + 0.03f * c;
        if (p == "Emit") return 0.1f * c;
        if (p == "Env") return 0.2f;
        return 0.f;
    };
    if (pass == "Combined") {
        if (c == 3) return 1.f;
        float sum = value("Emit") + value("Env");
        for (std::string x : {"Diff", "Gloss"})
            sum += (value(x + "Dir") + value(x + "Ind")) * value(x + "Col");
        return sum;
    }
    if (pass == "Debug Sample Count") return 0.25f * float(x + 1);
    return value(pass);
}

std::vector<std::string> BlenderChannels(const std::vector<std::string> &rgbPasses) {
    std::vector<std::string> channels = {"ViewLayer.Combined.R", "ViewLayer.Combined.G",
                                         "ViewLayer.Combined.B", "ViewLayer.Combined.A"};
    for (const std::string &pass : rgbPasses)
        for (const char *c : {"R", "G", "B"}) channels.push_back("ViewLayer." + pass + "." + c);
    return channels;
}

TEST_F(IoTest, BlenderComposesDirectAndIndirectFromTheLightPasses) {
    std::vector<std::string> channels = BlenderChannels(
        {"DiffDir", "DiffInd", "DiffCol", "GlossDir", "GlossInd", "GlossCol", "Emit", "Env"});
    for (const char *single :
         {"ViewLayer.IndexOB.X", "ViewLayer.IndexMA.X", "ViewLayer.Debug Sample Count.X"})
        channels.push_back(single);
    std::string path = Path("cycles.exr");
    WriteValues(path, 4, 3, channels, BlenderValue, {{"cycles.ViewLayer.samples", "16"}});
    Frame frame = ReadFrame(path);

    auto part = [](bool direct) {
        return [direct](const std::string &channel, int x, int y) {
            float sum = direct ? BlenderValue("V.Emit." + channel, x, y) +
                                     BlenderValue("V.Env." + channel, x, y)
                               : 0.f;
            for (std::string p : {"Diff", "Gloss"})
                sum += BlenderValue("V." + p + (direct ? "Dir." : "Ind.") + channel, x, y) *
                       BlenderValue("V." + p + "Col." + channel, x, y);
            return sum;
        };
    };
    ExpectValues(frame, "direct", {"R", "G", "B"}, part(true), 1e-5f);
    ExpectValues(frame, "indirect", {"R", "G", "B"}, part(false), 1e-5f);
    // Debug Sample Count is a share of cycles.ViewLayer.samples.
    ExpectValues(frame, "spp", {"x"},
                 [](const std::string &, int x, int) { return 4.f * (x + 1); });
    EXPECT_TRUE(frame.Has("objectId"));
    EXPECT_TRUE(frame.Has("partId"));  // IndexMA
    const std::string &line = frame.metadata[kConventionKey];
    EXPECT_TRUE(Contains(line, "read as Blender Cycles multilayer (view layer 'ViewLayer')"));
    EXPECT_TRUE(Contains(line,
                         "direct/indirect composed from the light passes (Diff, Gloss, "
                         "Emit, Env)"));
    EXPECT_TRUE(Contains(line, "spp = Debug Sample Count x 16"));
    EXPECT_TRUE(Contains(line, "no variance (Cycles writes none)"));
    EXPECT_FALSE(Contains(line, "the rest goes to indirect"));
}

TEST_F(IoTest, BlenderSplitKeepsWhatThePassesMissAndSaysSo) {
    // Gloss is in Combined but its passes were not written; no sample total either.
    std::vector<std::string> channels =
        BlenderChannels({"DiffDir", "DiffInd", "DiffCol", "Emit", "Env"});
    channels.push_back("ViewLayer.Debug Sample Count.X");
    std::string path = Path("partial.exr");
    WriteValues(path, 3, 2, channels, BlenderValue);
    Frame frame = ReadFrame(path);

    ASSERT_TRUE(frame.Has("direct") && frame.Has("indirect"));
    const Image &color = frame.Get("color"), &direct = frame.Get("direct"),
                &indirect = frame.Get("indirect");
    for (size_t i = 0; i < color.Size(); ++i)
        EXPECT_NEAR(direct.data[i] + indirect.data[i], color.data[i], 1e-5f);
    EXPECT_FALSE(frame.Has("spp"));
    EXPECT_TRUE(frame.Has("Debug Sample Count"));
    const std::string &line = frame.metadata[kConventionKey];
    EXPECT_TRUE(Contains(line,
                         "the rest goes to indirect (passes not written: VolumeDir "
                         "VolumeInd Gloss* Trans*)"));
    EXPECT_TRUE(Contains(line, "Debug Sample Count kept as a fraction"));

    // Light passes without their colour pass are not composed.
    std::string noCol = Path("nocol.exr");
    WriteValues(noCol, 3, 2, BlenderChannels({"DiffDir", "DiffInd"}), BlenderValue);
    Frame bare = ReadFrame(noCol);
    EXPECT_FALSE(bare.Has("direct"));
    EXPECT_TRUE(Contains(bare.metadata[kConventionKey],
                         "no direct/indirect: the light passes of "
                         "Diff lack Dir, Ind or Col"));
}

// A light pass of other than 3 channels (a damaged or hand-made file) is not composed:
// it was summed as if it had 3, reading past its planes (found by fuzzing a Cycles frame
// under AddressSanitizer with one channel renamed).
TEST_F(IoTest, BlenderPassesOfTheWrongWidthAreNotComposed) {
    std::vector<std::string> channels = BlenderChannels({"DiffDir", "DiffInd"});
    for (const char *c : {"ViewLayer.DiffCol.R", "ViewLayer.DiffCol.G"}) channels.push_back(c);
    std::string twoCol = Path("twocol.exr");
    WriteValues(twoCol, 3, 2, channels, BlenderValue);
    Frame frame = ReadFrame(twoCol);
    EXPECT_FALSE(frame.Has("direct"));
    EXPECT_TRUE(Contains(frame.metadata[kConventionKey],
                         "no direct/indirect: the light passes of Diff lack Dir, Ind or Col"));

    channels = BlenderChannels({"DiffDir", "DiffInd", "DiffCol"});
    channels.push_back("ViewLayer.Emit.R");
    std::string oneEmit = Path("oneemit.exr");
    WriteValues(oneEmit, 3, 2, channels, BlenderValue);
    frame = ReadFrame(oneEmit);
    ASSERT_TRUE(frame.Has("direct") && frame.Has("indirect"));
    const Image &color = frame.Get("color"), &direct = frame.Get("direct"),
                &indirect = frame.Get("indirect");
    for (size_t i = 0; i < color.Size(); ++i)
        EXPECT_NEAR(direct.data[i] + indirect.data[i], color.data[i], 1e-5f);
    EXPECT_TRUE(Contains(frame.metadata[kConventionKey], "from the light passes (Diff)"));
}

TEST_F(IoTest, PbrtVarianceOfTheSamplesBecomesVarianceOfTheMean) {
    std::vector<std::string> channels = {"R",          "G",   "B",   "Variance.R", "Variance.G",
                                         "Variance.B", "N.X", "N.Y", "N.Z"};
    auto value = [](const std::string &channel, int x, int y) {
        return 0.5f * float(channel.size()) + float(x) + 4.f * float(y);
    };
    std::string path = Path("pbrt.exr");
    // pbrt-v4 writes half floats by default, and the sample count only in the header.
    WriteValues(path, 4, 3, channels, value, {{"samplesPerPixel", 16}}, OIIO::TypeHalf);
    Frame frame = ReadFrame(path);
    ExpectValues(frame, "variance", {"Variance.R", "Variance.G", "Variance.B"},
                 [&](const std::string &c, int x, int y) { return value(c, x, y) / 16.f; });
    EXPECT_FALSE(frame.Has("Variance"));
    EXPECT_TRUE(Contains(frame.metadata[kConventionKey],
                         "read as pbrt-v4 GBufferFilm: variance = Variance.* / "
                         "samplesPerPixel (16)"));

    // A file's own variance layer is ours already: left alone.
    std::vector<std::string> own = {"R", "G", "B", "variance.R", "variance.G", "variance.B"};
    std::string ownPath = Path("own.exr");
    WriteValues(ownPath, 2, 2, own, value, {{"samplesPerPixel", 16}});
    Frame ours = ReadFrame(ownPath);
    ExpectValues(ours, "variance", {"variance.R", "variance.G", "variance.B"}, value);
    EXPECT_EQ(ours.metadata.count(kConventionKey), 0u);
}

TEST_F(IoTest, ReadsMitsubaAovs) {
    std::vector<std::string> channels = {
        "R",        "G",           "B",           "A",           "albedo.R", "albedo.G",
        "albedo.B", "sh_normal.X", "sh_normal.Y", "sh_normal.Z", "depth.T",  "shape_index.I"};
    std::string path = Path("mitsuba_aov.exr");
    WriteRaw(path, 3, 2, channels);
    Frame frame = ReadFrame(path);
    ExpectLayer(frame, "albedo", {"albedo.R", "albedo.G", "albedo.B"}, channels);
    ExpectLayer(frame, "normal", {"sh_normal.X", "sh_normal.Y", "sh_normal.Z"}, channels);
    ExpectLayer(frame, "depth", {"depth.T"}, channels);
    ExpectLayer(frame, "objectId", {"shape_index.I"}, channels);
    const std::string &line = frame.metadata[kConventionKey];
    EXPECT_TRUE(Contains(line,
                         "read as Mitsuba 3 aov: normal from sh_normal (world space); "
                         "depth from depth.T (distance along the ray); objectId from "
                         "shape_index"));
}

TEST_F(IoTest, MitsubaMomentsMakeVarianceWhenTheSampleCountIsKnown) {
    std::vector<std::string> channels = {
        "R", "G", "B", "path.X", "path.Y", "path.Z", "m2_path.X", "m2_path.Y", "m2_path.Z"};
    // Grey pixels: color = Y, so the variance is (m2 - m1^2) / spp in every channel.
    auto value = [](const std::string &channel, int x, int y) {
        float mean = 0.5f + 0.25f * float(x + y);
        if (channel.starts_with("m2_")) return mean * mean + 0.125f * float(x + 1);
        return mean;
    };
    std::string path = Path("moment.exr");
    WriteValues(path, 3, 2, channels, value, {{"spp", 4}});
    Frame frame = ReadFrame(path);
    ExpectValues(
        frame, "variance", {"R", "G", "B"},
        [](const std::string &, int x, int) { return 0.125f * float(x + 1) / 4.f; }, 1e-6f);
    EXPECT_TRUE(Contains(frame.metadata[kConventionKey],
                         "read as Mitsuba 3 moment (path, m2_path): variance = (m2_path.Y - "
                         "path.Y^2) / spp (4)"));

    std::string noSpp = Path("moment_nospp.exr");
    WriteValues(noSpp, 3, 2, channels, value);
    Frame bare = ReadFrame(noSpp);
    EXPECT_FALSE(bare.Has("variance"));
    EXPECT_TRUE(Contains(bare.metadata[kConventionKey],
                         "NO variance: the file does not say how many samples per pixel"));
}

// A frame Blender 3.4 rendered (scripts/blender/glossy_box.py --spp 16 --seed 1 --size 32),
// so the names and the split are checked against Cycles itself without Blender in CI.
TEST_F(IoTest, ReadsARealCyclesFrame) {
    Frame frame =
        ReadFrame(std::string(MCD_SOURCE_DIR) + "/tests/data/cycles_glossy_box_32_16spp.exr");
    ASSERT_EQ(frame.width, 32);
    for (const char *layer :
         {"color", "direct", "indirect", "albedo", "normal", "depth", "objectId", "partId"})
        EXPECT_TRUE(frame.Has(layer)) << layer;
    EXPECT_FALSE(frame.Has("variance"));
    // Cycles' light passes add up to its Combined: the split leaves nothing over.
    const Image &color = frame.Get("color"), &direct = frame.Get("direct"),
                &indirect = frame.Get("indirect");
    double gap = 0, total = 0;
    for (size_t i = 0; i < color.Size(); ++i) {
        gap += std::abs(color.data[i] - direct.data[i] - indirect.data[i]);
        total += std::abs(color.data[i]);
    }
    EXPECT_LT(gap, 1e-5 * total);
    ExpectValues(frame, "spp", {"spp"}, [](const std::string &, int, int) { return 16.f; });
    const std::string &line = frame.metadata[kConventionKey];
    EXPECT_TRUE(Contains(line, "read as Blender Cycles multilayer (view layer 'ViewLayer')"));
    EXPECT_TRUE(Contains(line, "normal from Denoising Normal (camera space)"));
    EXPECT_TRUE(Contains(line,
                         "direct/indirect composed from the light passes (Diff, Gloss, "
                         "Trans, Emit, Env, VolumeDir, VolumeInd)"));
    EXPECT_FALSE(Contains(line, "the rest goes to indirect"));
}

// The EXR chunk decoder (ZIP, ZIPS, none) gives the bytes OpenEXR's own reader gives, for
// every channel or a few, float, half and 32-bit unsigned, with a data window off the
// origin, a last chunk of fewer rows, chunks that compress and chunks stored raw (random
// bits), NaN and Inf; files it leaves to OpenEXR (PIZ, RLE, tiled) read the same too.
TEST_F(IoTest, ExrChunkDecoderMatchesOpenExr) {
    const int width = 13, height = 37;
    std::vector<std::string> names = {"B",          "G",         "R",          "depth.Y",
                                      "hist.0",     "hist.1",    "objectId.Y", "variance.B",
                                      "variance.G", "variance.R"};
    std::vector<OIIO::TypeDesc> formats = {
        OIIO::TypeFloat, OIIO::TypeFloat, OIIO::TypeFloat, OIIO::TypeHalf, OIIO::TypeFloat,
        OIIO::TypeFloat, OIIO::TypeUInt,  OIIO::TypeFloat, OIIO::TypeHalf, OIIO::TypeFloat};
    int n = int(names.size());
    // The pixels in the channels' own formats, and the floats they stand for: smooth rows
    // at the top (they compress), random bits below (stored raw), a few NaN and Inf.
    std::mt19937 random(7);
    std::vector<unsigned char> native;
    std::vector<float> expected(size_t(width) * height * n);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
            for (int c = 0; c < n; ++c) {
                bool smooth = y < 20;
                float &value = expected[(size_t(y) * width + x) * n + c];
                if (formats[c] == OIIO::TypeFloat) {
                    float f = smooth ? 0.25f * float(x) + float(c)
                                     : std::bit_cast<float>(uint32_t(random()));
                    if ((x * 7 + y * 3 + c) % 29 == 0)
                        f = std::numeric_limits<float>::quiet_NaN();
                    if ((x * 5 + y + c) % 31 == 0) f = -std::numeric_limits<float>::infinity();
                    uint32_t bits = std::bit_cast<uint32_t>(f);
                    for (int k = 0; k < 4; ++k) native.push_back(uint8_t(bits >> (8 * k)));
                    value = f;
                } else if (formats[c] == OIIO::TypeHalf) {
                    // 1 + x/1024, or any half (NaN and Inf among them).
                    uint16_t bits = smooth ? uint16_t(0x3c00 + x) : uint16_t(random());
                    native.push_back(uint8_t(bits)), native.push_back(uint8_t(bits >> 8));
                    int exponent = (bits >> 10) & 31, mantissa = bits & 1023;
                    float magnitude =
                        exponent == 31  ? (mantissa ? std::numeric_limits<float>::quiet_NaN()
                                                    : std::numeric_limits<float>::infinity())
                        : exponent == 0 ? std::ldexp(float(mantissa), -24)
                                        : std::ldexp(float(1024 + mantissa), exponent - 25);
                    value = bits & 0x8000 ? -magnitude : magnitude;
                } else {
                    uint32_t id = smooth ? uint32_t(x + c) : uint32_t(random());
                    for (int k = 0; k < 4; ++k) native.push_back(uint8_t(id >> (8 * k)));
                    value = float(id);
                }
            }

    for (const char *compression : {"zip", "zips", "none", "piz", "rle", "tiled"}) {
        SCOPED_TRACE(compression);
        std::string path = Path(std::string(compression) + ".exr");
        OIIO::ImageSpec spec(width, height, n, OIIO::TypeFloat);
        spec.x = -3, spec.y = 5;
        spec.channelnames = names;
        spec.channelformats = formats;
        bool tiled = std::string(compression) == "tiled";
        spec.attribute("compression", tiled ? "zip" : compression);
        if (tiled) spec.tile_width = spec.tile_height = 16;
        {
            auto out = OIIO::ImageOutput::create(path);
            ASSERT_TRUE(out && out->open(path, spec)) << OIIO::geterror();
            ASSERT_TRUE(out->write_image(OIIO::TypeUnknown, native.data())) << out->geterror();
            ASSERT_TRUE(out->close());
        }
        for (const std::vector<int> &wanted :
             {std::vector<int>{0, 1, 2, 3, 4, 5, 6, 7, 8, 9}, std::vector<int>{2, 6, 8},
              std::vector<int>{9}}) {
            Image ours(width, height, int(wanted.size())), theirs = ours;
            std::vector<ExrTarget> a, b;
            for (size_t k = 0; k < wanted.size(); ++k) {
                a.push_back({names[wanted[k]], ours.Plane(int(k))});
                b.push_back({names[wanted[k]], theirs.Plane(int(k))});
            }
            ASSERT_TRUE(ReadExrChannels(path, -3, 5, width, height, a, ExrDecoder::Auto));
            ASSERT_TRUE(ReadExrChannels(path, -3, 5, width, height, b, ExrDecoder::OpenExr));
            EXPECT_TRUE(BitEqual(ours, theirs)) << wanted.size() << " channels";
            // And they are the values written.
            for (size_t k = 0; k < wanted.size(); ++k)
                for (int y = 0; y < height; ++y)
                    for (int x = 0; x < width; ++x) {
                        float value = expected[(size_t(y) * width + x) * n + wanted[k]];
                        float read = ours.At(int(k), y, x);
                        ASSERT_TRUE(std::isnan(value) ? std::isnan(read) : read == value)
                            << names[wanted[k]] << " at " << x << "," << y << ": " << read
                            << " for " << value;
                    }
        }
    }
    // A data window other than the one given: not read.
    Image plane(width, height, 1);
    EXPECT_FALSE(
        ReadExrChannels(Path("zip.exr"), 0, 0, width, height, {{"R", plane.Plane(0)}}));
}

// Damaged EXRs for the chunk decoder, ZIP (chunks of 16 rows, the last shorter) and ZIPS:
// cut at many lengths, bytes overwritten at seeded places, and the offset table, chunk y
// and packed sizes set to values a bad file could hold. Each read is an error naming the
// file (a cut file always) or a read; where our decoder reads one, OpenEXR's reads the same
// bits. (A wider run of this under AddressSanitizer, on these and the Cycles frame of
// tests/data, found the overflow of BlenderPassesOfTheWrongWidthAreNotComposed.)
TEST_F(IoTest, DamagedExrFilesAreErrorsOrReadsNeverCrashes) {
    const int width = 7, height = 37, x0 = -2, y0 = 3;
    std::vector<std::string> names = {"B", "G", "R", "depth.Y", "objectId.Y"};
    std::vector<OIIO::TypeDesc> formats = {OIIO::TypeFloat, OIIO::TypeHalf, OIIO::TypeFloat,
                                           OIIO::TypeHalf, OIIO::TypeUInt};
    int n = int(names.size());
    std::mt19937 random(11);
    std::vector<unsigned char> native;
    for (int i = 0; i < width * height; ++i)
        for (int c = 0; c < n; ++c)
            for (int k = 0; k < (formats[c] == OIIO::TypeHalf ? 2 : 4); ++k)
                native.push_back(uint8_t(i < width * height / 2 ? i + c : random()));
    for (const char *compression : {"zip", "zips"}) {
        SCOPED_TRACE(compression);
        int chunkLines = std::string(compression) == "zip" ? 16 : 1;
        std::string source = Path(std::string("source_") + compression + ".exr");
        OIIO::ImageSpec spec(width, height, n, OIIO::TypeFloat);
        spec.x = x0, spec.y = y0;
        spec.channelnames = names;
        spec.channelformats = formats;
        spec.attribute("compression", compression);
        {
            auto out = OIIO::ImageOutput::create(source);
            ASSERT_TRUE(out && out->open(source, spec)) << OIIO::geterror();
            ASSERT_TRUE(out->write_image(OIIO::TypeUnknown, native.data())) << out->geterror();
            ASSERT_TRUE(out->close());
        }
        const std::string bytes = ReadBytes(source);
        // The header's attributes end with a 0 byte; the offset table (8 bytes a chunk)
        // follows, each chunk starting with its y and its packed size (4 bytes each).
        size_t at = 8;
        while (bytes.at(at) != 0) {
            at = bytes.find('\0', at) + 1;  // name
            at = bytes.find('\0', at) + 1;  // type
            int32_t size;
            std::memcpy(&size, bytes.data() + at, 4);
            at += 4 + size_t(size);
        }
        const size_t table = at + 1;
        const int chunks = (height + chunkLines - 1) / chunkLines;
        std::vector<uint64_t> offsets(chunks);
        std::memcpy(offsets.data(), bytes.data() + table, 8 * size_t(chunks));
        ASSERT_EQ(offsets[0], table + 8 * size_t(chunks));

        std::string damaged = Path(std::string("damaged_") + compression + ".exr");
        auto check = [&](const std::string &file, const std::string &what, bool mustFail) {
            SCOPED_TRACE(what);
            std::ofstream(damaged, std::ios::binary | std::ios::trunc) << file;
            // One read each: whether a damaged file fails is checked on the same call as
            // the failure's kind.
            std::optional<test::Thrown> thrown = test::ThrownBy([&] { ReadFrame(damaged); });
            if (mustFail || thrown) {
                ASSERT_TRUE(thrown) << "ReadFrame threw nothing";
                EXPECT_EQ(thrown->kind, ErrorKind::Io) << thrown->message;
                EXPECT_TRUE(Contains(thrown->message, damaged)) << thrown->message;
            }
            Image ours(width, height, n), theirs = ours;
            std::vector<ExrTarget> a, b;
            for (int c = 0; c < n; ++c) {
                a.push_back({names[c], ours.Plane(c)});
                b.push_back({names[c], theirs.Plane(c)});
            }
            thrown =
                test::ThrownBy([&] { ReadExrChannels(damaged, x0, y0, width, height, a); });
            if (thrown) {
                EXPECT_EQ(thrown->kind, ErrorKind::Io) << thrown->message;
                EXPECT_TRUE(Contains(thrown->message, damaged)) << thrown->message;
                return;
            }
            EXPECT_FALSE(mustFail);
            bool theirsRead =
                ErrorOf([&] {
                    ReadExrChannels(damaged, x0, y0, width, height, b, ExrDecoder::OpenExr);
                }) == "<no error>";
            if (theirsRead) {
                EXPECT_TRUE(BitEqual(ours, theirs));
            }
        };
        check(bytes, "as written", false);
        for (size_t length = 0; length < bytes.size(); length += 1 + random() % 53)
            check(bytes.substr(0, length), fmt::format("cut at {}", length), true);
        for (int trial = 0; trial < 40; ++trial) {
            std::string file = bytes;
            // Half the trials in the pixel data, half anywhere.
            size_t begin = trial % 2 ? table : 0;
            std::string what = "bytes at";
            for (int k = 0; k < 1 + trial % 3; ++k) {
                size_t place = begin + random() % (file.size() - begin);
                file[place] = char(random());
                what += fmt::format(" {}", place);
            }
            check(file, what, false);
        }
        auto put = [](std::string file, size_t place, auto value) {
            std::memcpy(file.data() + place, &value, sizeof(value));
            return file;
        };
        for (int c = 0; c < chunks; c += std::max(1, chunks / 3)) {
            for (uint64_t offset :
                 {uint64_t(0), uint64_t(table), uint64_t(bytes.size() - 4),
                  uint64_t(bytes.size() + 8), uint64_t(1) << 63, offsets[(c + 1) % chunks]})
                check(put(bytes, table + 8 * size_t(c), offset),
                      fmt::format("chunk {} at {}", c, offset), false);
            int32_t y, size;
            std::memcpy(&y, bytes.data() + offsets[c], 4);
            std::memcpy(&size, bytes.data() + offsets[c] + 4, 4);
            for (int32_t value : {y - 1, y + chunkLines, INT32_MIN, INT32_MAX})
                check(put(bytes, size_t(offsets[c]), value),
                      fmt::format("chunk {} y {}", c, value), true);
            for (int32_t value : {-1, 0, size - 1, size + 1, INT32_MAX})
                check(put(bytes, size_t(offsets[c]) + 4, value),
                      fmt::format("chunk {} size {}", c, value), true);
        }
    }
}

// A deep scanline EXR (ZIPS, as OIIO writes it) is OpenEXR's to read, which composites
// the samples: our decoder took its chunks for flat ones and failed. ReadFrame refuses
// deep files before.
TEST_F(IoTest, DeepExrIsLeftToOpenExr) {
    const int width = 5, height = 7;
    std::string path = Path("deep.exr");
    OIIO::ImageSpec spec(width, height, 5, OIIO::TypeFloat);
    spec.channelnames = {"R", "G", "B", "A", "Z"};
    spec.deep = true;
    spec.attribute("compression", "zips");
    OIIO::DeepData deep(spec);
    for (int i = 0; i < width * height; ++i) {
        deep.set_samples(i, 1);
        for (int c = 0; c < 5; ++c)
            deep.set_deep_value(i, c, 0, c >= 3 ? 1.f : 0.25f * float(i + c));
    }
    {
        auto out = OIIO::ImageOutput::create(path);
        ASSERT_TRUE(out && out->open(path, spec)) << OIIO::geterror();
        ASSERT_TRUE(out->write_deep_image(deep)) << out->geterror();
        ASSERT_TRUE(out->close());
    }
    Image ours(width, height, 3), theirs = ours;
    for (auto [image, decoder] :
         {std::pair{&ours, ExrDecoder::Auto}, std::pair{&theirs, ExrDecoder::OpenExr}})
        ASSERT_TRUE(ReadExrChannels(
            path, 0, 0, width, height,
            {{"R", image->Plane(0)}, {"G", image->Plane(1)}, {"B", image->Plane(2)}}, decoder));
    EXPECT_TRUE(BitEqual(ours, theirs));
    EXPECT_EQ(ours.At(2, 1, 3), 0.25f * (8 + 2));
    EXPECT_TRUE(ThrowsError(
        ErrorKind::Io, [&] { ReadFrame(path); }, path));
}

// ReadExrChannels with a channel asked for twice fills both planes (our decoder restored
// its bytes twice, reading far outside its buffer), and with a channel the file does not
// have is an error naming both (OpenEXR's reader had filled it with zeros).
TEST_F(IoTest, ExrChannelsTwiceOrMissing) {
    Image color = Ramp(5, 19, 3, 0.f);
    std::string path = Path("color.exr");
    WriteExr(path, {{"color", &color}});
    for (ExrDecoder decoder : {ExrDecoder::Auto, ExrDecoder::OpenExr}) {
        Image twice(5, 19, 3);
        ASSERT_TRUE(ReadExrChannels(
            path, 0, 0, 5, 19,
            {{"R", twice.Plane(0)}, {"G", twice.Plane(1)}, {"R", twice.Plane(2)}}, decoder));
        for (size_t i = 0; i < twice.PixelCount(); ++i) {
            ASSERT_EQ(twice.Plane(0)[i], color.Plane(0)[i]) << i;
            ASSERT_EQ(twice.Plane(1)[i], color.Plane(1)[i]) << i;
            ASSERT_EQ(twice.Plane(2)[i], color.Plane(0)[i]) << i;
        }
        std::string error = ErrorOf([&] {
            ReadExrChannels(path, 0, 0, 5, 19, {{"Q", twice.Plane(0)}}, decoder);
        });
        EXPECT_TRUE(Contains(error, path));
        EXPECT_TRUE(Contains(error, "'Q'"));
        EXPECT_TRUE(ThrowsError(ErrorKind::Io, [&] {
            ReadExrChannels(path, 0, 0, 5, 19, {{"Q", twice.Plane(0)}}, decoder);
        }));
    }
}

// ReadOptions::layers: the layers asked for come back bit for bit as in a full read, the
// others are not there; Cycles' light passes come only with direct or indirect; renderer
// passes that are not ours stay.
TEST_F(IoTest, ReadsOnlyTheLayersAskedFor) {
    std::string ours = Path("ours.exr");
    Image color = Ramp(7, 5, 3, 0.f), variance = Ramp(7, 5, 3, 9.f), hist = Ramp(7, 5, 7, 2.f),
          partial = Ramp(7, 5, 3, 5.f);
    WriteExr(ours, {{"color", &color},
                    {"variance", &variance},
                    {"hist", &hist},
                    {"partial0.color", &partial}});
    Frame all = ReadFrame(ours);
    Frame some = ReadFrame(ours, {{"color", "variance", "alpha"}});
    EXPECT_TRUE(BitEqual(some.Get("color"), all.Get("color")));
    EXPECT_TRUE(BitEqual(some.Get("variance"), all.Get("variance")));
    EXPECT_FALSE(some.Has("hist"));
    EXPECT_FALSE(some.Has("partial0.color"));
    Frame partials = ReadFrame(ours, {{"color", "partial*"}});
    EXPECT_TRUE(BitEqual(partials.Get("partial0.color"), all.Get("partial0.color")));
    EXPECT_FALSE(partials.Has("variance"));

    std::string cycles =
        std::string(MCD_SOURCE_DIR) + "/tests/data/cycles_glossy_box_32_16spp.exr";
    Frame full = ReadFrame(cycles);
    Frame plain = ReadFrame(cycles, {{"color", "albedo"}});
    EXPECT_FALSE(plain.Has("direct"));
    EXPECT_FALSE(plain.Has("DiffDir"));
    EXPECT_FALSE(plain.Has("normal"));
    EXPECT_TRUE(BitEqual(plain.Get("albedo"), full.Get("albedo")));
    Frame split = ReadFrame(cycles, {{"color", "direct", "indirect"}});
    EXPECT_TRUE(BitEqual(split.Get("direct"), full.Get("direct")));
    EXPECT_TRUE(BitEqual(split.Get("indirect"), full.Get("indirect")));
    EXPECT_FALSE(split.Has("albedo"));
}

}  // namespace
}  // namespace mcd::io
