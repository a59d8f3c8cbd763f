// The samples per pixel a frame states in its metadata: what accumulate checks its frames
// by and what nfor's rim hits read a hit's share of a light from.
#pragma once

#include <map>
#include <string>

namespace mcd {

// The samples per pixel a frame's metadata states (our renderer's mcd:spp, Cycles'
// cycles.<view layer>.samples, pbrt's samplesPerPixel), or 0 when it states none.
int SppFromMetadata(const std::map<std::string, std::string> &metadata);

}  // namespace mcd
