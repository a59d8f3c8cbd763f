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

}  // namespace mcd
