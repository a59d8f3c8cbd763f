// WriteExr, WritePng and WriteDenoisedOver, all written to a temporary file that is renamed
// over the target.
#include <Imath/ImathBox.h>
#include <Imath/half.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfThreading.h>
#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <set>
#include <system_error>
#include <thread>

#include "host/error.h"
#include "host/io/frame.h"
#include "host/io/image_file.h"
#include "host/io/layer_names.h"

namespace mcd {
using namespace io;

namespace {

namespace fs = std::filesystem;

// Rows copied at a time: bounded memory for histogram frames.
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

// Write a file with `write` into a hidden temporary file beside path
// (".name.tmp<pid>-<n>.ext": same file system, so the rename is atomic), then rename it over
// path. Readers see the old file or the new one, never a part of one; on any failure (write
// throws) the temporary file is removed and the old file left as it was.
// A path that is a symbolic link is written through: the file it leads to is replaced (the
// link stays a link), and an existing file keeps its permission bits.
void WriteAtomically(const std::string &path,
                     const std::function<void(const std::string &temp)> &write) {
    static std::atomic<int> tempCount{0};
    std::error_code ec;
    fs::path target(path);
    if (fs::is_symlink(target, ec)) {
        fs::path resolved = fs::weakly_canonical(target, ec);
        if (ec)
            throw Error(fmt::format("cannot write '{}': the link leads nowhere readable: {}",
                                    path, ec.message()),
                        ErrorKind::Io);
        target = resolved;
    }
    fs::path dir = target.parent_path();
    if (dir.empty()) dir = ".";
    if (!fs::is_directory(dir, ec))
        throw Error(fmt::format("cannot write '{}': '{}' is not an existing directory", path,
                                dir.string()),
                    ErrorKind::Io);
    if (!target.has_filename())
        throw Error(fmt::format("cannot write '{}': it names no file", path),
                    ErrorKind::InvalidArgument);

    TempFile temp(dir / fmt::format(".{}.tmp{}-{}{}", target.stem().string(), ::getpid(),
                                    tempCount++, target.extension().string()));
    write(temp.Path().string());
    if (!SyncFile(temp.Path()))
        throw Error(
            fmt::format("cannot write '{}': flushing '{}' failed", path, temp.Path().string()),
            ErrorKind::Io);

    if (fs::file_status old = fs::status(target, ec); !ec && fs::is_regular_file(old)) {
        fs::permissions(temp.Path(), old.permissions(), ec);
        if (ec)
            throw Error(fmt::format("cannot write '{}': keeping its permissions failed: {}",
                                    path, ec.message()),
                        ErrorKind::Io);
    }
    fs::rename(temp.Path(), target, ec);
    if (ec)
        throw Error(fmt::format("cannot write '{}': renaming '{}' onto it failed: {}", path,
                                temp.Path().string(), ec.message()),
                    ErrorKind::Io);
    temp.Commit();
}

// OpenEXR compresses on every core, as OpenImageIO had it do.
void UseAllCores() {
    static std::once_flag threads;
    std::call_once(threads, [] {
        Imf::setGlobalThreadCount(int(std::max(1u, std::thread::hardware_concurrency())));
    });
}

// Set string attributes by OpenImageIO's names (as ReadFrame reports them) on an EXR
// header; the file's layout is not metadata's to change.
void SetStringAttributes(Imf::Header &header,
                         const std::map<std::string, std::string> &metadata) {
    for (const auto &[key, value] : metadata) {
        std::string name = ExrAttributeName(key);
        if (key.starts_with("oiio:") || IsLayoutAttribute(name)) continue;
        // An attribute of another type under that name stays as it is.
        if (auto old = header.find(name);
            old != header.end() &&
            !dynamic_cast<const Imf::StringAttribute *>(&old.attribute()))
            continue;
        header.insert(name, Imf::StringAttribute(value));
    }
    // The time of writing where none is given, as OpenImageIO wrote it before.
    if (header.find("capDate") == header.end()) {
        std::time_t now = std::time(nullptr);
        std::tm local{};
        char text[32] = {};
        if (localtime_r(&now, &local) &&
            std::strftime(text, sizeof text, "%Y:%m:%d %H:%M:%S", &local))
            header.insert("capDate", Imf::StringAttribute(text));
    }
}

// The windows the metadata states (ReadFrame's, of the frame the layers come from) on a
// header of the layers' size: the data window moved to its origin, the display window as
// it was. Windows of another size are not these layers' and are left out.
void SetWindows(Imf::Header &header, const std::map<std::string, std::string> &metadata) {
    auto data = metadata.find(kDataWindowKey), display = metadata.find(kDisplayWindowKey);
    int x, y, w, h, fx, fy, fw, fh;
    Imath::Box2i &window = header.dataWindow();
    if (data == metadata.end() || display == metadata.end() ||
        !ParseWindow(data->second, &x, &y, &w, &h) ||
        !ParseWindow(display->second, &fx, &fy, &fw, &fh) ||
        w != window.max.x - window.min.x + 1 || h != window.max.y - window.min.y + 1)
        return;
    window = Imath::Box2i({x, y}, {x + w - 1, y + h - 1});
    header.displayWindow() = Imath::Box2i({fx, fy}, {fx + fw - 1, fy + fh - 1});
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

// Where WriteDenoisedOver puts the colours among a file's channels.
struct OverwriteTargets {
    std::vector<int> denoised;            // the channels the result replaces, layer order
    std::vector<std::string> noisyNames;  // the channels added, each a copy of
    std::vector<int> noisyFrom;           // this channel of the file
};

// The channel named `name`, or -1.
int ChannelIndex(const std::vector<std::string> &names, const std::string &name) {
    auto it = std::find(names.begin(), names.end(), name);
    return it == names.end() ? -1 : int(it - names.begin());
}

// The colour a method reads (GroupChannels' "color") and, on a Blender frame, Cycles'
// layout: the denoised image in Combined, the noisy one in Noisy Image, as Cycles' own
// denoiser leaves them. Other frames: the colour's channels, the noisy one beside it under
// kNoisyColorLayer.
OverwriteTargets FindTargets(const std::vector<std::string> &names, const std::string &path) {
    std::vector<int> color;
    for (const LayerChannels &layer : GroupChannels(names))
        if (layer.name == "color") color = layer.channels;
    if (color.empty())
        throw Error(ErrorKind::MissingLayer, fmt::format("'{}' has no colour channels", path));

    OverwriteTargets t;
    const std::string &first = names[color.front()];
    std::string prefix = first.substr(0, first.rfind('.') + 1);  // "" when unprefixed
    auto endsWith = [&](const std::string &pass) {
        return prefix == pass + "." || prefix.ends_with("." + pass + ".");
    };
    if (endsWith("Noisy Image") || endsWith("Combined")) {
        bool noisy = endsWith("Noisy Image");
        std::string viewLayer =
            prefix.substr(0, prefix.size() - (noisy ? 12 : 9));  // "<view layer>."
        for (const char *c : {"R", "G", "B"}) {
            int combined = ChannelIndex(names, viewLayer + "Combined." + c);
            if (combined < 0)
                throw Error(ErrorKind::MissingLayer,
                            fmt::format("'{}' has no channel {}Combined.{} for the denoised "
                                        "colour",
                                        path, viewLayer, c));
            t.denoised.push_back(combined);
            if (!noisy) {
                t.noisyNames.push_back(viewLayer + "Noisy Image." + c);
                t.noisyFrom.push_back(combined);
            }
        }
        if (int alpha = ChannelIndex(names, viewLayer + "Combined.A"); !noisy && alpha >= 0)
            t.noisyNames.push_back(viewLayer + "Noisy Image.A"), t.noisyFrom.push_back(alpha);
        return t;
    }
    t.denoised = color;
    std::vector<std::string> noisy = ChannelNamesOf(kNoisyColorLayer, int(color.size()));
    bool present = std::all_of(noisy.begin(), noisy.end(), [&](const std::string &n) {
        return ChannelIndex(names, n) >= 0;
    });
    if (!present) t.noisyNames = noisy, t.noisyFrom = color;
    return t;
}

// The file's header as written back: its channels, their types and its attributes,
// increasing scanlines, the added channels (each of the type of the one it copies), lossless,
// `metadata` on top.
Imf::Header OverwriteHeader(const Imf::Header &in, const std::vector<std::string> &names,
                            const OverwriteTargets &t,
                            const std::map<std::string, std::string> &metadata) {
    Imf::Header header = in;
    for (const char *layout : {"tiles", "type", "chunkCount", "name", "version"})
        if (header.find(layout) != header.end()) header.erase(layout);
    for (size_t k = 0; k < t.noisyNames.size(); ++k)
        header.channels().insert(t.noisyNames[k], in.channels()[names[t.noisyFrom[k]]]);
    // Lossy compression (DWA, B44) would change the kept channels' bits once more.
    Imf::Compression compression = header.compression();
    if (compression == Imf::DWAA_COMPRESSION || compression == Imf::DWAB_COMPRESSION ||
        compression == Imf::B44_COMPRESSION || compression == Imf::B44A_COMPRESSION)
        header.compression() = Imf::ZIP_COMPRESSION;
    // Bands are written top-down: a decreasing or random order would read them out of range.
    header.lineOrder() = Imf::INCREASING_Y;
    SetStringAttributes(header, metadata);
    return header;
}

size_t SampleBytes(Imf::PixelType type) {
    return type == Imf::HALF ? 2 : 4;
}

// Store a float as a sample of `type` (ids rounded, as ReadFrame reads them back).
void StoreSample(float v, Imf::PixelType type, char *dst) {
    if (type == Imf::HALF) {
        Imath::half h(v);
        std::memcpy(dst, &h, 2);
    } else if (type == Imf::FLOAT) {
        std::memcpy(dst, &v, 4);
    } else {
        double r = std::isfinite(v) ? std::clamp(std::round(double(v)), 0.0, 4294967295.0) : 0;
        uint32_t u = uint32_t(r);
        std::memcpy(dst, &u, 4);
    }
}

// A channel's samples for a band of rows.
struct BandSlice {
    std::string name;
    Imf::PixelType type;
    char *plane;
};

// A frame buffer over band planes whose first row is row `top` (absolute).
Imf::FrameBuffer BandBuffer(const std::vector<BandSlice> &slices, const Imath::Box2i &window,
                            int top) {
    Imf::FrameBuffer buffer;
    std::ptrdiff_t width = window.max.x - window.min.x + 1;
    for (const BandSlice &slice : slices) {
        std::ptrdiff_t bytes = std::ptrdiff_t(SampleBytes(slice.type)), row = bytes * width;
        // OpenEXR addresses pixel (x, y) at base + x xStride + y yStride.
        char *base = slice.plane - window.min.x * bytes - std::ptrdiff_t(top) * row;
        buffer.insert(slice.name, Imf::Slice(slice.type, base, size_t(bytes), size_t(row)));
    }
    return buffer;
}

}  // namespace

void io::WriteDenoisedOver(const std::string &path, const Image &denoised,
                           const std::map<std::string, std::string> &metadata) {
    auto fail = [&](const std::string &why) {
        return Error(ErrorKind::Io,
                     fmt::format("cannot write the denoised colour into '{}': {}", path, why));
    };
    std::error_code ec;
    if (!fs::exists(path, ec)) throw fail("no such file");
    if (!IsExrFile(path)) throw fail("it is not an OpenEXR file");
    ImageHeader inSpec;
    try {
        inSpec = ReadExrHeader(path);
    } catch (const Error &e) {
        throw fail(e.what());
    }
    if (inSpec.parts > 1)
        throw fail(
            fmt::format("it has {} parts, and only one-part files are written over "
                        "(write the result with -o instead)",
                        inSpec.parts));
    if (inSpec.deep) throw fail("deep and volume images are unsupported");
    OverwriteTargets t;
    try {
        t = FindTargets(inSpec.channelNames, path);
    } catch (const Error &e) {
        throw fail(e.what());
    }
    if (denoised.width != inSpec.width || denoised.height != inSpec.height ||
        denoised.channels != int(t.denoised.size()) || !Malformed(denoised).empty())
        throw fail(fmt::format("the image is {}x{}x{}, the frame's colour {}x{}x{}",
                               denoised.width, denoised.height, denoised.channels, inSpec.width,
                               inSpec.height, t.denoised.size()));

    // Native samples in and out: every channel kept bit for bit but those the result
    // replaces. One plane per channel a band high; the replaced channels are written from
    // planes of their own, the added ones from the planes of the channels they copy.
    UseAllCores();
    try {
        Imf::InputFile in(path.c_str());
        const Imf::Header &inHeader = in.header();
        const Imath::Box2i window = inHeader.dataWindow();
        const std::vector<std::string> &names = inSpec.channelNames;
        const int width = inSpec.width, count = int(names.size());
        std::vector<Imf::PixelType> types;
        for (const std::string &name : names) types.push_back(inHeader.channels()[name].type);
        Imf::Header header = OverwriteHeader(inHeader, names, t, metadata);

        // Planes a band high: one per channel read, one per replaced channel; the added
        // channels are written from the planes of the channels they copy.
        std::vector<std::vector<char>> planes(count), replaced(t.denoised.size());
        std::vector<BandSlice> read, written;
        for (int c = 0; c < count; ++c) {
            planes[c].resize(size_t(kBandRows) * width * SampleBytes(types[c]));
            read.push_back({names[c], types[c], planes[c].data()});
        }
        written = read;
        for (size_t k = 0; k < t.denoised.size(); ++k) {
            int c = t.denoised[k];
            replaced[k].resize(planes[c].size());
            written[c].plane = replaced[k].data();
        }
        for (size_t k = 0; k < t.noisyNames.size(); ++k)
            written.push_back(
                {t.noisyNames[k], types[t.noisyFrom[k]], planes[t.noisyFrom[k]].data()});

        WriteAtomically(path, [&](const std::string &temp) {
            Imf::OutputFile out(temp.c_str(), header);
            for (int y0 = 0; y0 < inSpec.height; y0 += kBandRows) {
                int y1 = std::min(inSpec.height, y0 + kBandRows);
                int top = window.min.y + y0;
                in.setFrameBuffer(BandBuffer(read, window, top));
                in.readPixels(top, window.min.y + y1 - 1);
                for (size_t k = 0; k < t.denoised.size(); ++k) {
                    Imf::PixelType type = types[t.denoised[k]];
                    size_t bytes = SampleBytes(type);
                    const float *src = denoised.Plane(int(k)) + size_t(y0) * width;
                    for (size_t p = 0; p < size_t(y1 - y0) * width; ++p)
                        StoreSample(src[p], type, replaced[k].data() + p * bytes);
                }
                out.setFrameBuffer(BandBuffer(written, window, top));
                out.writePixels(y1 - y0);
            }
        });
    } catch (const Error &) {
        throw;
    } catch (const std::exception &e) {
        throw fail(e.what());
    }
}

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
    Imf::Header header(width, height);
    SetWindows(header, metadata);
    header.compression() = Imf::ZIP_COMPRESSION;
    for (const std::string &name : channelNames)
        header.channels().insert(name, Imf::Channel(Imf::FLOAT));
    SetStringAttributes(header, metadata);

    // OpenEXR reads the planar layers as they are: no interleaved copy. It addresses pixel
    // (x, y) of the data window at base + x xStride + y yStride.
    const Imath::Box2i window = header.dataWindow();
    std::ptrdiff_t origin =
        std::ptrdiff_t(window.min.x) * std::ptrdiff_t(sizeof(float)) +
        std::ptrdiff_t(window.min.y) * std::ptrdiff_t(sizeof(float)) * width;
    Imf::FrameBuffer buffer;
    for (const auto &[name, image] : layers) {
        std::vector<std::string> names = ChannelNamesOf(name, image->channels);
        for (int c = 0; c < image->channels; ++c)
            buffer.insert(
                names[c],
                Imf::Slice(
                    Imf::FLOAT,
                    reinterpret_cast<char *>(const_cast<float *>(image->Plane(c))) - origin,
                    sizeof(float), sizeof(float) * size_t(width)));
    }
    UseAllCores();
    WriteAtomically(path, [&](const std::string &temp) {
        try {
            Imf::OutputFile out(temp.c_str(), header);
            out.setFrameBuffer(buffer);
            out.writePixels(height);
        } catch (const std::exception &e) {
            throw Error(fmt::format("cannot write '{}': {}", path, e.what()), ErrorKind::Io);
        }
    });
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

    // PNG through the OpenImageIO module, loaded at the first preview.
    WriteAtomically(path, [&](const std::string &temp) {
        // The color is stored as it is, not divided by alpha (ReadFrame reads it so too).
        WriteModuleUInt8(temp, path, "png", image.width, image.height, channels, pixels.data(),
                         alpha != nullptr);
    });
}

}  // namespace io

}  // namespace mcd
