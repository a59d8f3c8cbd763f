// nfor's emitters: renderers write a light's emission as its albedo (a reflectance is at
// most about 1), so a pixel whose largest albedo channel exceeds a threshold is a light.
#pragma once

#include <algorithm>
#include <cstddef>

#include "host/image.h"

namespace mcd {

// The largest channel of `albedo` at pixel i, taken in channel order.
inline float NforLargestAlbedo(const Image &albedo, size_t i) {
    float most = albedo.Plane(0)[i];
    for (int c = 1; c < albedo.channels; ++c) most = std::max(most, albedo.Plane(c)[i]);
    return most;
}

}  // namespace mcd
