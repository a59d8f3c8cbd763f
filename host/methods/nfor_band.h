// nfor's glint bands (beyond the papers): on a frame without a variance layer, near a glint
// (a renderer that writes a reflected light into the albedo, as Cycles does) the albedo is
// noise and the features cannot explain a glossy highlight's band: the fits leave it as the
// samples' hits and misses along it, a broken line where the band is smooth. Here each pixel
// within the glints' reach takes, by the coherence of its structure tensor, the mean of the
// output along its line (the tensor's direction of least change), emitters left out.
#pragma once

#include "host/image.h"

namespace mcd {

struct NforGlintBandSettings {
    int radius = 3;              // samples along the line each side of the pixel (0: off)
    float sigma = 1.5f;          // their Gaussian's scale in pixels
    float tensorSigma = 1.5f;    // the structure tensor's Gaussian
    float bound = 2;             // a sample's luminance held within [Y / bound, Y bound + 0.01]
    float glintAlbedo = 8;       // an albedo channel above this is a glint
    int reach = 16;              // the pass runs within this (Chebyshev) of a glint
    float emitterAlbedo = 1.5f;  // an albedo channel above this: an emitter, left out
};
// What a tiled run's halo holds for the pass: the glints' reach, beyond the tensor's and the
// samples' (radius + 1, so a radius of at most kNforGlintBandReach - 1).
constexpr int kNforGlintBandReach = 16;

// Within settings.reach of a pixel of `albedo` with a channel above glintAlbedo, each pixel
// of `output` that is no emitter moves towards the Gaussian-weighted mean of the output sampled
// (bilinearly) along its line, by the coherence ((l1 - l2) / (l1 + l2))^2 of the structure
// tensor of log(luminance + 0.01), each sample weighted by the share of its footprint that is
// no emitter and not empty (`alpha` 0, where given) and its colour scaled so that its
// luminance Y' lies within [Y / bound, Y x bound + 0.01] for the pixel's Y (a sample with Y'
// <= 0 counts as black). Empty pixels and those with a non-finite value do not move; a
// sample with one in its footprint is left out. Reads the output as it came in. Returns how
// many pixels moved; 0 leaves `output` as it was, bit for bit.
size_t NforSmoothGlintBands(const Image &albedo, const Image *alpha,
                            const NforGlintBandSettings &settings, Image *output);

}  // namespace mcd
