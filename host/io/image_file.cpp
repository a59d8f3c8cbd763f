#include "host/io/image_file.h"

#include <Imath/ImathBox.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfCompression.h>
#include <OpenEXR/ImfFloatAttribute.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfMultiPartInputFile.h>
#include <OpenEXR/ImfPartType.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <dlfcn.h>
#include <fmt/format.h>

#include <strings.h>
#include <algorithm>
#include <atomic>
#include <cctype>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <mutex>
#include <set>

#include "host/error.h"
#include "host/io/layer_names.h"

#ifndef MCD_INSTALL_LIBDIR
#define MCD_INSTALL_LIBDIR ""
#endif
#ifndef MCD_RELATIVE_LIBDIR
#define MCD_RELATIVE_LIBDIR ""
#endif

namespace mcd::io {

namespace {

constexpr const char *kModuleName = "libmcdenoise_oiio.so";

// EXR names OpenImageIO reports under its own ones.
constexpr std::pair<const char *, const char *> kRenamed[] = {
    {"capDate", "DateTime"},     {"comments", "ImageDescription"},
    {"owner", "Copyright"},      {"pixelAspectRatio", "PixelAspectRatio"},
    {"expTime", "ExposureTime"}, {"aperture", "FNumber"},
    {"xDensity", "XResolution"},
};

const char *CompressionName(Imf::Compression compression) {
    switch (compression) {
        case Imf::NO_COMPRESSION:
            return "none";
        case Imf::RLE_COMPRESSION:
            return "rle";
        case Imf::ZIPS_COMPRESSION:
            return "zips";
        case Imf::ZIP_COMPRESSION:
            return "zip";
        case Imf::PIZ_COMPRESSION:
            return "piz";
        case Imf::PXR24_COMPRESSION:
            return "pxr24";
        case Imf::B44_COMPRESSION:
            return "b44";
        case Imf::B44A_COMPRESSION:
            return "b44a";
        case Imf::DWAA_COMPRESSION:
            return "dwaa";
        case Imf::DWAB_COMPRESSION:
            return "dwab";
        default:
            return "unknown";
    }
}

SampleType TypeOf(const std::string &name) {
    if (name == "uint8") return SampleType::UInt8;
    if (name == "uint16") return SampleType::UInt16;
    if (name == "uint32") return SampleType::UInt32;
    if (name == "half") return SampleType::Half;
    if (name == "float") return SampleType::Float;
    if (name == "double") return SampleType::Double;
    return SampleType::Other;
}

std::atomic<bool> moduleLoaded{false};

}  // namespace

bool IsLayoutAttribute(const std::string &name) {
    for (const char *layout : {"channels", "compression", "dataWindow", "displayWindow",
                               "lineOrder", "tiles", "type", "name", "version", "chunkCount"})
        if (name == layout) return true;
    return false;
}

std::string OiioAttributeName(const std::string &exrName) {
    for (const auto &[exr, oiio] : kRenamed)
        if (exrName == exr) return oiio;
    return exrName;
}

std::string ExrAttributeName(const std::string &oiioName) {
    for (const auto &[exr, oiio] : kRenamed)
        if (oiioName == oiio) return exr;
    return oiioName;
}

std::vector<int> OiioChannelOrder(const std::vector<std::string> &names) {
    // OpenImageIO sorts by layer ("" first), then the channels with special names in this
    // order (any case), then the others as stored; a layer with X and Y or Z has X, Y, Z
    // right after the colours.
    static const char *const special[] = {"R",    "Red",  "G",  "Green", "B",     "Blue", "Y",
                                          "real", "imag", "A",  "Alpha", "AR",    "RA",   "AG",
                                          "GA",   "AB",   "BA", "Z",     "Depth", "Zback"};
    constexpr int kBlue = 5, kOther = 1000;
    auto split = [](const std::string &name) {
        size_t dot = name.rfind('.');
        if (dot == std::string::npos) return std::pair<std::string, std::string>{"", name};
        return std::pair{name.substr(0, dot + 1), name.substr(dot + 1)};
    };
    std::map<std::string, std::set<char>> axes;  // layer -> which of x, y, z it has
    for (const std::string &name : names) {
        auto [layer, suffix] = split(name);
        if (suffix.size() == 1 && std::strchr("xyzXYZ", suffix[0]))
            axes[layer].insert(char(std::tolower((unsigned char)suffix[0])));
    }
    struct Key {
        std::string layer;
        int rank;
        int index;
    };
    std::vector<Key> keys;
    for (int i = 0; i < int(names.size()); ++i) {
        auto [layer, suffix] = split(names[i]);
        int rank = kOther;
        const std::set<char> &has = axes[layer];
        bool xyz = has.count('x') && (has.count('y') || has.count('z'));
        if (xyz && suffix.size() == 1 && std::strchr("xyzXYZ", suffix[0])) {
            rank = 10 * kBlue + 1 + (std::tolower((unsigned char)suffix[0]) - 'x');
        } else {
            for (int s = 0; s < int(std::size(special)); ++s)
                if (strcasecmp(suffix.c_str(), special[s]) == 0) {
                    rank = 10 * s;
                    break;
                }
        }
        keys.push_back({layer, rank, i});
    }
    std::sort(keys.begin(), keys.end(), [](const Key &a, const Key &b) {
        if (a.layer != b.layer) return a.layer < b.layer;
        if (a.rank != b.rank) return a.rank < b.rank;
        return a.index < b.index;
    });
    std::vector<int> order;
    for (const Key &key : keys) order.push_back(key.index);
    return order;
}

bool IsExrFile(const std::string &path) {
    FILE *file = std::fopen(path.c_str(), "rb");
    if (!file) return false;
    unsigned char magic[4] = {};
    bool exr = std::fread(magic, 1, 4, file) == 4 && magic[0] == 0x76 && magic[1] == 0x2f &&
               magic[2] == 0x31 && magic[3] == 0x01;
    std::fclose(file);
    return exr;
}

std::string WindowText(int x, int y, int width, int height) {
    return fmt::format("{} {} {} {}", x, y, x + width - 1, y + height - 1);
}

bool ParseWindow(const std::string &text, int *x, int *y, int *width, int *height) {
    long v[4];
    char tail;
    if (std::sscanf(text.c_str(), "%ld %ld %ld %ld %c", &v[0], &v[1], &v[2], &v[3], &tail) != 4)
        return false;
    for (long value : v)
        if (value < INT_MIN / 2 || value > INT_MAX / 2) return false;
    if (v[2] < v[0] || v[3] < v[1]) return false;
    *x = int(v[0]), *y = int(v[1]);
    *width = int(v[2] - v[0] + 1), *height = int(v[3] - v[1] + 1);
    return true;
}

void AddWindows(const ImageHeader &h, std::map<std::string, std::string> &metadata) {
    if (!h.exr || (h.x == 0 && h.y == 0 && h.fullX == h.x && h.fullY == h.y &&
                   h.fullWidth == h.width && h.fullHeight == h.height))
        return;
    metadata[kDataWindowKey] = WindowText(h.x, h.y, h.width, h.height);
    metadata[kDisplayWindowKey] = WindowText(h.fullX, h.fullY, h.fullWidth, h.fullHeight);
}

namespace {

// Whether a part's channels make a "color" layer (malformed names make none).
bool HoldsColor(const std::vector<std::string> &channelNames) {
    try {
        for (const LayerChannels &layer : GroupChannels(channelNames))
            if (layer.name == "color") return true;
    } catch (const Error &) {
    }
    return false;
}

// The part a frame is read from: part 0 unless another part holds the colour and it does not.
int ColorPart(const std::vector<ImageHeader::Part> &parts) {
    if (parts.empty() || parts.front().color) return 0;
    for (size_t k = 1; k < parts.size(); ++k)
        if (parts[k].color) return int(k);
    return 0;
}

SampleType SampleTypeOf(Imf::PixelType type) {
    return type == Imf::HALF    ? SampleType::Half
           : type == Imf::FLOAT ? SampleType::Float
                                : SampleType::UInt32;
}

const char *SampleTypeName(SampleType type) {
    return type == SampleType::Half ? "half" : type == SampleType::Float ? "float" : "uint32";
}

// Part `part` of the file in ImageHeader's terms (not the list of parts).
void DescribePart(Imf::MultiPartInputFile &file, int part, ImageHeader &header) {
    const Imf::Header &h = file.header(part);
    header.part = part;
    const Imath::Box2i window = h.dataWindow();
    header.x = window.min.x, header.y = window.min.y;
    header.width = window.max.x - window.min.x + 1;
    header.height = window.max.y - window.min.y + 1;
    const Imath::Box2i display = h.displayWindow();
    header.fullX = display.min.x, header.fullY = display.min.y;
    header.fullWidth = display.max.x - display.min.x + 1;
    header.fullHeight = display.max.y - display.min.y + 1;
    header.tiled = h.hasTileDescription();
    header.deep = h.hasType() && Imf::isDeepData(h.type());
    std::vector<std::string> names;
    std::vector<Imf::PixelType> types;
    for (auto it = h.channels().begin(); it != h.channels().end(); ++it) {
        if (it.channel().xSampling != 1 || it.channel().ySampling != 1)
            throw std::runtime_error(
                fmt::format("channel '{}' is subsampled, which is unsupported", it.name()));
        names.push_back(it.name());
        types.push_back(it.channel().type);
    }
    for (int i : OiioChannelOrder(names)) {
        header.channelNames.push_back(names[i]);
        header.channelTypes.push_back(SampleTypeOf(types[i]));
        header.typeNames.push_back(SampleTypeName(header.channelTypes.back()));
    }
    header.strings["compression"] = CompressionName(h.compression());
    for (auto it = h.begin(); it != h.end(); ++it) {
        std::string name = it.name();
        if (IsLayoutAttribute(name)) continue;
        name = OiioAttributeName(name);
        if (auto *s = dynamic_cast<const Imf::StringAttribute *>(&it.attribute()))
            header.strings[name] = s->value();
        else if (auto *i = dynamic_cast<const Imf::IntAttribute *>(&it.attribute()))
            header.ints[name] = i->value();
        else if (auto *f = dynamic_cast<const Imf::FloatAttribute *>(&it.attribute()))
            header.floats[name] = f->value();
    }
}

// Why part k cannot be joined to the read part's channels; "" when it can.
std::string JoinRefusal(const Imf::Header &h, const ImageHeader &header, int k) {
    const ImageHeader::Part &part = header.partList[k];
    if (h.hasType() && Imf::isDeepData(h.type())) return "deep";
    if (part.x != header.x || part.y != header.y || part.width != header.width ||
        part.height != header.height)
        return fmt::format("its data window {}x{} at {},{} is not the colour's {}x{} at {},{}",
                           part.width, part.height, part.x, part.y, header.width, header.height,
                           header.x, header.y);
    for (auto it = h.channels().begin(); it != h.channels().end(); ++it)
        if (it.channel().xSampling != 1 || it.channel().ySampling != 1)
            return fmt::format("channel '{}' is subsampled", it.name());
    return "";
}

// Join part k's channels to the header's (the read part's): after them, in OpenImageIO's
// order within the part, each recorded in channelSources. Names the frame already has are
// left, and said so in the part's `left`.
void JoinPart(Imf::MultiPartInputFile &file, int k, ImageHeader &header) {
    const Imf::Header &h = file.header(k);
    ImageHeader::Part &part = header.partList[k];
    part.left = JoinRefusal(h, header, k);
    if (!part.left.empty()) return;
    if (header.channelSources.empty())
        for (const std::string &name : header.channelNames)
            header.channelSources.push_back({header.part, name});
    std::vector<std::string> names;
    std::vector<Imf::PixelType> types;
    for (auto it = h.channels().begin(); it != h.channels().end(); ++it) {
        names.push_back(it.name());
        types.push_back(it.channel().type);
    }
    std::vector<std::string> clashes;
    for (int i : OiioChannelOrder(names)) {
        // An unprefixed channel of a named part is that part's layer.
        std::string full = names[i].find('.') == std::string::npos && !part.name.empty()
                               ? part.name + "." + names[i]
                               : names[i];
        if (std::find(header.channelNames.begin(), header.channelNames.end(), full) !=
            header.channelNames.end()) {
            clashes.push_back(full);
            continue;
        }
        header.channelNames.push_back(full);
        header.channelTypes.push_back(SampleTypeOf(types[i]));
        header.typeNames.push_back(SampleTypeName(header.channelTypes.back()));
        header.channelSources.push_back({k, names[i]});
        part.joined = true;
    }
    if (!clashes.empty()) {
        std::string list;
        for (const std::string &name : clashes) list += (list.empty() ? "" : ",") + name;
        part.left = fmt::format("the frame already has {}", list);
    }
}

}  // namespace

ImageHeader ReadExrHeader(const std::string &path) {
    ImageHeader header;
    header.exr = true;
    try {
        Imf::MultiPartInputFile file(path.c_str());
        header.parts = file.parts();
        if (header.parts > 1) {
            for (int k = 0; k < header.parts; ++k) {
                const Imf::Header &h = file.header(k);
                ImageHeader::Part part;
                if (h.hasName()) part.name = h.name();
                const Imath::Box2i window = h.dataWindow();
                part.x = window.min.x, part.y = window.min.y;
                part.width = window.max.x - window.min.x + 1;
                part.height = window.max.y - window.min.y + 1;
                for (auto it = h.channels().begin(); it != h.channels().end(); ++it)
                    part.channelNames.push_back(it.name());
                part.color = HoldsColor(part.channelNames);
                header.partList.push_back(std::move(part));
            }
        }
        DescribePart(file, ColorPart(header.partList), header);
        for (int k = 0; k < int(header.partList.size()); ++k)
            if (k != header.part) JoinPart(file, k, header);
    } catch (const std::exception &e) {
        throw Error(fmt::format("cannot read '{}': {}", path, e.what()), ErrorKind::Io);
    }
    return header;
}

ImageHeader ReadImageHeader(const std::string &path) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec))
        throw Error(fmt::format("cannot read '{}': no such file", path), ErrorKind::Io);
    if (IsExrFile(path)) return ReadExrHeader(path);
    return ModuleImage(path).Header();
}

bool IoModuleLoaded() {
    return moduleLoaded.load();
}

const McdOiioApi &IoModule(const std::string &path, const std::string &what) {
    static std::mutex mutex;
    static const McdOiioApi *api = nullptr;
    std::lock_guard lock(mutex);
    if (api) return *api;

    namespace fs = std::filesystem;
    std::vector<fs::path> dirs;
    if (const char *dir = std::getenv("MCD_OIIO_MODULE_DIR"); dir && *dir) {
        dirs.push_back(dir);
    } else {
        Dl_info info{};
        if (dladdr(reinterpret_cast<void *>(&IoModuleLoaded), &info) && info.dli_fname) {
            std::error_code ec;
            fs::path self = fs::canonical(info.dli_fname, ec);
            if (!ec) dirs.push_back(self.parent_path());
            // The tool in <prefix>/bin finds <prefix>/lib wherever the prefix went.
            if (!ec && *MCD_RELATIVE_LIBDIR)
                dirs.push_back(self.parent_path().parent_path() / MCD_RELATIVE_LIBDIR);
        }
        if (*MCD_INSTALL_LIBDIR) dirs.push_back(MCD_INSTALL_LIBDIR);
    }
    std::string looked, why;
    for (const fs::path &dir : dirs) {
        fs::path candidate = dir / kModuleName;
        looked += (looked.empty() ? "" : ", ") + dir.string();
        std::error_code ec;
        if (!fs::exists(candidate, ec)) continue;
        void *handle = dlopen(candidate.c_str(), RTLD_NOW | RTLD_LOCAL);
        if (!handle) {
            const char *error = dlerror();
            why += fmt::format("; cannot load {}: {}", candidate.string(),
                               error ? error : "unknown error");
            continue;
        }
        auto entry =
            reinterpret_cast<McdOiioModuleFunction>(dlsym(handle, MCD_OIIO_MODULE_ENTRY));
        const McdOiioApi *found = entry ? entry() : nullptr;
        if (!found || found->version != MCD_OIIO_MODULE_VERSION) {
            why +=
                fmt::format("; cannot load {}: not this version's module", candidate.string());
            continue;
        }
        api = found;
        moduleLoaded = true;
        return *api;
    }
    // Found but unloadable says why (the loader's words), else where it was looked for.
    std::string missing =
        why.empty() ? fmt::format("not found in {}", looked.empty() ? "(nowhere)" : looked)
                    : why.substr(2);
    throw Error(fmt::format("cannot {} '{}': that needs the OpenImageIO module {}, {}", what,
                            path, kModuleName, missing),
                ErrorKind::Io);
}

ModuleImage::ModuleImage(const std::string &path) : path(path) {
    api = &IoModule(path, "read");
    char error[1024] = {};
    const McdOiioHeader *h = nullptr;
    handle = api->open(path.c_str(), &h, error, sizeof error);
    if (!handle) throw Error(fmt::format("cannot read '{}': {}", path, error), ErrorKind::Io);
    try {
        FillHeader(h);
    } catch (...) {
        api->close(handle);  // the destructor does not run for a throwing constructor
        handle = nullptr;
        throw;
    }
}

// The module's header in ImageHeader's terms.
void ModuleImage::FillHeader(const McdOiioHeader *h) {
    header.x = h->x, header.y = h->y, header.width = h->width, header.height = h->height;
    header.depth = h->depth, header.tiled = h->tiled, header.deep = h->deep;
    header.fullX = h->x, header.fullY = h->y, header.fullWidth = h->width;
    header.fullHeight = h->height;
    header.parts = h->subimages;
    for (int c = 0; c < h->channelCount; ++c) {
        header.channelNames.push_back(h->channelNames[c]);
        header.typeNames.push_back(h->channelTypes[c]);
        header.channelTypes.push_back(TypeOf(h->channelTypes[c]));
    }
    for (int a = 0; a < h->attributeCount; ++a) {
        const McdOiioAttribute &attribute = h->attributes[a];
        if (attribute.kind == MCD_OIIO_STRING)
            header.strings[attribute.name] = attribute.text;
        else if (attribute.kind == MCD_OIIO_INT)
            header.ints[attribute.name] = attribute.integer;
        else
            header.floats[attribute.name] = attribute.real;
    }
}

ModuleImage::~ModuleImage() {
    if (handle) api->close(handle);
}

void ModuleImage::ReadRows(int y0, int y1, float *pixels) {
    char error[1024] = {};
    if (!api->readRows(handle, y0, y1, pixels, error, sizeof error))
        throw Error(fmt::format("cannot read '{}': {}", path, error), ErrorKind::Io);
}

void WriteModuleUInt8(const std::string &path, const std::string &target, const char *format,
                      int width, int height, int channels, const unsigned char *pixels,
                      bool unassociatedAlpha) {
    const McdOiioApi &api = IoModule(target, "write");
    char error[1024] = {};
    if (!api.writeUInt8(path.c_str(), format, width, height, channels, pixels,
                        unassociatedAlpha, error, sizeof error))
        throw Error(fmt::format("cannot write '{}': {}", target, error), ErrorKind::Io);
}

}  // namespace mcd::io
