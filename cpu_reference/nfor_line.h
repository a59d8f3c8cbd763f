// nfor's line spread (host/methods/nfor_line.h), the CPU reference, in double, on the whole
// frame.
#pragma once

#include "host/image.h"

namespace mcd::ref {

// With L the Rec. 709 luminance of `clamped` (non-finite: 0), Ls its Gaussian of sigma 1 and
// J the Gaussians of sigma 3 of the products of Ls's central differences (one-sided at the
// ends; both mirrored at the frame's ends without repeating the end pixel), a pixel p gives
// when: a pixel within gateReach (Chebyshev) has an albedo channel above lightAlbedo; its
// alpha (where given) is above 0; r = max(color - clamped, 0) is finite and not all 0; J has
// structure (coherence above 0); and with a the minor eigenvector of J and n the major, the
// mean of Ls (bilinear, 0 outside) at p + t a, t in {-2, -1, 1, 2}, exceeds ratio x the mean
// at p +- 2 n. It gives r to the pixels q = round(p + t a + b n), t in -radius..radius, b in
// -1..1, inside the frame and of alpha above 0, in proportion to (radius + 1 - |t|) x
// exp(-b^2 / 0.98) x max(M(q), 0), M(q) the mean of max(L, 0) over q + t a(q), t in -2..2.
// Each pixel then takes of what it was given the share k = min(1, max(Min(q) - lum(out(q)),
// 0) / lum(given)), Min(q) the mean of the input's luminance the same way. Returns the
// number of pixels that gave.
int NforSpreadLine(const Image &color, const Image &clamped, const Image &albedo,
                   const Image *alpha, double lightAlbedo, int gateReach, double ratio,
                   int radius, Image *output);

}  // namespace mcd::ref
