// Cycle spinning (Coifman & Donoho): shift invariance for a method built on a decimated
// wavelet transform, by averaging it over spins x spins shifts of the image against the
// transform's grid. Shift (dx, dy) pads the image with its mirror image, dx columns on the
// left and dy rows on top, runs the method on that, and crops the padding off again.
#pragma once

#include <functional>

#include "host/image.h"

namespace mcd {

// `image` padded by dx columns on the left and dy rows on top with its mirror image
// (-k-1 -> k, clamped for images narrower than the shift).
Image MirrorPad(const Image &image, int dx, int dy);

// The mean over (dx, dy) in [0, spins)^2, row-major, of run(dx, dy) cropped back to
// width x height; run returns a (width + dx) x (height + dy) image with `channels`
// channels. Sums in double and divides once at the end.
Image CycleSpin(int width, int height, int channels, int spins,
                const std::function<Image(int dx, int dy)> &run);

}  // namespace mcd
