#include "host/io/conventions.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <optional>
#include <set>
#include <string_view>

namespace mcd::io {

namespace {

// The prefix of a channel name (before its last dot), or "" for an unprefixed one.
std::string PrefixOf(const std::string &name) {
    size_t dot = name.rfind('.');
    return dot == std::string::npos ? std::string() : name.substr(0, dot);
}

std::optional<double> ParseNumber(const std::string &text) {
    double value = 0;
    auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (ec != std::errc() || end != text.data() + text.size()) return std::nullopt;
    return value;
}

// A positive sample count from the header: a numeric attribute or a string one.
std::optional<double> SampleCount(const Frame &frame,
                                  const std::map<std::string, double> &numbers,
                                  std::initializer_list<const char *> keys) {
    for (const char *key : keys) {
        if (auto it = numbers.find(key); it != numbers.end() && it->second > 0)
            return it->second;
        if (auto it = frame.metadata.find(key); it != frame.metadata.end())
            if (std::optional<double> n = ParseNumber(it->second); n && *n > 0) return n;
    }
    return std::nullopt;
}

// Whether the frame has the layer with 3 channels (a damaged or hand-made file may not).
bool HasRgb(const Frame &frame, const std::string &name) {
    return frame.Has(name) && frame.Get(name).channels == 3;
}

// sum += a b, pixel by pixel; all of the same size (3 channels: HasRgb).
void AddScaled(Image &sum, const Image &a, const Image *b) {
    for (size_t i = 0; i < sum.Size(); ++i) sum.data[i] += a.data[i] * (b ? b->data[i] : 1.f);
}

// Blender passes a multilayer EXR names "<view layer>.<pass>.<channel>".
constexpr std::array<std::string_view, 24> kBlenderPasses = {"Combined",
                                                             "Noisy Image",
                                                             "Denoising Albedo",
                                                             "Denoising Normal",
                                                             "Denoising Depth",
                                                             "Depth",
                                                             "Normal",
                                                             "IndexOB",
                                                             "IndexMA",
                                                             "DiffDir",
                                                             "DiffInd",
                                                             "DiffCol",
                                                             "GlossDir",
                                                             "GlossInd",
                                                             "GlossCol",
                                                             "TransDir",
                                                             "TransInd",
                                                             "TransCol",
                                                             "Emit",
                                                             "Env",
                                                             "VolumeDir",
                                                             "VolumeInd",
                                                             "AO",
                                                             "Debug Sample Count"};

// The Blender passes in the file, by pass name; empty when it is not a Blender file.
std::set<std::string> BlenderPasses(const std::vector<std::string> &channelNames,
                                    std::string *viewLayer) {
    std::set<std::string> passes;
    for (const std::string &name : channelNames) {
        std::string prefix = PrefixOf(name);
        size_t dot = prefix.find('.');
        if (dot == std::string::npos) continue;
        std::string pass = prefix.substr(dot + 1);
        if (std::find(kBlenderPasses.begin(), kBlenderPasses.end(), pass) ==
            kBlenderPasses.end())
            continue;
        passes.insert(pass);
        *viewLayer = prefix.substr(0, dot);
    }
    return passes;
}

// Whether Film > Transparent left the background out of Combined: alpha below 1 at a pixel
// whose Env pass (the world the camera sees there) is not zero. On opaque film the world
// counts as covered, alpha 1.
bool TransparentFilm(const Frame &frame) {
    if (!frame.Has("alpha") || !HasRgb(frame, "Env")) return false;
    const Image &alpha = frame.Get("alpha"), &env = frame.Get("Env");
    if (alpha.channels != 1 || !alpha.SameShape(Image(env.width, env.height, 1))) return false;
    for (size_t i = 0; i < alpha.PixelCount(); ++i)
        if (alpha.data[i] < 1.f)
            for (int c = 0; c < 3; ++c)
                if (env.Plane(c)[i] != 0.f) return true;
    return false;
}

// Cycles' Combined = sum over X of (XDir + XInd) XCol + VolumeDir + VolumeInd + Emit, + Env
// unless the film is transparent: direct and indirect from those passes, what they miss
// of color added to indirect. Returns the convention's text.
std::string ComposeSplit(Frame &frame) {
    std::vector<std::string> used, incomplete;
    for (const char *x : {"Diff", "Gloss", "Trans"}) {
        std::string dir = std::string(x) + "Dir", ind = std::string(x) + "Ind",
                    col = std::string(x) + "Col";
        int have = HasRgb(frame, dir) + HasRgb(frame, ind) + HasRgb(frame, col);
        if (have == 3)
            used.push_back(x);
        else if (frame.Has(dir) || frame.Has(ind))
            incomplete.push_back(x);
    }
    if (!incomplete.empty()) {
        std::string text = "no direct/indirect: the light passes of";
        for (const std::string &x : incomplete) text += " " + x;
        return text + " lack Dir, Ind or Col";
    }
    if (used.empty())
        return "no direct/indirect: no light passes (Diff/Gloss/Trans Dir, Ind, Col)";

    const Image &color = frame.Get("color");
    Image direct(color.width, color.height, 3), indirect = direct;
    for (const std::string &x : used) {
        const Image &col = frame.Get(x + "Col");
        AddScaled(direct, frame.Get(x + "Dir"), &col);
        AddScaled(indirect, frame.Get(x + "Ind"), &col);
    }
    bool transparent = TransparentFilm(frame);
    std::vector<std::string> missing;
    for (const char *pass : {"Emit", "Env", "VolumeDir"})
        if (transparent && std::string(pass) == "Env")
            continue;
        else if (HasRgb(frame, pass))
            AddScaled(direct, frame.Get(pass), nullptr), used.push_back(pass);
        else
            missing.push_back(pass);
    if (HasRgb(frame, "VolumeInd"))
        AddScaled(indirect, frame.Get("VolumeInd"), nullptr), used.push_back("VolumeInd");
    else
        missing.push_back("VolumeInd");
    for (const char *x : {"Diff", "Gloss", "Trans"})
        if (std::find(used.begin(), used.end(), x) == used.end())
            missing.push_back(std::string(x) + "*");

    // What the passes miss goes to indirect, so that direct + indirect = color and the
    // bayes split (direct added back) keeps all of it.
    double gap = 0, total = 0;
    for (size_t i = 0; i < color.Size(); ++i) {
        float rest = color.data[i] - direct.data[i] - indirect.data[i];
        if (!std::isfinite(rest)) continue;
        gap += std::abs(rest), total += std::abs(color.data[i]);
        indirect.data[i] += rest;
    }
    double percent = total > 0 ? 100 * gap / total : 0;
    std::string text = "direct/indirect composed from the light passes (";
    for (size_t i = 0; i < used.size(); ++i) text += (i ? ", " : "") + used[i];
    if (transparent)
        text +=
            "; not Env: the film is transparent, alpha below 1 where the world shows, "
            "and Combined holds no background";
    text += fmt::format("): they sum to color within {:.2g}% of |color|", percent);
    if (percent > 0.1) {
        text += "; the rest goes to indirect";
        if (!missing.empty()) {
            text += " (passes not written:";
            for (const std::string &m : missing) text += " " + m;
            text += ")";
        }
    }
    frame.layers["direct"] = std::move(direct);
    frame.layers["indirect"] = std::move(indirect);
    return text;
}

std::string ReadBlender(Frame &frame, const std::set<std::string> &names,
                        const std::set<std::string> &passes, const std::string &viewLayer) {
    std::vector<std::string> parts;
    bool noisy = passes.count("Noisy Image") > 0;
    if (noisy)
        for (const auto &[name, image] : frame.layers)
            if (name == "Combined" || name.ends_with(".Combined"))
                frame.metadata[kShownColorKey] = name;
    if (frame.Has("color"))
        parts.push_back(noisy ? "color from Noisy Image (Combined is denoised)"
                              : "color from Combined");
    if (frame.Has("alpha") && !names.count("A"))
        parts.push_back(noisy && names.count(viewLayer + ".Noisy Image.A")
                            ? "alpha from Noisy Image.A"
                            : "alpha from Combined.A");
    if (frame.Has("normal"))
        parts.push_back(passes.count("Denoising Normal")
                            ? "normal from Denoising Normal (camera space)"
                            : "normal from Normal (world space)");
    if (frame.Has("depth"))
        parts.push_back(passes.count("Denoising Depth") ? "depth from Denoising Depth"
                                                        : "depth from Depth");

    if (!frame.Has("direct") && !frame.Has("indirect") && frame.Has("color") &&
        frame.Get("color").channels == 3)
        parts.push_back(ComposeSplit(frame));

    // Debug Sample Count is the pixel's share of the samples, in (0, 1].
    if (frame.Has("Debug Sample Count") && !frame.Has("spp")) {
        std::optional<double> total;
        for (const auto &[key, value] : frame.metadata)
            if (key == "cycles." + viewLayer + ".samples" ||
                (!total && key.starts_with("cycles.") && key.ends_with(".samples")))
                if (std::optional<double> n = ParseNumber(value); n && *n > 0) total = n;
        if (total) {
            Image spp = frame.Get("Debug Sample Count");
            for (float &v : spp.data) v = std::round(v * float(*total));
            frame.layers["spp"] = std::move(spp);
            parts.push_back(
                fmt::format("spp = Debug Sample Count x {} (cycles.*.samples)", *total));
        } else {
            parts.push_back(
                "Debug Sample Count kept as a fraction: the metadata has no "
                "cycles.<view layer>.samples to make it spp");
        }
    }
    if (!frame.Has("variance")) parts.push_back("no variance (Cycles writes none)");

    std::string line =
        fmt::format("read as Blender Cycles multilayer (view layer '{}')", viewLayer);
    for (size_t i = 0; i < parts.size(); ++i) line += (i ? "; " : ": ") + parts[i];
    return line;
}

std::string ReadPbrt(Frame &frame, const std::map<std::string, double> &numbers) {
    std::optional<double> spp = SampleCount(frame, numbers, {"samplesPerPixel"});
    if (!spp) {
        // Refuse to guess: dividing by a wrong count would scale every noise estimate.
        frame.layers["Variance"] = std::move(frame.layers["variance"]);
        frame.layers.erase("variance");
        return "read as pbrt-v4 GBufferFilm: NO variance layer: Variance.* is the variance "
               "of the samples and the header has no samplesPerPixel to divide it by (kept "
               "as layer 'Variance')";
    }
    for (float &v : frame.layers["variance"].data) v /= float(*spp);
    return fmt::format(
        "read as pbrt-v4 GBufferFilm: variance = Variance.* / samplesPerPixel ({:g}) (the "
        "samples' variance, over those that hit a surface, in sensor RGB){}",
        *spp, frame.Has("normal") ? "; normal from N (geometric, camera or world space)" : "");
}

// Mitsuba 3's aov integrator: the AOVs named after their type.
std::string ReadMitsubaAov(const std::set<std::string> &prefixes) {
    std::vector<std::string> parts;
    if (prefixes.count("sh_normal"))
        parts.push_back("normal from sh_normal (world space)");
    else if (prefixes.count("geo_normal"))
        parts.push_back("normal from geo_normal (world space)");
    if (prefixes.count("depth")) parts.push_back("depth from depth.T (distance along the ray)");
    if (prefixes.count("shape_index")) parts.push_back("objectId from shape_index");
    std::string line = "read as Mitsuba 3 aov";
    for (size_t i = 0; i < parts.size(); ++i) line += (i ? "; " : ": ") + parts[i];
    return line;
}

// Mitsuba 3's moment integrator: <name>.X/Y/Z and m2_<name>.X/Y/Z, the first and second
// moments of the nested integrator's samples in CIE XYZ.
std::string ReadMitsubaMoment(Frame &frame, const std::map<std::string, double> &numbers,
                              const std::string &name) {
    std::string line = fmt::format("read as Mitsuba 3 moment ({}, m2_{})", name, name);
    std::optional<double> spp = SampleCount(frame, numbers, {"spp", "samplesPerPixel"});
    if (frame.Has("variance")) return line + ": the frame's own variance layer kept";
    if (!frame.Has("color") || frame.Get("color").channels != 3)
        return line + ": no variance: the frame has no RGB color";
    if (!spp)
        return line +
               ": NO variance: the file does not say how many samples per pixel (add a "
               "header attribute spp, e.g. oiiotool --attrib:type=int spp 64)";
    const Image &m1 = frame.Get(name), &m2 = frame.Get("m2_" + name),
                &color = frame.Get("color");
    // Only Y's second moment is exact; colour follows the pixel's chromaticity.
    Image variance(color.width, color.height, 3);
    for (int y = 0; y < color.height; ++y)
        for (int x = 0; x < color.width; ++x) {
            float meanY = m1.At(1, y, x);
            float varY = std::max(0.f, m2.At(1, y, x) - meanY * meanY) / float(*spp);
            for (int c = 0; c < 3; ++c) {
                float ratio = meanY > 0 ? color.At(c, y, x) / meanY : 1.f;
                variance.At(c, y, x) = varY * ratio * ratio;
            }
        }
    frame.layers["variance"] = std::move(variance);
    return line + fmt::format(
                      ": variance = (m2_{0}.Y - {0}.Y^2) / spp ({1:g}) x (color / {0}.Y)^2 "
                      "(only the luminance moment is exact)",
                      name, *spp);
}

}  // namespace

bool IsSplitSource(const std::string &layer) {
    for (const char *x : {"Diff", "Gloss", "Trans"})
        for (const char *part : {"Dir", "Ind", "Col"})
            if (layer == std::string(x) + part) return true;
    return layer == "Emit" || layer == "Env" || layer == "VolumeDir" || layer == "VolumeInd" ||
           layer == "alpha";
}

void ApplyConventions(Frame &frame, const std::vector<std::string> &channelNames,
                      const std::map<std::string, double> &numbers) {
    frame.metadata.erase(kConventionKey);
    frame.metadata.erase(kShownColorKey);
    std::set<std::string> names(channelNames.begin(), channelNames.end()), prefixes;
    for (const std::string &name : channelNames) prefixes.insert(PrefixOf(name));

    std::vector<std::string> lines;
    std::string viewLayer;
    if (std::set<std::string> passes = BlenderPasses(channelNames, &viewLayer); !passes.empty())
        lines.push_back(ReadBlender(frame, names, passes, viewLayer));

    // pbrt-v4's Variance won our "variance" unless the file had its own.
    if (names.count("Variance.R") && !names.count("variance.R") && frame.Has("variance"))
        lines.push_back(ReadPbrt(frame, numbers));

    if (prefixes.count("sh_normal") || prefixes.count("geo_normal") ||
        prefixes.count("shape_index") || names.count("depth.T"))
        lines.push_back(ReadMitsubaAov(prefixes));
    for (const std::string &prefix : prefixes)
        if (prefix.starts_with("m2_") && frame.Has(prefix) && frame.Has(prefix.substr(3)) &&
            frame.Get(prefix).channels == 3 && frame.Get(prefix.substr(3)).channels == 3 &&
            names.count(prefix + ".Y")) {
            lines.push_back(ReadMitsubaMoment(frame, numbers, prefix.substr(3)));
            break;
        }

    std::string text;
    for (const std::string &line : lines) text += (text.empty() ? "" : " | ") + line;
    if (!text.empty()) frame.metadata[kConventionKey] = text;
}

}  // namespace mcd::io
