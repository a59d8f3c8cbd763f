// Other renderers' conventions (README, "Frames from other renderers"): what their layers
// mean, converted into ours after the channel names are grouped (layer_names.h). Each
// conversion made is named in frame.metadata[kConventionKey], which `info` and
// `denoise --explain` print.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "mcdenoise/frame.h"

namespace mcd::io {

// The metadata key that says how a frame was read; absent for frames in our own names.
inline constexpr const char *kConventionKey = "mcd:convention";
// The metadata key naming the layer that holds the image a file shows when the frame's
// colour is a noisy colour kept beside a denoised result (Blender's Combined beside its
// Noisy Image; kDenoisedColorLayer beside kNoisyColorLayer); absent otherwise. Set on
// read, so a file's own value is dropped like its mcd:convention.
inline constexpr const char *kShownColorKey = "mcd:shownColor";

// Convert the layers of a frame just read: channelNames are the file's channel names,
// numbers its numeric header attributes (pbrt-v4's samplesPerPixel is an int).
// - Blender Cycles: direct/indirect composed from the light passes (Env left out where
//   Film > Transparent leaves the background out of Combined), Debug Sample Count (a
//   fraction of the samples) made spp when the total is in the metadata.
// - pbrt-v4 GBufferFilm: Variance.* (of the samples) divided by samplesPerPixel into
//   variance (of the mean); without samplesPerPixel it keeps its own name.
// - Mitsuba 3 moment integrator: m2_<name>.* and <name>.* (XYZ moments) make variance
//   when the sample count is known.
// A file's own mcd:convention is dropped: the layers it describes are ours by now.
// Whether a layer is one that the conventions compose `direct` and `indirect` from:
// Cycles' light passes kept under their names (DiffDir, GlossCol, Emit, Env, ...), and
// `alpha`, which says whether Env is part of Combined (not on Film > Transparent).
bool IsSplitSource(const std::string &layer);

void ApplyConventions(Frame &frame, const std::vector<std::string> &channelNames,
                      const std::map<std::string, double> &numbers);

}  // namespace mcd::io
