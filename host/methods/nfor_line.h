// nfor's line spread (beyond the papers): a glossy object's highlight line one pixel wide,
// reflecting a small bright light, is drawn by a plain frame's few samples as hits with
// gaps. The firefly clamp takes most of each hit's light (a hit is far above its 8
// neighbours), and the fits cannot give it back: the line comes out broken and too dark.
// Near a light (a pixel within gateReach of an albedo channel above lightAlbedo), a pixel
// whose clamp removed light and which lies on a line (the clamped luminance along the
// structure tensor's line direction above ratio x the luminance across it) shares that
// light over the line: tent-weighted steps along it, a narrow Gaussian across, each target
// weighted by the clamped luminance averaged along its own line. A pixel then receives at
// most up to the input's luminance averaged along its line (the cap): light the frame does
// not show there is dropped, not placed. Runs last, after the lights' spread, on the output,
// the colour and the clamped colour as written; a pixel of alpha 0 (or NaN) neither gives
// nor receives. Works in one window per group of lights (their reach about them), so that
// its cost follows the lights' surroundings, not the frame.
#pragma once

#include <cstddef>

#include "host/image.h"

namespace mcd {

// How far the pass reads from a pixel it writes (the tensor's smoothing, the spread along
// the line, the weights' and the cap's line means).
constexpr int kNforLineReach = 24;

struct NforLineSettings {
    float lightAlbedo = 8;  // a light: its largest albedo channel above this; 0: off
    int gateReach = 4;      // pixels within this (Chebyshev) of a light may give
    double ratio = 3;       // the line test: along > ratio x across
    int radius = 4;         // steps along the line a pixel's light is shared over
};

struct NforLineStats {
    size_t givers = 0;   // pixels whose clamped light was shared along their line
    double moved = 0;    // the luminance they shared
    double dropped = 0;  // the luminance the cap dropped
};

// Whether the pass has work on a frame: some albedo channel above lightAlbedo (> 0).
bool NforLineSpreads(const Image &albedo, float lightAlbedo);

// Adds to `output` the light `color` lost to `clamped` (max(color - clamped, 0) per channel)
// at the line pixels near a light (by `albedo`), shared along their lines and capped, as the
// header says. Every sum in a fixed order: two runs give the same bits. Touches nothing when
// no albedo channel exceeds settings.lightAlbedo.
NforLineStats NforSpreadLine(const Image &color, const Image &clamped, const Image &albedo,
                             const Image *alpha, const NforLineSettings &settings,
                             Image *output);

}  // namespace mcd
