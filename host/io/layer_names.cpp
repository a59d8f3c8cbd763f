#include "host/io/layer_names.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <map>
#include <optional>
#include <set>
#include <string_view>
#include <utility>

#include "host/error.h"

namespace mcd::io {

namespace {

// When several sets of channels map to one layer name, the highest priority takes it and
// the others keep their names as found in the file. Our own names come first, then the
// pass a renderer means for denoising, then its plainer fallback.
constexpr int kOwnPriority = 3;
constexpr int kUnknownPriority = 0;

// Our layer names (ARCHITECTURE.md), plus "hist" for the Bin_NNNN channels and "zhist" for the
// histograms of color / pivot (zhist.0 .. zhist.3n, laid out as hist), and "alpha" for the
// A channel beside an unprefixed color, and "motion" for motion vectors (Blender's Vector
// pass: shaders/temporal/temporal.h).
constexpr std::array<std::string_view, 19> kOwnNames = {
    "color",     "variance",  "spp",    "min",    "max",   "hist",     "direct",
    "indirect",  "pivot",     "albedo", "normal", "depth", "objectId", "partId",
    "reference", "remainder", "zhist",  "alpha",  "motion"};

struct Alias {
    std::string_view from, to;  // to == "" drops the channels
    int priority;
};

// Other renderers' names. Blender passes kept under their own names are listed too, so
// that a view-layer prefix in front of them is recognised and stripped.
constexpr Alias kAliases[] = {
    // pbrt-v4 (GBufferFilm).
    {"Albedo", "albedo", 2},
    {"N", "normal", 2},
    {"Ns", "normal", 1},
    {"Variance", "variance", 2},
    {"P", "", 2},
    // Blender (Cycles). Denoising Data alone leaves Combined noisy and adds no Noisy Image
    // (the fixtures in tests/data); with the render denoiser on, Combined is its output and
    // Noisy Image the noisy colour, which wins "color" when both are there.
    {"Noisy Image", "color", 2},
    {"Combined", "color", 1},
    {"Denoising Albedo", "albedo", 2},
    {"Denoising Normal", "normal", 2},
    {"Normal", "normal", 1},
    {"Denoising Depth", "depth", 2},
    {"Depth", "depth", 1},
    {"IndexOB", "objectId", 2},
    {"IndexMA", "partId", 2},
    {"Vector", "motion", 2},
    {"DiffDir", "DiffDir", 1},
    {"DiffInd", "DiffInd", 1},
    {"DiffCol", "DiffCol", 1},
    {"GlossDir", "GlossDir", 1},
    {"GlossInd", "GlossInd", 1},
    {"GlossCol", "GlossCol", 1},
    {"TransDir", "TransDir", 1},
    {"TransInd", "TransInd", 1},
    {"TransCol", "TransCol", 1},
    {"Emit", "Emit", 1},
    {"Env", "Env", 1},
    {"VolumeDir", "VolumeDir", 1},
    {"VolumeInd", "VolumeInd", 1},
    {"AO", "AO", 1},
    {"Debug Sample Count", "Debug Sample Count", 1},
    // Mitsuba 3 (aov integrator), AOVs named after their type; both normals are world
    // space, the shading one is what a denoiser wants.
    {"sh_normal", "normal", 2},
    {"geo_normal", "normal", 1},
    {"shape_index", "objectId", 2},
};

struct Target {
    std::string name;
    int priority;
};

// Ershov section 8's partial images: partial<k>.color, .pivot and .variance, k decimal.
// Own names whole, so that "partial0.pivot" is not read as view layer "partial0" of pivot.
bool IsPartialName(std::string_view name) {
    if (name.rfind("partial", 0) != 0) return false;
    size_t dot = name.find('.');
    if (dot == std::string_view::npos || dot == 7 || dot > 7 + 9) return false;
    for (size_t i = 7; i < dot; ++i)
        if (name[i] < '0' || name[i] > '9') return false;
    std::string_view what = name.substr(dot + 1);
    return what == "color" || what == "pivot" || what == "variance";
}

// Own names with a dot, taken whole: "direct.variance" is not view layer "direct" of
// variance (which it would take from the real one, whose channels sort after it).
constexpr std::array<std::string_view, 4> kOwnDottedNames = {
    "direct.variance", "indirect.variance", "half0.color", "half1.color"};

bool IsOwnName(std::string_view name) {
    return std::find(kOwnNames.begin(), kOwnNames.end(), name) != kOwnNames.end() ||
           std::find(kOwnDottedNames.begin(), kOwnDottedNames.end(), name) !=
               kOwnDottedNames.end() ||
           IsPartialName(name) || IsHalf0LayerName(name);
}

std::optional<Target> LookUp(std::string_view name) {
    if (IsOwnName(name)) return Target{std::string(name), kOwnPriority};
    for (const Alias &alias : kAliases)
        if (alias.from == name) return Target{std::string(alias.to), alias.priority};
    return std::nullopt;
}

// Map a channel prefix to a layer; strip one leading view-layer prefix (Blender's
// "ViewLayer.Combined") when what is left is a known name.
Target Resolve(const std::string &prefix) {
    if (std::optional<Target> target = LookUp(prefix)) return *target;
    if (size_t dot = prefix.find('.'); dot != std::string::npos)
        if (std::optional<Target> target = LookUp(std::string_view(prefix).substr(dot + 1)))
            return *target;
    return {prefix, kUnknownPriority};
}

std::string Upper(std::string_view s) {
    std::string upper(s);
    for (char &c : upper) c = char(std::toupper((unsigned char)c));
    return upper;
}

// Parse a string of decimal digits; nullopt for anything else (or too long to be sane).
std::optional<long> ParseIndex(std::string_view s) {
    if (s.empty() || s.size() > 9) return std::nullopt;
    long value = 0;
    for (char c : s) {
        if (c < '0' || c > '9') return std::nullopt;
        value = value * 10 + (c - '0');
    }
    return value;
}

struct Channel {
    std::string suffix;
    int index;
};

// Put a group's channels in layer order: R,G,B or X,Y,Z whatever the file order (suffixes
// compared case-blind), numbered suffixes by number, anything else as found. Alpha is
// left out of a known RGB layer and kept in an unknown one (e.g. Cryptomatte).
std::vector<int> OrderChannels(const std::vector<Channel> &group, bool dropAlpha) {
    auto allIn = [&](std::string_view set) {
        return std::all_of(group.begin(), group.end(), [&](const Channel &ch) {
            std::string s = Upper(ch.suffix);
            return s.size() == 1 && set.find(s[0]) != std::string_view::npos;
        });
    };
    auto inOrder = [&](std::string_view order) {
        std::vector<int> channels;
        for (char want : order)
            for (const Channel &ch : group)
                if (Upper(ch.suffix) == std::string(1, want)) channels.push_back(ch.index);
        return channels;
    };

    bool anyRgb = std::any_of(group.begin(), group.end(), [](const Channel &ch) {
        std::string s = Upper(ch.suffix);
        return s == "R" || s == "G" || s == "B";
    });
    if (anyRgb && allIn("RGBA")) return inOrder(dropAlpha ? "RGB" : "RGBA");
    if (allIn("XYZ")) return inOrder("XYZ");
    if (group.size() == 4 && allIn("XYZW")) return inOrder("XYZW");  // Blender's Vector

    std::vector<std::pair<long, int>> numbered;
    for (const Channel &ch : group)
        if (std::optional<long> n = ParseIndex(ch.suffix)) numbered.push_back({*n, ch.index});
    if (numbered.size() == group.size()) {
        std::sort(numbered.begin(), numbered.end());
        std::vector<int> channels;
        for (auto &[n, index] : numbered) channels.push_back(index);
        return channels;
    }

    std::vector<int> channels;
    for (const Channel &ch : group) channels.push_back(ch.index);
    return channels;
}

// Check the Bin_NNNN channels form the RHF layout and return them in bin order.
std::vector<int> OrderBins(std::vector<std::pair<long, int>> bins,
                           const std::vector<std::string> &names) {
    std::sort(bins.begin(), bins.end());
    for (size_t i = 0; i < bins.size(); ++i) {
        if (bins[i].first == long(i)) continue;
        if (i > 0 && bins[i].first == bins[i - 1].first)
            throw Error(
                fmt::format("histogram channels '{}' and '{}' are both bin {}",
                            names[bins[i - 1].second], names[bins[i].second], bins[i].first),
                ErrorKind::InvalidArgument);
        throw Error(
            fmt::format(
                "histogram channels are not contiguous from Bin_0000: bin {} is missing "
                "(found {} Bin_* channels, the highest is '{}')",
                i, bins.size(), names[bins.back().second]),
            ErrorKind::InvalidArgument);
    }
    if (bins.size() < 4 || (bins.size() - 1) % 3 != 0)
        throw Error(
            fmt::format(
                "histogram has {} Bin_* channels; expected 3n+1 (n bins for each of R,G,B, "
                "then the sample count)",
                bins.size()),
            ErrorKind::InvalidArgument);
    std::vector<int> channels;
    for (auto &[bin, index] : bins) channels.push_back(index);
    return channels;
}

struct Candidate {
    Target target;
    std::string ownName;  // the name as found in the file, used when target is taken
    std::string what;     // the channels, for messages
    std::vector<int> channels;
    bool optional = false;  // left out, not an error, when its target is taken
};

// The index of a group's alpha channel (suffix A, any case), if it has one.
std::optional<int> AlphaOf(const std::vector<Channel> &group) {
    for (const Channel &ch : group)
        if (Upper(ch.suffix) == "A") return ch.index;
    return std::nullopt;
}

}  // namespace

bool IsOwnLayerName(std::string_view name) {
    return IsOwnName(name);
}

std::vector<LayerChannels> GroupChannels(const std::vector<std::string> &channelNames) {
    std::set<std::string> seen;
    for (const std::string &name : channelNames)
        if (!seen.insert(name).second)
            throw Error(fmt::format("channel name '{}' appears more than once", name),
                        ErrorKind::InvalidArgument);

    // Split the names: Bin_NNNN, unprefixed, and "<prefix>.<suffix>" grouped by prefix in
    // the order prefixes first appear.
    std::vector<std::pair<long, int>> bins;
    std::map<std::string, int> plain;  // unprefixed name -> channel
    std::vector<std::string> prefixes;
    std::map<std::string, std::vector<Channel>> groups;
    for (int i = 0; i < int(channelNames.size()); ++i) {
        const std::string &name = channelNames[i];
        size_t dot = name.rfind('.');
        if (dot == std::string::npos) {
            std::optional<long> bin;
            if (name.rfind("Bin_", 0) == 0) bin = ParseIndex(std::string_view(name).substr(4));
            if (bin)
                bins.push_back({*bin, i});
            else
                plain[name] = i;
            continue;
        }
        std::string prefix = name.substr(0, dot);
        if (!groups.count(prefix)) prefixes.push_back(prefix);
        groups[prefix].push_back({name.substr(dot + 1), i});
    }

    std::vector<Candidate> candidates;
    if (!bins.empty())
        candidates.push_back({{"hist", kOwnPriority},
                              "hist",
                              "the Bin_* channels",
                              OrderBins(bins, channelNames)});

    // Unprefixed R,G,B make color; a lone Y is a grey color. Their A is the frame's alpha,
    // kept so that a denoised image can carry it on (compositors and OIDN expect it).
    std::vector<int> rgb;
    for (const char *c : {"R", "G", "B"})
        if (auto it = plain.find(c); it != plain.end()) rgb.push_back(it->second);
    bool hasY = plain.count("Y") > 0;
    if (!rgb.empty() || hasY) {
        bool grey = rgb.empty();
        candidates.push_back({{"color", kOwnPriority},
                              "",
                              grey ? "channel Y" : "channels R,G,B",
                              grey ? std::vector<int>{plain["Y"]} : rgb});
        if (auto it = plain.find("A"); it != plain.end())
            candidates.push_back({{"alpha", kOwnPriority}, "A", "channel A", {it->second}});
        for (const char *c : {"R", "G", "B", "A"}) plain.erase(c);
        if (grey) plain.erase("Y");
    }
    // Other unprefixed channels (spp, depth, pbrt-v4's u, v, ...) are layers of one.
    for (const std::string &name : channelNames)
        if (auto it = plain.find(name); it != plain.end())
            candidates.push_back({{name, IsOwnName(name) ? kOwnPriority : kUnknownPriority},
                                  name,
                                  fmt::format("channel {}", name),
                                  {it->second}});

    for (const std::string &prefix : prefixes) {
        Target target = Resolve(prefix);
        if (target.name.empty()) continue;  // channels with nothing for us (pbrt-v4 P)
        bool known = target.priority > kUnknownPriority;
        candidates.push_back({target, prefix, fmt::format("channels {}.*", prefix),
                              OrderChannels(groups[prefix], known)});
        // A renderer's colour pass with alpha (Blender's Combined.A: film transparency)
        // gives the frame's alpha, by the colour's priorities (an unprefixed A first).
        if (target.name == "color")
            if (std::optional<int> a = AlphaOf(groups[prefix]))
                candidates.push_back({{"alpha", target.priority},
                                      "",
                                      fmt::format("channel {}.A", prefix),
                                      {*a},
                                      true});
    }

    // Hand out names by priority, ties to the set that came first in the file.
    std::stable_sort(candidates.begin(), candidates.end(),
                     [](const Candidate &a, const Candidate &b) {
                         return a.target.priority > b.target.priority;
                     });
    std::map<std::string, std::string> owner;  // layer -> what made it
    std::vector<LayerChannels> layers;
    for (Candidate &candidate : candidates) {
        std::string name = candidate.target.name;
        if (owner.count(name)) {
            if (candidate.optional) continue;
            if (candidate.ownName.empty() || owner.count(candidate.ownName))
                throw Error(fmt::format("{} and {} both make layer '{}'", owner[name],
                                        candidate.what, name),
                            ErrorKind::InvalidArgument);
            name = candidate.ownName;
        }
        owner[name] = candidate.what;
        layers.push_back({name, std::move(candidate.channels)});
    }
    return layers;
}

std::vector<std::string> ChannelNamesOf(const std::string &layer, int channelCount) {
    if (layer.empty()) throw Error("a layer needs a name", ErrorKind::InvalidArgument);
    if (channelCount < 1)
        throw Error(fmt::format("layer '{}' has {} channels", layer, channelCount),
                    ErrorKind::InvalidArgument);

    std::vector<std::string> names;
    if (layer == "hist") {
        if (channelCount < 4 || (channelCount - 1) % 3 != 0)
            throw Error(
                fmt::format(
                    "layer 'hist' has {} channels; expected 3n+1 (n bins for each of R,G,B, "
                    "then the sample count)",
                    channelCount),
                ErrorKind::InvalidArgument);
        for (int bin = 0; bin < channelCount; ++bin)
            names.push_back(fmt::format("Bin_{:04d}", bin));
    } else if (channelCount == 3) {
        const char *suffixes = layer == "normal" ? "XYZ" : "RGB";
        for (int c = 0; c < 3; ++c)
            names.push_back(layer == "color" ? std::string(1, suffixes[c])
                                             : layer + "." + suffixes[c]);
    } else if (channelCount == 1) {
        if (layer == "color")
            names.push_back("Y");
        else if (layer == "alpha")
            names.push_back("A");
        else if (layer == "depth")
            names.push_back("depth.Z");
        else
            names.push_back(layer + ".Y");
    } else {
        for (int c = 0; c < channelCount; ++c) names.push_back(fmt::format("{}.{}", layer, c));
    }
    return names;
}

}  // namespace mcd::io
