// nfor's lights spread (beyond the papers): on a plain frame a light's rim is sampled by few
// of its samples. Where none hit it, a pixel next to a light keeps the dark surface
// behind it, while the reference's pixel filter gives it a share of the light; where one
// did, the light's own pixel is brighter than its coverage. Each emitter pixel gives a share
// of its output to each of its 4 neighbours that is no emitter, and keeps the rest: the
// frame's light stays, and a light's rim is no longer a hard edge against the dark. It runs
// on the output as written (premultiplied by alpha where the frame has one), and a pixel the
// renderer left fully transparent, which the frame's colour replaces afterwards, takes no
// part: light given to it would be lost. A weak emitter (a partly covered pixel, a moving
// light's streak) gives a larger share than a strong one, whose light is far above its
// rim's.
#pragma once

#include <cstddef>

#include "host/image.h"

namespace mcd {

struct NforLightSettings {
    float emitterAlbedo = 1.5f;  // an emitter: its largest albedo channel above this
    float weakAlbedo = 8;        // a weak emitter: its largest albedo channel below this
    // The share of its output an emitter gives to each neighbour that is no emitter.
    float weakShare = 0.08f, strongShare = 0.004f;
};

// Each emitter pixel p (by `albedo`) with finite output gives share x its output, every
// channel, to each of its 4 neighbours inside the frame that is no emitter, and loses what
// it gives; every value read on the output as it came in. Where `alpha` is given, a pixel
// of alpha 0 (or NaN) neither gives nor receives. Returns how many emitter pixels gave light.
size_t NforSpreadLights(const Image &albedo, const Image *alpha,
                        const NforLightSettings &settings, Image *output);

// nfor's rim hits (beyond the papers): at a light's rim a pixel that one or two of a
// frame's samples hit reads the light's radiance times their share (1/16 of it at 16 spp),
// where the reference's pixel filter leaves it a small part of that. relMSE charges such a
// pixel many times the frame's mean error, PSNR nothing (both display as white). An emitter
// pixel whose largest albedo channel is at most 1/coreRatio of an emitter's within radius
// (Chebyshev; the light's core) is scaled down to the geometric mean of its input and the
// median input of its 8 neighbours that are no emitter (channel means), and the light it
// loses goes to that core, each core pixel by its share of the core's output, channel by
// channel: the frame's light stays, on the pixels where the light is.
struct NforRimSettings {
    float emitterAlbedo = 1.5f;  // an emitter: its largest albedo channel above this
    float coreRatio = 0;         // the core's albedo over the rim pixel's, at least; 0: off
    int radius = 2;              // how far the core is looked for
};

// The rim pixels the pass takes are those that at most this many of the frame's samples hit:
// coreRatio is the frame's samples per pixel over it.
constexpr int kNforRimHits = 2;

// The core ratio of a frame of `spp` samples per pixel for pixels that at most `hits` of them
// hit; 0 (off) where that is under 4: a pixel covered by a quarter of the light or more is
// the light's edge itself, which few samples at 4 spp cannot tell from a rim.
inline float NforRimRatio(int spp, int hits) {
    const float ratio = hits > 0 ? float(spp) / float(hits) : 0.f;
    return ratio >= 4 ? ratio : 0.f;
}

// The rim hits on `output` (as written), `color` the frame's colour as written; every value
// read as it came in. Where `alpha` is given, a pixel of alpha 0 (or NaN) takes no part. A
// pixel with a non-finite output neither gives nor takes. Returns how many pixels gave light.
size_t NforFoldRimHits(const Image &color, const Image &albedo, const Image *alpha,
                       const NforRimSettings &settings, Image *output);

}  // namespace mcd
