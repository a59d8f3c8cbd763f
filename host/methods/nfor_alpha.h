// nfor on partly covered pixels (beyond the papers): a renderer with a transparent
// background (Cycles' Film > Transparent) writes the colour and every feature of a pixel
// the surface covers in part premultiplied by that coverage, alpha, the background adding
// nothing. Such a pixel's albedo, normal and depth are then far from the surface's, so the
// fits weigh few neighbours for it and it keeps most of its noise. Divided by its alpha it
// is the surface's own colour and features, mean of the samples that hit it: the fits weigh
// it with the surface around it, and its output is multiplied back.
#pragma once

#include "host/image.h"

namespace mcd {

// Pixels whose alpha is at least this and below 1 are divided (a pixel covered less keeps
// its values: they are next to nothing, and a division would blow them up).
constexpr float kNforMinAlpha = 1e-3f;

// Whether a pixel of this alpha is partly covered: in [kNforMinAlpha, 1).
inline bool NforPartlyCovered(float alpha) {
    return alpha >= kNforMinAlpha && alpha < 1.f;
}

// The number of pixels of `alpha` (one channel) in [kNforMinAlpha, 1).
size_t NforPartlyCovered(const Image &alpha);

// `image` (any channels, the size of alpha) with every channel of each such pixel divided
// by alpha^power (1 for colour and features, 2 for the colour's variance).
Image NforDivideByAlpha(const Image &image, const Image &alpha, int power = 1);

// Every channel of each such pixel of *image multiplied by its alpha.
void NforMultiplyByAlpha(const Image &alpha, Image *image);

}  // namespace mcd
