#include "host/io/frame.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <system_error>
#include <utility>

#include <unistd.h>

#include "host/error.h"
#include "host/io/conventions.h"
#include "host/io/exr_read.h"
#include "host/io/image_file.h"
#include "host/io/layer_names.h"

namespace mcd {
using namespace io;

namespace {

// How a channel's stored values become our floats. The OpenImageIO module hands integer
// data over as normalized [0,1] floats.
enum class Decode {
    None,     // float data, or integer data in a linear color space
    Srgb,     // 8/16-bit display data: undo the sRGB transfer curve
    Integer,  // 32-bit unsigned: undo the normalization
};

float SrgbToLinear(float v) {
    return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

bool IsLinearColorSpace(std::string colorSpace) {
    for (char &c : colorSpace) c = char(std::tolower((unsigned char)c));
    return colorSpace.find("linear") != std::string::npos;
}

bool IsAlpha(const std::string &channelName) {
    return channelName == "A" || channelName.ends_with(".A");
}

// Whether ReadFrame keeps a layer of the file: the ones asked for, the layers a
// convention composes them from, and other renderer passes (small, and kept so that
// `info` and the conventions see them).
bool Wanted(const std::string &layer, const ReadOptions &options) {
    if (options.layers.empty()) return true;
    auto asked = [&](const std::string &name) {
        for (const std::string &want : options.layers)
            if (want == name ||
                (want.ends_with('*') && name.starts_with(want.substr(0, want.size() - 1))))
                return true;
        return false;
    };
    if (asked(layer)) return true;
    if (IsSplitSource(layer)) return asked("direct") || asked("indirect");
    return !IsOwnLayerName(layer);
}

// Read a band of rows at a time through the module, interleaved, and scatter it into the
// planes; a whole interleaved copy of a big frame would double the memory needed.
void ReadBands(ModuleImage &in, const std::vector<Decode> &decode,
               const std::vector<float *> &destination) {
    const ImageHeader &spec = in.Header();
    int channelCount = int(spec.channelNames.size());
    constexpr int bandRows = 32;
    size_t rowValues = size_t(spec.width) * size_t(channelCount);
    std::vector<float> band(size_t(bandRows) * rowValues);
    for (int y0 = 0; y0 < spec.height; y0 += bandRows) {
        int y1 = std::min(spec.height, y0 + bandRows);
        in.ReadRows(y0, y1, band.data());
        for (int c = 0; c < channelCount; ++c) {
            if (!destination[c]) continue;
            for (int y = y0; y < y1; ++y) {
                const float *src = band.data() + size_t(y - y0) * rowValues + c;
                float *dst = destination[c] + size_t(y) * spec.width;
                for (int x = 0; x < spec.width; ++x) {
                    float v = src[size_t(x) * channelCount];
                    switch (decode[c]) {
                        case Decode::None:
                            break;
                        case Decode::Srgb:
                            v = SrgbToLinear(v);
                            break;
                        // Exact for ids below 2^24, which is what a float can hold anyway.
                        case Decode::Integer:
                            v = float(std::round(double(v) * 4294967295.0));
                            break;
                    }
                    dst[x] = v;
                }
            }
        }
    }
}

// A frame denoised in place (WriteDenoisedOver) keeps the render's colour in
// kNoisyColorLayer and the denoised one as its colour: the noisy one is the frame's colour,
// so that denoising it again starts from the render, and the denoised one is the layer
// kDenoisedColorLayer, so that compare can measure it. Whether it did so.
bool TakeNoisyColor(std::vector<LayerChannels> &grouped) {
    auto named = [&](const std::string &name) {
        return std::find_if(grouped.begin(), grouped.end(),
                            [&](const LayerChannels &l) { return l.name == name; });
    };
    auto color = named("color"), noisy = named(kNoisyColorLayer);
    if (color == grouped.end() || noisy == grouped.end() ||
        color->channels.size() != noisy->channels.size())
        return false;
    std::swap(color->channels, noisy->channels);
    noisy->name = kDenoisedColorLayer;
    return true;
}

// Which part of a multi-part EXR was read, the parts joined to it and what was not read,
// and why; "" for one part.
std::string PartsNote(const ImageHeader &spec) {
    if (spec.partList.size() < 2) return "";
    auto label = [&](int k) {
        const std::string &name = spec.partList[k].name;
        return name.empty() ? std::to_string(k) : fmt::format("{} ({})", k, name);
    };
    std::string joined, left;
    for (int k = 0; k < int(spec.partList.size()); ++k) {
        if (k == spec.part) continue;
        const ImageHeader::Part &part = spec.partList[k];
        if (part.joined) joined += (joined.empty() ? "" : ", ") + label(k);
        if (!part.left.empty())
            left += fmt::format("{}part {}{}: {}", left.empty() ? "" : "; ", label(k),
                                part.joined ? "'s other channels" : "", part.left);
    }
    std::string note = fmt::format("part {} of {}{}", label(spec.part), spec.partList.size(),
                                   spec.partList[spec.part].color ? ", the colour's" : "");
    if (!joined.empty())
        note += "; joined: part" +
                std::string(joined.find(',') == std::string::npos ? " " : "s ") + joined;
    if (!left.empty()) note += "; not read: " + left;
    return note;
}

// Add to the frame's mcd:convention which part it was read from and whether its colour is
// the noisy one kept beside a denoised result (then kShownColorKey names the result).
void AddReadNotes(Frame &frame, const ImageHeader &spec, bool tookNoisy) {
    std::string note = PartsNote(spec);
    if (tookNoisy) {
        note += fmt::format("{}color from {} (the colour channels hold a denoised result)",
                            note.empty() ? "" : " | ", kNoisyColorLayer);
        frame.metadata[kShownColorKey] = kDenoisedColorLayer;
    }
    if (!note.empty()) {
        std::string &text = frame.metadata[kConventionKey];
        text += (text.empty() ? "" : " | ") + note;
    }
}

}  // namespace

// The machine's physical memory in bytes (0 if unknown).
static uint64_t PhysicalMemory() {
    long pages = sysconf(_SC_PHYS_PAGES), pageSize = sysconf(_SC_PAGE_SIZE);
    return pages > 0 && pageSize > 0 ? uint64_t(pages) * uint64_t(pageSize) : 0;
}

Frame ReadFrame(const std::string &path, const ReadOptions &options) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec))
        throw Error(fmt::format("cannot read '{}': no such file", path), ErrorKind::Io);
    // EXR with OpenEXR; anything else through the OpenImageIO module, loaded only now.
    std::unique_ptr<ModuleImage> module;
    ImageHeader exrHeader;
    if (IsExrFile(path))
        exrHeader = ReadExrHeader(path);
    else
        module = std::make_unique<ModuleImage>(path);
    const ImageHeader &spec = module ? module->Header() : exrHeader;

    // The data window is the frame; its origin and the display window go into the
    // metadata (below) for the writers.
    int channelCount = int(spec.channelNames.size());
    if (spec.width <= 0 || spec.height <= 0 || channelCount <= 0)
        throw Error(fmt::format("cannot read '{}': it has zero size ({}x{}, {} channels)", path,
                                spec.width, spec.height, channelCount),
                    ErrorKind::Io);
    if (spec.deep)
        throw Error(fmt::format("cannot read '{}': deep images are unsupported", path),
                    ErrorKind::Io);
    if (spec.depth > 1)
        throw Error(fmt::format("cannot read '{}': volume images are unsupported", path),
                    ErrorKind::Io);

    // Decide per channel how its values are turned into floats.
    auto colorSpace = spec.strings.find("oiio:ColorSpace");
    bool linear = colorSpace != spec.strings.end() && IsLinearColorSpace(colorSpace->second);
    std::vector<Decode> decode(channelCount);
    for (int c = 0; c < channelCount; ++c) {
        SampleType format = spec.channelTypes[c];
        if (format == SampleType::Float || format == SampleType::Half ||
            format == SampleType::Double)
            decode[c] = Decode::None;
        else if (format == SampleType::UInt8 || format == SampleType::UInt16)
            decode[c] = linear || IsAlpha(spec.channelNames[c]) ? Decode::None : Decode::Srgb;
        else if (format == SampleType::UInt32)
            decode[c] = Decode::Integer;
        else
            throw Error(fmt::format("cannot read '{}': channel '{}' has unsupported format {}",
                                    path, spec.channelNames[c], spec.typeNames[c]),
                        ErrorKind::Io);
    }

    std::vector<LayerChannels> grouped;
    bool tookNoisy = false;
    try {
        grouped = GroupChannels(spec.channelNames);
        tookNoisy = TakeNoisyColor(grouped);
    } catch (const Error &e) {
        throw Error(fmt::format("cannot read '{}': {}", path, e.what()), ErrorKind::Io);
    }

    // Refuse before allocating a data window that cannot fit in memory.
    uint64_t wantedChannels = 0;
    for (const LayerChannels &layer : grouped)
        if (Wanted(layer.name, options)) wantedChannels += layer.channels.size();
    uint64_t bytes = uint64_t(spec.width) * uint64_t(spec.height) * wantedChannels * 4;
    uint64_t limit = options.memoryLimit ? options.memoryLimit : PhysicalMemory();
    if (limit && bytes > limit)
        throw Error(fmt::format("cannot read '{}': its {}x{} data window with {} channel(s) "
                                "read needs {:.1f} GB, more than the {:.1f} GB allowed",
                                path, spec.width, spec.height, wantedChannels, bytes / 1e9,
                                limit / 1e9),
                    ErrorKind::OutOfMemory);

    Frame frame;
    frame.path = path;
    frame.width = spec.width;
    frame.height = spec.height;
    // Where each file channel goes: layer plane, or nowhere (alpha, pbrt-v4 P.*).
    std::vector<float *> destination(channelCount, nullptr);
    for (const LayerChannels &layer : grouped) {
        if (!Wanted(layer.name, options)) continue;
        Image &image = frame.layers[layer.name] =
            Image(spec.width, spec.height, int(layer.channels.size()));
        for (size_t c = 0; c < layer.channels.size(); ++c)
            destination[layer.channels[c]] = image.Plane(int(c));
    }

    // EXR files straight into the planes, only the wanted channels (EXR data is float, half
    // or 32-bit ids, none of which needs decoding beyond a float conversion).
    if (module) {
        ReadBands(*module, decode, destination);
    } else {
        std::vector<ExrTarget> targets;
        for (int c = 0; c < channelCount; ++c)
            if (destination[c]) targets.push_back({spec.channelNames[c], destination[c]});
        if (!ReadExrFrameChannels(path, spec, targets))
            throw Error(
                fmt::format("cannot read '{}': subsampled channels are unsupported", path),
                ErrorKind::Io);
    }

    // The file's string attributes; "oiio:*" are OpenImageIO's hints, not the file's.
    for (const auto &[name, value] : spec.strings)
        if (!name.starts_with("oiio:")) frame.metadata[name] = value;
    // An EXR's windows, so that WriteExr keeps them.
    AddWindows(spec, frame.metadata);
    // Numbers only for the conventions (pbrt-v4's samplesPerPixel is an int).
    std::map<std::string, double> numbers;
    for (const auto &[name, value] : spec.ints) numbers[name] = value;
    for (const auto &[name, value] : spec.floats) numbers[name] = value;
    ApplyConventions(frame, spec.channelNames, numbers);
    AddReadNotes(frame, spec, tookNoisy);
    return frame;
}

Image ReadImage(const std::string &path, const std::string &layer) {
    Frame frame = ReadFrame(path);
    frame.Get(layer);  // throws if missing
    return std::move(frame.layers[layer]);
}

}  // namespace mcd
