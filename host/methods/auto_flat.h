// auto beside the half-buffers: where the frame is flat (no edge of the albedo or the normals,
// nor of the output's shading, within a pixel) and nfor's output agrees with the
// combination's, nfor's output. There the halves' estimate reads nfor's error high (the
// error both halves share, docs/methods/auto.md) and the combination mixes in the other
// candidates' specks and blotches. A frame where nfor holds less light there than the
// combination (its firefly clamp on a heavy-tailed frame) keeps the combination.
#pragma once

#include <cstddef>

#include "host/image.h"

namespace mcd {

struct AutoFlatSettings {
    // A feature edge: the albedo's and the normals' absolute forward differences, summed
    // over both directions and the channels, above this.
    float featureStep = 0.1f;
    // A shading edge: the absolute forward differences of log(mean channel + 0.01) of the
    // output, summed over both directions, above this.
    float shadingStep = 0.1f;
    // nfor agrees where its mean channel is within this share of |the output's| + 0.01.
    float agreement = 0.1f;
    // The least share of the output's light (the mean channels summed over the pixels taken)
    // that nfor must hold there.
    float keep = 0.995f;
};

struct AutoFlatResult {
    size_t pixels = 0;  // flat pixels where nfor agrees
    double light = 0;   // nfor's light there over the output's
    bool taken = false;
};

// Per pixel of `output` (3 or 4 channels, the first 3 colour) flat and agreeing, nfor's
// colour replaces the output's if nfor's light over those pixels is at least keep x the
// output's; alpha stays. `albedo` and `normal` have 3 channels, all images one size.
AutoFlatResult AutoTakeNforWhereFlat(const Image &albedo, const Image &normal,
                                     const Image &nfor, const AutoFlatSettings &settings,
                                     Image *output);

}  // namespace mcd
