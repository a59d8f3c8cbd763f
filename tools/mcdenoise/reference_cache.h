// Converged references of the built-in scenes, rendered once and cached on disk under
// $XDG_CACHE_HOME/mcdenoise/references (else ~/.cache/...), keyed by scene, size, spp and
// renderer version, so tests, `render --reference` and the benchmarks share them.
#pragma once

#include <string>

#include "host/io/frame.h"

namespace mcd::tool {

// Where the reference of (scene, width x height, spp) is cached.
std::string ReferenceCachePath(const std::string &scene, int width, int height, int spp);

// The cached reference (its color, variance, spp, min and max layers), rendered with the
// reference seed on `threads` cores (0: all) and cached first when missing. `rendered` is
// set when it had to be rendered. A cache that cannot be written is reported, not fatal.
io::Frame CachedReference(const std::string &scene, int width, int height, int spp,
                          int threads = 0, bool *rendered = nullptr);

}  // namespace mcd::tool
