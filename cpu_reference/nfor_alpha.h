// nfor's partly covered pixels (host/methods/nfor_alpha.h), the CPU reference: a pixel
// whose alpha a satisfies 1e-3 <= a < 1 is the surface it shows times a; its values are
// divided by a (a^2 for a variance) before the method and its output multiplied by a after.
#pragma once

#include "host/image.h"

namespace mcd::ref {

// Whether alpha a marks a partly covered pixel: 1e-3 <= a < 1.
bool NforPartlyCovered(double a);

// `image` with every channel of each partly covered pixel (by `alpha`, one channel)
// divided by a^power, in double.
Image NforStraight(const Image &image, const Image &alpha, int power);

// `image` with every channel of each partly covered pixel multiplied by a, in double.
Image NforPremultiply(const Image &image, const Image &alpha);

}  // namespace mcd::ref
