// nfor's specks clamped (beyond the papers): a pixel far above all its neighbours whose
// fits weighed only itself (a sample that hit a sunlit wire under a pixel wide, its normal
// and albedo unlike the ground's: a glint no neighbour saw) comes out of the fits as bright
// as the firefly clamp left it, a speck where the reference spreads that light thinly over
// the wire around it. On a frame without a variance layer the fits' output at such a pixel
// is scaled down to a bound over its neighbours' outputs, before the local means are
// restored (host/common/local_mean.h, against the clamped colour), which give the pixels
// around it as much of its light as they hold for certain.
#pragma once

#include <vector>

#include "host/image.h"

namespace mcd {

struct NforSpeckSettings {
    float relative = 0.2f;  // bound: (1 + relative) x the rank-th brightest neighbour + floor
    float floor = 0.01f;
    // A pixel with this many bright neighbours or more (a line's, a highlight's) is kept.
    int rank = 2;
    // Where the neighbours' median is at least flatShare x the rank-th brightest (a speck
    // on a flat ground, no highlight's slope), the bound takes flatRelative; 0: off.
    float flatShare = 0;
    float flatRelative = 0.1f;
};

// Each pixel of `output` (mask 1, not on the frame's border, no emitter, mask 0, among its
// 8 neighbours) whose luminance (the mean of its channels) is above (1 + relative) n +
// floor, n the rank-th largest (1 to 8) luminance of its neighbours (flatRelative in place
// of relative where their 5th largest is at least flatShare x n), scaled by that bound over
// its luminance (its hue kept); every decision on the output as it came in. Returns how
// many pixels changed.
size_t NforClampSpecks(const Image &mask, const NforSpeckSettings &settings, Image *output);

// Pixels on an exact ground (beyond the papers), for a frame without a variance layer: a
// pixel (mask 1, not on the frame's border) that the firefly clamp left (`clamped` equal to
// `input` in every channel) and that differs from its 8 neighbours, whose input colours are
// all the same bit for bit, lit (a channel above 0) and no emitter (mask 1). Every sample
// of such a ground saw the same (a mirror's or a sky's constant colour), so the pixel's
// difference is no noise but its footprint's coverage of something small (a light seen in
// a mirror), which the fits and the local means would spread into a blotch. One flag per
// pixel.
std::vector<char> NforExactGround(const Image &input, const Image &clamped, const Image &mask);

// A lone sample: the layer's sigma at least the mean over sqrt(kNforLoneHits) (one sample
// of n holds a mean m with a sigma of the mean about m), the mean above kNforLoneRatio x its
// neighbours' median; isolated: no other lone sample within kNforLoneReach (a caustic's
// samples come in numbers).
constexpr double kNforLoneHits = 2, kNforLoneRatio = 4;
constexpr int kNforLoneReach = 15;

// A variance layer for the firefly clamp (beyond the papers): a firefly's few samples report
// its own variance in the layer, so a threshold of sigmas of it clamps nothing. At each
// isolated lone sample (above; the mean of the channels, colour and sigma alike) every
// channel of `variance` is capped at the lower median of its in-frame neighbours' values
// (non-finite ones skipped), so the clamp reads the quiet ground's noise there; a caustic's
// lone samples, near each other, keep theirs. A pixel whose neighbours' colour is the same
// bit for bit (an exact ground: every sample saw the same, so a light there is coverage)
// or whose neighbours' median is 0 is no lone sample. Returns the pixels capped; `capped`
// gets the capped layer where any was and is left as it is where none was (most frames: no
// copy of the layer).
size_t NforCapLoneSamples(const Image &variance, const Image &color, Image *capped);

}  // namespace mcd
