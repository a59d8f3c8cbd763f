// nfor's rare light (host/methods/nfor_rare.h), the CPU reference, in double.
#pragma once

#include <vector>

#include "host/image.h"

namespace mcd::ref {

// A cut pixel is one with near 0 whose colour's channel sum A and clamped colour's channel
// sum B satisfy A finite, A > 0 and A > ratio B; a source, a cut pixel with at least `others`
// more cut pixels within `pair` (Chebyshev). Each source scatters, per channel, share x g(dy)
// g(dx) x max(color - clamped, 0) to every pixel within `radius` (Chebyshev, inside the
// frame) with near 0, g the Gaussian of `sigma` over -radius..radius normalised to sum 1; the
// sums are added to `output` once per value. Returns how many sources gave.
size_t NforSpreadRareLight(const Image &color, const Image &clamped,
                           const std::vector<char> &near, double share, double ratio,
                           double sigma, int radius, int pair, int others, Image *output);

}  // namespace mcd::ref
