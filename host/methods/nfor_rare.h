// nfor's rare light (beyond the papers): on a frame without a variance layer, a pixel that
// the firefly clamp cut far below its colour (under 1 / ratio) held a rare bright sample (one
// of its few that a glossy floor reflected from a light). Such hits lie scattered over a
// reflection's footprint with dark misses between them; the fits keep the misses, and the
// restore of the clamp's light, which takes each value's difference for its noise, gives
// little of their light back. Here a share of each such pixel's lost light, where another
// lies near it, is given to the pixels around it as a Gaussian, away from emitters and partly
// covered pixels (the clamp's light's reach), whose own light other passes place.
#pragma once

#include <vector>

#include "host/image.h"

namespace mcd {

struct NforRareLightSettings {
    float share = 0.4f;  // of the light the clamp took from a source, given around it
    float ratio = 40;    // a source's colour over its clamped colour (channels' sums)
    float sigma = 2;     // the Gaussian's scale in pixels
    int radius = 6;      // the Gaussian's reach (a square of 2 radius + 1), weights to sum 1
    // A source: a cut pixel with at least `others` more within `pair` (Chebyshev). A
    // reflection's footprint holds its hits close together; hits scattered thinly (a
    // caustic's over a whole floor) are each as lone as a firefly, and the Gaussian would
    // draw a blob at each.
    int pair = 6;
    int others = 2;
};
// What a tiled run's halo holds for the pass: the Gaussian's reach
// (NforRareLightSettings::radius) and the largest pairing distance (pair) it takes.
constexpr int kNforRareRadius = 6, kNforRarePair = 16;

// Each pixel of `output` not flagged in `near` (one flag per pixel: within the clamp's
// light's reach of an emitter or a partly covered pixel) receives share x the Gaussian
// (normalised over its full square, so that a tile's run gives the same bits) of the
// sources' lost light, per channel max(color - clamped, 0); a source is a pixel not in
// `near` whose channels' mean in `color` is positive and above ratio x that in `clamped`,
// with at least `others` more such pixels within `pair` (Chebyshev, at most kNforRarePair):
// a lone one is a firefly.
// Returns how many sources gave; 0 leaves `output` as it was, bit for bit.
size_t NforSpreadRareLight(const Image &color, const Image &clamped,
                           const std::vector<char> &near, const NforRareLightSettings &settings,
                           Image *output);

}  // namespace mcd
