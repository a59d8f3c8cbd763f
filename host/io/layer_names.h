// Layer-name conventions (ARCHITECTURE.md, "Frames, layers and error"): how a file's channel
// names group into our layers, and the channel names each layer is written under. Pure
// string work, kept apart from the file I/O so the rules can be read in one place.
#pragma once

#include <algorithm>
#include <array>
#include <string>
#include <string_view>
#include <vector>

namespace mcd::io {

// One layer found in a file: our name for it and the file channels that make it, in the
// layer's channel order (R,G,B / X,Y,Z / histogram bins in numeric order).
struct LayerChannels {
    std::string name;
    std::vector<int> channels;
};

// Groups a file's channel names into layers. Unprefixed R,G,B (or a lone Y) make "color"
// and an unprefixed A beside them "alpha"; "<layer>.<suffix>" channels make "<layer>";
// Bin_NNNN channels make "hist"; names of other renderers (pbrt-v4, Blender, Mitsuba 3) are
// mapped where the mapping is plain. A renderer's colour pass with A (Blender's
// <view layer>.Combined.A) gives "alpha" when no unprefixed A does. Alpha inside another
// known prefixed RGB layer (albedo.A) and pbrt-v4's P.* are left out; every other channel
// lands in a layer.
// Throws mcd::Error (without a path: the caller adds it) on a malformed histogram, a
// repeated channel name or two sets of channels that both claim one layer name.
std::vector<LayerChannels> GroupChannels(const std::vector<std::string> &channelNames);

// Whether a layer name is one of ours (ARCHITECTURE.md's table, partial images included)
// rather than a renderer's pass kept under its own name.
bool IsOwnLayerName(std::string_view name);

// The layers that half0 may have its own of ("half0.<layer>": accumulated from half0's
// frames alone, for auto's runs on half0); half0.color is an own name of its own. Inline:
// the core library (auto, temporal) reads them without linking the file I/O library.
inline constexpr std::array<std::string_view, 14> kHalf0Layers = {
    "variance", "spp",    "min",    "max",   "hist",  "direct",          "indirect",
    "pivot",    "albedo", "normal", "depth", "alpha", "direct.variance", "indirect.variance"};

// "half0.<layer>" for a layer that accumulate also writes for half0 alone (the frames
// half0.color is the mean of): auto's runs on half0 read them in place of the frame's.
inline bool IsHalf0LayerName(std::string_view name) {
    if (!name.starts_with("half0.")) return false;
    return std::find(kHalf0Layers.begin(), kHalf0Layers.end(), name.substr(6)) !=
           kHalf0Layers.end();
}

// Those layers' names without the "half0." (variance, hist, albedo, normal, ...).
inline std::vector<std::string> Half0Layers() {
    return {kHalf0Layers.begin(), kHalf0Layers.end()};
}

// The channel names a layer of channelCount channels is written under: "color" -> R,G,B
// (Y when grey); "alpha" -> A; "normal" -> normal.X/Y/Z; other 3-channel layers -> x.R/G/B;
// "depth"
// -> depth.Z; other 1-channel layers -> x.Y; "hist" -> Bin_0000..; any other count ->
// x.0, x.1, ... GroupChannels maps these names back to the same layer.
std::vector<std::string> ChannelNamesOf(const std::string &layer, int channelCount);

}  // namespace mcd::io
