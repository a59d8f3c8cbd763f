// Issue #29 item 4, Blender conventions in host/io: Film > Transparent (Env left out of
// direct where Combined leaves the background out; alpha from Combined.A), the denoised
// colour written into a frame under the renderer's own channel names (WriteDenoisedOver),
// and the missing-layer hints per renderer (hints.h).
#include <OpenImageIO/imageio.h>
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "harness/errors.h"
#include "host/error.h"
#include "host/image.h"
#include "host/io/conventions.h"
#include "host/io/frame.h"
#include "host/io/hints.h"
#include "mcdenoise/mcdenoise.h"

namespace mcd::io {
namespace {

namespace fs = std::filesystem;
using test::Contains;

const std::string kTransparent =
    std::string(MCD_SOURCE_DIR) + "/tests/data/cycles_transparent_24_16spp_s1.exr";

std::string ReadBytes(const fs::path &path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// A file as stored: each channel's name, pixel type and native bytes (pixel after pixel),
// and its header attributes as text.
struct Stored {
    std::vector<std::string> names;
    std::map<std::string, OIIO::TypeDesc> types;
    std::map<std::string, std::string> bytes, attributes;
    int width = 0, height = 0;

    // Channel `name` as floats.
    std::vector<float> Values(const std::string &name) const {
        const std::string &raw = bytes.at(name);
        OIIO::TypeDesc type = types.at(name);
        std::vector<float> values(raw.size() / type.size());
        for (size_t i = 0; i < values.size(); ++i)
            OIIO::convert_pixel_values(type, raw.data() + i * type.size(), OIIO::TypeFloat,
                                       &values[i]);
        return values;
    }
};

// Channel names as a set: OpenEXR stores them sorted, whatever order they were given in.
std::vector<std::string> Sorted(std::vector<std::string> names) {
    std::sort(names.begin(), names.end());
    return names;
}

Stored ReadStored(const std::string &path) {
    Stored s;
    std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(path);
    if (!in) throw Error("cannot open " + path);
    const OIIO::ImageSpec &spec = in->spec();
    s.names = spec.channelnames;
    s.width = spec.width, s.height = spec.height;
    std::vector<unsigned char> pixels(spec.image_bytes(true));
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeUnknown, pixels.data()))
        throw Error(in->geterror());
    size_t pixel = spec.pixel_bytes(true), offset = 0;
    for (int c = 0; c < spec.nchannels; ++c) {
        size_t size = spec.channelformat(c).size();
        std::string &raw = s.bytes[s.names[c]];
        for (size_t p = 0; p < size_t(spec.width) * spec.height; ++p)
            raw.append(reinterpret_cast<const char *>(pixels.data() + p * pixel + offset),
                       size);
        s.types[s.names[c]] = spec.channelformat(c);
        offset += size;
    }
    for (const OIIO::ParamValue &a : spec.extra_attribs)
        s.attributes[a.name().string()] = a.get_string();
    return s;
}

class IoTestConventions : public ::testing::Test {
  protected:
    void SetUp() override {
        std::random_device random;
        dir =
            fs::temp_directory_path() / ("mcd_conventions_test_" + std::to_string(::getpid()) +
                                         "_" + std::to_string(random()));
        fs::create_directories(dir);
    }
    void TearDown() override {
        std::error_code ec;
        fs::remove_all(dir, ec);
    }
    std::string Path(const std::string &name) const { return (dir / name).string(); }

    // A file whose channels hold value(name, x, y), each of its pixel type (float unless
    // listed), with header attributes; tiled when tileSize > 0.
    void Write(const std::string &path, int width, int height,
               const std::vector<std::string> &channels,
               const std::function<float(const std::string &, int, int)> &value,
               const std::map<std::string, OIIO::TypeDesc> &types = {},
               const std::vector<OIIO::ParamValue> &attributes = {}, int tileSize = 0) {
        int n = int(channels.size());
        OIIO::ImageSpec spec(width, height, n, OIIO::TypeFloat);
        spec.channelnames = channels;
        for (const std::string &name : channels)
            spec.channelformats.push_back(types.count(name) ? types.at(name) : OIIO::TypeFloat);
        if (tileSize) spec.tile_width = spec.tile_height = tileSize;
        for (const OIIO::ParamValue &a : attributes) spec.extra_attribs.push_back(a);
        std::vector<float> pixels(size_t(width) * height * n);
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x)
                for (int c = 0; c < n; ++c)
                    pixels[(size_t(y) * width + x) * n + c] = value(channels[c], x, y);
        auto out = OIIO::ImageOutput::create(path);
        ASSERT_TRUE(out && out->open(path, spec)) << OIIO::geterror();
        ASSERT_TRUE(out->write_image(OIIO::TypeFloat, pixels.data())) << out->geterror();
        ASSERT_TRUE(out->close());
    }

    fs::path dir;
};

// Pixels of a fully transparent pixel (alpha 0) and whether a frame's pixel is one.
std::vector<size_t> TransparentPixels(const Frame &frame) {
    std::vector<size_t> pixels;
    const Image &alpha = frame.Get("alpha");
    for (size_t i = 0; i < alpha.PixelCount(); ++i)
        if (alpha.data[i] == 0.f) pixels.push_back(i);
    return pixels;
}

// Blender 3.4 with Film > Transparent (scripts/blender/transparent_film.py): Combined.A is 0
// on the background and Combined holds none of the world there, though the Env pass does.
// Env is left out of direct, so that direct + indirect = color and indirect is not negative;
// alpha is Combined.A.
TEST_F(IoTestConventions, CyclesTransparentFilmLeavesEnvOutAndCarriesAlpha) {
    Frame frame = ReadFrame(kTransparent);
    Stored stored = ReadStored(kTransparent);
    ASSERT_TRUE(frame.Has("alpha"));
    EXPECT_EQ(frame.Get("alpha").data, stored.Values("ViewLayer.Combined.A"));
    std::vector<size_t> background = TransparentPixels(frame);
    // The fixture is mostly background, with the world visible in Env there.
    ASSERT_GT(background.size(), frame.Get("alpha").PixelCount() / 4);
    const Image &env = frame.Get("Env"), &color = frame.Get("color");
    EXPECT_GT(env.At(2, 0, 0), 0.5f);

    const Image &direct = frame.Get("direct"), &indirect = frame.Get("indirect");
    double gap = 0, total = 0, indirectSum = 0;
    for (size_t i = 0; i < color.Size(); ++i) {
        gap += std::abs(color.data[i] - direct.data[i] - indirect.data[i]);
        total += std::abs(color.data[i]);
        indirectSum += indirect.data[i];
        EXPECT_GE(indirect.data[i], -1e-5f) << i;
    }
    EXPECT_LT(gap, 1e-5 * total);
    EXPECT_GT(indirectSum, 0);
    for (size_t i : background)
        for (int c = 0; c < 3; ++c) {
            EXPECT_EQ(color.Plane(c)[i], 0.f);
            EXPECT_NEAR(direct.Plane(c)[i], 0.f, 1e-6f);
        }
    const std::string &line = frame.metadata[kConventionKey];
    EXPECT_TRUE(Contains(line, "alpha from Combined.A"));
    EXPECT_TRUE(Contains(line,
                         "(Diff, Gloss, Trans, Emit, VolumeDir, VolumeInd; not Env: the "
                         "film is transparent"));
    EXPECT_FALSE(Contains(line, "the rest goes to indirect"));

    // Reading only the split brings alpha along, so the composition is the same.
    Frame split = ReadFrame(kTransparent, {{"color", "direct", "indirect"}});
    EXPECT_EQ(split.Get("direct").data, direct.data);
    EXPECT_EQ(split.Get("indirect").data, indirect.data);
}

// The rule on hand-made passes: where alpha < 1 shows the world, Combined without Env is
// the transparent film's; with alpha 1 everywhere the same passes keep Env in direct.
TEST_F(IoTestConventions, EnvIsInDirectOnlyOnOpaqueFilm) {
    std::vector<std::string> channels;
    for (std::string pass : {"Combined", "DiffDir", "DiffInd", "DiffCol", "Env"})
        for (const char *c : {"R", "G", "B", "A"})
            if (pass == "Combined" || std::string(c) != "A")
                channels.push_back("ViewLayer." + pass + "." + c);
    auto scene = [](bool transparent) {
        return [transparent](const std::string &name, int x, int y) {
            bool sky = x == 0;  // the first column shows the world only
            float dir = sky ? 0.f : 0.5f + 0.1f * y, ind = sky ? 0.f : 0.25f,
                  col = sky ? 0.f : 0.8f, env = sky ? 0.4f : 0.f;
            if (name.ends_with(".A")) return transparent && sky ? 0.f : 1.f;
            if (name.find("DiffDir") != std::string::npos) return dir;
            if (name.find("DiffInd") != std::string::npos) return ind;
            if (name.find("DiffCol") != std::string::npos) return col;
            if (name.find("Env") != std::string::npos) return env;
            return (dir + ind) * col + (transparent ? 0.f : env);  // Combined
        };
    };
    for (bool transparent : {true, false}) {
        std::string path = Path(transparent ? "transparent.exr" : "opaque.exr");
        Write(path, 3, 2, channels, scene(transparent));
        Frame frame = ReadFrame(path);
        const Image &direct = frame.Get("direct"), &indirect = frame.Get("indirect");
        for (int y = 0; y < 2; ++y)
            for (int x = 0; x < 3; ++x)
                for (int c = 0; c < 3; ++c) {
                    float want = x == 0 ? (transparent ? 0.f : 0.4f) : (0.5f + 0.1f * y) * 0.8f;
                    EXPECT_NEAR(direct.At(c, y, x), want, 1e-6f) << transparent << x << y;
                    EXPECT_NEAR(indirect.At(c, y, x), x == 0 ? 0.f : 0.2f, 1e-6f);
                }
        EXPECT_EQ(Contains(frame.metadata[kConventionKey], "not Env"), bool(transparent));
        EXPECT_FALSE(Contains(frame.metadata[kConventionKey], "the rest goes to indirect"));
    }
}

// The alpha of a colour pass: an unprefixed A first, then Noisy Image's, then Combined's;
// A inside another known layer (albedo.A) is still not alpha.
TEST_F(IoTestConventions, AlphaComesFromTheColourPass) {
    auto value = [](const std::string &name, int x, int) {
        float base = name.find("Noisy") != std::string::npos      ? 10.f
                     : name.find("Combined") != std::string::npos ? 20.f
                     : name.find("albedo") != std::string::npos   ? 30.f
                                                                  : 40.f;
        return base + (name.ends_with("A") ? 1.f : 0.f) + 0.125f * x;
    };
    auto alphaOf = [&](const std::vector<std::string> &channels) {
        std::string path = Path("alpha.exr");
        Write(path, 2, 1, channels, value);
        Frame frame = ReadFrame(path);
        return frame.Has("alpha") ? frame.Get("alpha").At(0, 0, 0) : -1.f;
    };
    std::vector<std::string> combined = {"V.Combined.R", "V.Combined.G", "V.Combined.B",
                                         "V.Combined.A"};
    std::vector<std::string> noisy = {"V.Noisy Image.R", "V.Noisy Image.G", "V.Noisy Image.B",
                                      "V.Noisy Image.A"};
    EXPECT_EQ(alphaOf(combined), 21.f);
    std::vector<std::string> both = combined;
    both.insert(both.end(), noisy.begin(), noisy.end());
    EXPECT_EQ(alphaOf(both), 11.f);
    std::vector<std::string> plain = {"R", "G", "B", "A"};
    plain.insert(plain.end(), combined.begin(), combined.end());
    EXPECT_EQ(alphaOf(plain), 41.f);
    EXPECT_EQ(alphaOf({"R", "G", "B", "albedo.R", "albedo.G", "albedo.B", "albedo.A"}), -1.f);
}

// --overwrite-input on a Cycles frame: every channel under its own name and bits, the
// denoised colour in Combined, the noisy one added as Noisy Image (with Combined's alpha),
// the header kept. Read back, the colour is the noisy one again and alpha is unchanged;
// a second write adds nothing and leaves Noisy Image alone.
TEST_F(IoTestConventions, DenoisedOverACyclesFrameKeepsItsChannelNames) {
    std::string path = Path("cycles.exr");
    fs::copy_file(kTransparent, path);
    Stored before = ReadStored(path);
    Frame frame = ReadFrame(path);
    Image denoised(frame.width, frame.height, 3);
    for (size_t i = 0; i < denoised.Size(); ++i) denoised.data[i] = 0.001f * float(i);
    WriteDenoisedOver(path, denoised, {{"mcd:method", "test"}});

    Stored after = ReadStored(path);
    std::vector<std::string> want = before.names;
    for (const char *c : {"R", "G", "B", "A"})
        want.push_back(std::string("ViewLayer.Noisy Image.") + c);
    EXPECT_EQ(Sorted(after.names), Sorted(want));
    for (const std::string &name : before.names) {
        EXPECT_EQ(after.types[name], before.types[name]) << name;
        bool replaced = name == "ViewLayer.Combined.R" || name == "ViewLayer.Combined.G" ||
                        name == "ViewLayer.Combined.B";
        if (!replaced) {
            EXPECT_EQ(after.bytes[name], before.bytes[name]) << name;
        }
    }
    for (int c = 0; c < 3; ++c) {
        std::string name = std::string("ViewLayer.Combined.") + "RGB"[c];
        std::vector<float> plane(denoised.Plane(c), denoised.Plane(c) + denoised.PixelCount());
        EXPECT_EQ(after.Values(name), plane) << name;
        EXPECT_EQ(after.bytes[std::string("ViewLayer.Noisy Image.") + "RGB"[c]],
                  before.bytes[name]);
    }
    EXPECT_EQ(after.bytes["ViewLayer.Noisy Image.A"], before.bytes["ViewLayer.Combined.A"]);
    EXPECT_EQ(after.attributes["cycles.ViewLayer.samples"], "16");
    EXPECT_EQ(after.attributes["BlenderMultiChannel"],
              before.attributes["BlenderMultiChannel"]);
    EXPECT_EQ(after.attributes["mcd:method"], "test");

    Frame back = ReadFrame(path);
    EXPECT_EQ(back.Get("color").data, frame.Get("color").data);
    EXPECT_EQ(back.Get("alpha").data, frame.Get("alpha").data);
    EXPECT_TRUE(Contains(back.metadata[kConventionKey], "color from Noisy Image"));

    for (float &v : denoised.data) v += 1.f;
    WriteDenoisedOver(path, denoised, {});
    Stored again = ReadStored(path);
    EXPECT_EQ(Sorted(again.names), Sorted(want));
    for (const char *c : {"R", "G", "B", "A"})
        EXPECT_EQ(again.bytes[std::string("ViewLayer.Noisy Image.") + c],
                  after.bytes[std::string("ViewLayer.Noisy Image.") + c]);
    std::vector<float> red(denoised.Plane(0), denoised.Plane(0) + denoised.PixelCount());
    EXPECT_EQ(again.Values("ViewLayer.Combined.R"), red);
}

// Our names and other renderers' (pbrt-v4's P.*, which no layer reads; half channels, a
// 32-bit id; a tiled file): every channel kept under its name and type, bit for bit; the
// colour replaced in its own type; color.noisy added once, in the colour's type.
TEST_F(IoTestConventions, DenoisedOverOtherFramesKeepsEveryChannel) {
    std::vector<std::string> channels = {
        "R",   "G",   "B",   "A",          "Albedo.R",   "Albedo.G",   "Albedo.B",
        "P.X", "P.Y", "P.Z", "Variance.R", "Variance.G", "Variance.B", "id"};
    std::map<std::string, OIIO::TypeDesc> types = {{"R", OIIO::TypeHalf},
                                                   {"G", OIIO::TypeHalf},
                                                   {"B", OIIO::TypeHalf},
                                                   {"P.X", OIIO::TypeHalf},
                                                   {"id", OIIO::TypeUInt}};
    auto value = [](const std::string &name, int x, int y) {
        if (name == "id") return float(x + 3 * y) / 4294967295.f;  // OIIO normalises uint
        return 0.25f * float(name.size()) + 0.5f * float(x) + 0.0625f * float(y);
    };
    // Scanlines, tiles, and DWAA, which would lose more bits when written again.
    for (int variant : {0, 1, 2}) {
        int tile = variant == 1 ? 16 : 0;
        std::string path = Path(fmt::format("variant{}.exr", variant));
        Write(path, 19, 37, channels, value, types,
              {OIIO::ParamValue("samplesPerPixel", 16), OIIO::ParamValue("renderer", "pbrt"),
               OIIO::ParamValue("compression", variant == 2 ? "dwaa" : "zip")},
              tile);
        Stored before = ReadStored(path);
        Image denoised(19, 37, 3);
        for (size_t i = 0; i < denoised.Size(); ++i) denoised.data[i] = 0.5f + float(i % 7);
        WriteDenoisedOver(path, denoised, {{"mcd:method", "test"}});
        Stored after = ReadStored(path);

        std::vector<std::string> want = channels;
        for (const char *c : {"R", "G", "B"}) want.push_back(std::string("color.noisy.") + c);
        EXPECT_EQ(Sorted(after.names), Sorted(want)) << variant;
        for (const std::string &name : channels) {
            EXPECT_EQ(after.types[name], before.types[name]) << name;
            if (name.size() > 1) {
                EXPECT_EQ(after.bytes[name], before.bytes[name]) << name;
            }
        }
        for (int c = 0; c < 3; ++c) {
            std::string name(1, "RGB"[c]);
            EXPECT_EQ(after.types["color.noisy." + name], OIIO::TypeHalf);
            EXPECT_EQ(after.bytes["color.noisy." + name], before.bytes[name]);
            std::vector<float> plane(denoised.Plane(c), denoised.Plane(c) + 19 * 37);
            EXPECT_EQ(after.Values(name), plane) << name;  // exact in half
        }
        EXPECT_EQ(after.attributes["samplesPerPixel"], "16");
        EXPECT_EQ(after.attributes["renderer"], "pbrt");
        EXPECT_EQ(after.attributes["mcd:method"], "test");
        EXPECT_EQ(after.attributes["compression"],
                  variant == 2 ? "zip" : before.attributes["compression"]);

        // A second write keeps the first's noisy colour.
        WriteDenoisedOver(path, denoised, {});
        Stored again = ReadStored(path);
        EXPECT_EQ(Sorted(again.names), Sorted(want));
        EXPECT_EQ(again.bytes["color.noisy.G"], before.bytes["G"]);
    }
}

// A file it cannot write into is refused, named, and left as it was with nothing beside it.
TEST_F(IoTestConventions, DenoisedOverRefusesWhatItCannotKeep) {
    std::string exr = Path("small.exr"), png = Path("p.png");
    Write(exr, 4, 3, {"R", "G", "B"}, [](const std::string &, int x, int) { return float(x); });
    WritePng(png, Image(4, 3, 3, 0.5f));
    std::string exrBytes = ReadBytes(exr), pngBytes = ReadBytes(png);
    auto error = [](const std::function<void()> &f) {
        try {
            f();
        } catch (const Error &e) {
            return std::string(e.what());
        }
        return std::string("<no error>");
    };
    EXPECT_TRUE(Contains(error([&] { WriteDenoisedOver(exr, Image(5, 3, 3), {}); }),
                         "the image is 5x3x3, the frame's colour 4x3x3"));
    EXPECT_TRUE(Contains(error([&] { WriteDenoisedOver(png, Image(4, 3, 3), {}); }),
                         "it is not an OpenEXR file"));
    std::string none = Path("none.exr");
    Write(none, 2, 2, {"albedo.R", "albedo.G", "albedo.B"},
          [](const std::string &, int, int) { return 1.f; });
    EXPECT_TRUE(Contains(error([&] { WriteDenoisedOver(none, Image(2, 2, 3), {}); }),
                         "has no colour channels"));
    EXPECT_EQ(ReadBytes(exr), exrBytes);
    EXPECT_EQ(ReadBytes(png), pngBytes);
    std::vector<std::string> files;
    for (const auto &entry : fs::directory_iterator(dir))
        files.push_back(entry.path().filename().string());
    std::sort(files.begin(), files.end());
    EXPECT_EQ(files, (std::vector<std::string>{"none.exr", "p.png", "small.exr"}));
}

// A missing layer's hint is for the renderer that wrote the frame: Blender's pass, pbrt-v4's
// film, Mitsuba 3's integrator, our renderer's --layers, or accumulate for statistics.
TEST_F(IoTestConventions, MissingLayersSayWhatTheRendererEnables) {
    Frame cycles = ReadFrame(kTransparent, {{"color"}});
    EXPECT_EQ(RendererOf(cycles), Renderer::Blender);
    std::string rhf = Method("rhf").Missing(cycles);
    EXPECT_TRUE(Contains(rhf,
                         "no histogram channels (Bin_0000..) (Blender Cycles writes no "
                         "sample statistics"));
    EXPECT_TRUE(Contains(rhf, "`mcdenoise accumulate`"));
    EXPECT_FALSE(Contains(rhf, "--layers"));
    EXPECT_TRUE(Contains(Method("awr").Missing(cycles), "Blender Cycles writes no sample"));
    Frame bare = cycles;
    bare.layers.erase("albedo");
    EXPECT_TRUE(Contains(Method("pivot").Missing(bare),
                         "no pivot or albedo layer (in Blender, enable View Layer Properties "
                         "> Passes > Data > Denoising Data"));
    EXPECT_TRUE(Contains(HowToGet(cycles, "direct"), "Passes > Light: Diffuse, Glossy"));
    EXPECT_TRUE(Contains(HowToGet(cycles, "objectId"), "Object Index"));

    Frame ours;
    ours.metadata["mcd:renderer"] = "mcdenoise path tracer 3";
    EXPECT_EQ(RendererOf(ours), Renderer::Ours);
    EXPECT_TRUE(Contains(Method("rhf").Missing(ours), "`mcdenoise render --layers hist`"));
    EXPECT_TRUE(Contains(Method("pivot").Missing(ours), "--layers pivot"));
    EXPECT_TRUE(Contains(Method("pivot").Missing(ours), "--layers gbuffer"));

    Frame pbrt;
    pbrt.metadata[kConventionKey] = "read as pbrt-v4 GBufferFilm: NO variance layer";
    EXPECT_TRUE(Contains(Method("awr").Missing(pbrt), "pbrt-v4's gbuffer film"));
    EXPECT_TRUE(Contains(Method("rhf").Missing(pbrt), "`mcdenoise accumulate`"));
    Frame mitsuba;
    mitsuba.metadata[kConventionKey] = "read as Mitsuba 3 aov";
    EXPECT_TRUE(Contains(Method("pivot").Missing(mitsuba), "aov integrator"));
    EXPECT_TRUE(Contains(Method("awr").Missing(mitsuba), "moment integrator"));

    // A renderer nothing says: statistics from accumulate; zhist only from ours.
    Frame unknown;
    EXPECT_EQ(RendererOf(unknown), Renderer::Unknown);
    EXPECT_TRUE(Contains(Method("rhf").Missing(unknown), "`mcdenoise accumulate`"));
    EXPECT_TRUE(Contains(HowToGet(unknown, "zhist"), "mcdenoise render --layers zhist"));
    // Each hint once, however many layers share it.
    std::string both = Lacks(cycles, "no statistics", {"variance", "min", "max", "spp"});
    EXPECT_EQ(both.find("accumulate"), both.rfind("accumulate"));
    EXPECT_EQ(Lacks(cycles, "no mystery", {"mystery"}), "no mystery");
}

}  // namespace
}  // namespace mcd::io
