// WriteExr and WritePng, both written to a temporary file that is renamed over the target.
#include <OpenImageIO/imageio.h>
#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <set>
#include <system_error>

#include "host/error.h"
#include "host/io/frame.h"
#include "host/io/layer_names.h"

namespace mcd {
using namespace io;

namespace {

namespace fs = std::filesystem;

// Rows interleaved and handed to OIIO at a time: bounded memory for histogram frames.
constexpr int kBandRows = 32;

// Removes the temporary file when the scope ends, unless the write was committed.
class TempFile {
  public:
    explicit TempFile(fs::path path) : path(std::move(path)) {}
    ~TempFile() {
        std::error_code ec;
        if (!committed) fs::remove(path, ec);
    }
    TempFile(const TempFile &) = delete;
    TempFile &operator=(const TempFile &) = delete;

    const fs::path &Path() const { return path; }
    void Commit() { committed = true; }

  private:
    fs::path path;
    bool committed = false;
};

// Flush the file's data to disk, so that after the rename a crash cannot leave an empty
// file where the old good one was.
bool SyncFile(const fs::path &path) {
    int fd = ::open(path.c_str(), O_RDONLY);
    if (fd < 0) return false;
    bool ok = ::fsync(fd) == 0;
    return ::close(fd) == 0 && ok;
}

// Write an image with the OIIO writer named format into a hidden temporary file beside
// path (".name.tmp<pid>-<n>.ext": same file system, so the rename is atomic), then rename
// it over path. Readers see the old file or the new one, never a part of one; on any
// failure the temporary file is removed and the old file left as it was.
void WriteAtomically(const std::string &path, const char *format, const OIIO::ImageSpec &spec,
                     const std::function<bool(OIIO::ImageOutput &)> &writePixels) {
    static std::atomic<int> tempCount{0};
    fs::path target(path);
    fs::path dir = target.parent_path();
    if (dir.empty()) dir = ".";
    std::error_code ec;
    if (!fs::is_directory(dir, ec))
        throw Error(fmt::format("cannot write '{}': '{}' is not an existing directory", path,
                                dir.string()),
                    ErrorKind::Io);
    if (!target.has_filename())
        throw Error(fmt::format("cannot write '{}': it names no file", path),
                    ErrorKind::InvalidArgument);

    TempFile temp(dir / fmt::format(".{}.tmp{}-{}{}", target.stem().string(), ::getpid(),
                                    tempCount++, target.extension().string()));
    std::unique_ptr<OIIO::ImageOutput> out = OIIO::ImageOutput::create(format);
    if (!out)
        throw Error(fmt::format("cannot write '{}': {}", path, OIIO::geterror()),
                    ErrorKind::Io);
    if (!out->open(temp.Path().string(), spec))
        throw Error(fmt::format("cannot write '{}': {}", path, out->geterror()), ErrorKind::Io);
    if (!writePixels(*out) || !out->close())
        throw Error(fmt::format("cannot write '{}': {}", path, out->geterror()), ErrorKind::Io);
    out.reset();
    if (!SyncFile(temp.Path()))
        throw Error(
            fmt::format("cannot write '{}': flushing '{}' failed", path, temp.Path().string()),
            ErrorKind::Io);

    fs::rename(temp.Path(), target, ec);
    if (ec)
        throw Error(fmt::format("cannot write '{}': renaming '{}' onto it failed: {}", path,
                                temp.Path().string(), ec.message()),
                    ErrorKind::Io);
    temp.Commit();
}

uint8_t EncodeSrgb8(float v) {
    v = std::clamp(v, 0.f, 1.f);
    v = v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.f / 2.4f) - 0.055f;
    return uint8_t(std::lround(v * 255.f));
}

// Check an image is a whole, non-empty one; returns why not, or "".
std::string Malformed(const Image &image) {
    if (image.width <= 0 || image.height <= 0 || image.channels <= 0)
        return fmt::format("is empty ({}x{}, {} channels)", image.width, image.height,
                           image.channels);
    if (image.data.size() != image.PixelCount() * size_t(image.channels))
        return fmt::format("holds {} values, not {}x{}x{}", image.data.size(), image.width,
                           image.height, image.channels);
    return "";
}

}  // namespace

void WriteExr(const std::string &path,
              const std::vector<std::pair<std::string, const Image *>> &layers,
              const std::map<std::string, std::string> &metadata) {
    // The layers given cannot be written: the caller's to fix.
    auto fail = [&](const std::string &why) {
        return Error(fmt::format("cannot write '{}': {}", path, why),
                     ErrorKind::InvalidArgument);
    };
    if (layers.empty()) throw fail("no layers given");

    // Check all layers before anything touches the disk.
    const auto &[firstName, first] = layers.front();
    std::set<std::string> layerNames, channelSet;
    std::vector<std::string> channelNames;
    for (const auto &[name, image] : layers) {
        if (!image) throw fail(fmt::format("layer '{}' is null", name));
        if (std::string why = Malformed(*image); !why.empty())
            throw fail(fmt::format("layer '{}' {}", name, why));
        if (image->width != first->width || image->height != first->height)
            throw fail(fmt::format("layer '{}' is {}x{} but layer '{}' is {}x{}", name,
                                   image->width, image->height, firstName, first->width,
                                   first->height));
        if (!layerNames.insert(name).second)
            throw fail(fmt::format("layer '{}' is given twice", name));
        std::vector<std::string> names;
        try {
            names = ChannelNamesOf(name, image->channels);
        } catch (const Error &e) {
            throw fail(e.what());
        }
        for (const std::string &channel : names)
            if (!channelSet.insert(channel).second)
                throw fail(fmt::format("channel '{}' would be written twice", channel));
        channelNames.insert(channelNames.end(), names.begin(), names.end());
    }

    int width = first->width, height = first->height;
    int channelCount = int(channelNames.size());
    OIIO::ImageSpec spec(width, height, channelCount, OIIO::TypeFloat);
    spec.channelnames = channelNames;
    for (const auto &[key, value] : metadata)
        if (key != "compression") spec.attribute(key, value);
    spec.attribute("compression", "zip");

    // Interleave a band of rows at a time from the planar layers.
    std::vector<const float *> planes;
    for (const auto &[name, image] : layers)
        for (int c = 0; c < image->channels; ++c) planes.push_back(image->Plane(c));
    auto writePixels = [&](OIIO::ImageOutput &out) {
        std::vector<float> band(size_t(kBandRows) * width * channelCount);
        for (int y0 = 0; y0 < height; y0 += kBandRows) {
            int y1 = std::min(height, y0 + kBandRows);
            for (int y = y0; y < y1; ++y)
                for (int c = 0; c < channelCount; ++c) {
                    const float *src = planes[c] + size_t(y) * width;
                    float *dst = band.data() + size_t(y - y0) * width * channelCount + c;
                    for (int x = 0; x < width; ++x) dst[size_t(x) * channelCount] = src[x];
                }
            if (!out.write_scanlines(y0, y1, 0, OIIO::TypeFloat, band.data())) return false;
        }
        return true;
    };
    WriteAtomically(path, "openexr", spec, writePixels);
}

void WritePng(const std::string &path, const Image &image, float exposure) {
    io::WritePngWithAlpha(path, image, nullptr, exposure);
}

namespace io {

void WritePngWithAlpha(const std::string &path, const Image &image, const Image *alpha,
                       float exposure) {
    if (std::string why = Malformed(image); !why.empty())
        throw Error(fmt::format("cannot write '{}': the image {}", path, why),
                    ErrorKind::InvalidArgument);
    if (image.channels != 1 && image.channels != 3)
        throw Error(fmt::format("cannot write '{}': a preview needs 1 or 3 channels, not {}",
                                path, image.channels),
                    ErrorKind::InvalidArgument);
    if (alpha && (alpha->width != image.width || alpha->height != image.height ||
                  alpha->channels != 1 || !Malformed(*alpha).empty()))
        throw Error(
            fmt::format("cannot write '{}': alpha is {}x{}x{}, not {}x{}x1", path, alpha->width,
                        alpha->height, alpha->channels, image.width, image.height),
            ErrorKind::InvalidArgument);

    // Always RGB, so that non-finite pixels can be magenta in a grey image too.
    int channels = alpha ? 4 : 3;
    std::vector<uint8_t> pixels(image.PixelCount() * channels);
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) {
            float v[3];
            bool finite = true;
            for (int c = 0; c < 3; ++c) {
                v[c] = image.At(image.channels == 1 ? 0 : c, y, x) * exposure;
                finite = finite && std::isfinite(v[c]);
            }
            uint8_t *p = pixels.data() + (size_t(y) * image.width + x) * channels;
            for (int c = 0; c < 3; ++c) p[c] = finite ? EncodeSrgb8(v[c]) : (c == 1 ? 0 : 255);
            // Alpha is coverage, not light: linear, not sRGB-encoded, and not exposed.
            if (alpha) {
                float a = alpha->At(0, y, x);
                p[3] = std::isfinite(a) ? uint8_t(std::lround(std::clamp(a, 0.f, 1.f) * 255.f))
                                        : 255;
            }
        }

    OIIO::ImageSpec spec(image.width, image.height, channels, OIIO::TypeUInt8);
    spec.attribute("oiio:ColorSpace", "sRGB");
    // The color is stored as it is, not divided by alpha (ReadFrame reads it so too).
    if (alpha) spec.attribute("oiio:UnassociatedAlpha", 1);
    WriteAtomically(path, "png", spec, [&](OIIO::ImageOutput &out) {
        return out.write_image(OIIO::TypeUInt8, pixels.data());
    });
}

}  // namespace io

}  // namespace mcd
