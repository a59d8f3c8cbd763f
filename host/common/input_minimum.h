// A reconstruction held above the lowest input value around each pixel (beyond the papers).
// A wavelet filter's synthesis filters have negative lobes: where it shrinks the details
// beside a bright, noisy pixel (a highlight's streak on a glossy surface, seen by few
// samples), the coarse bands it keeps ring into troughs around it, near-black spots (below 0)
// on a dim surface beside the light. An average of the samples near a pixel is no lower than
// the lowest of them; a value below every input value in its window is the filter's ringing,
// not the frame's light, and is raised to the lowest. Crests are left: above a pixel's
// window they are mostly a firefly's or a light's energy spread, which the frame keeps.
#pragma once

#include <cstddef>

#include "host/image.h"

namespace mcd {

// Raise each value of `output` to at least the minimum of `input`'s values of the same
// channel over the window of radius r around the pixel, clipped to the image. Values whose
// output or window has a value that is not finite are left. Returns how many values moved.
size_t RaiseToInputMinimum(const Image &input, int r, Image *output);

}  // namespace mcd
