// Values a filter kept at their input beside other ids, held to the range of their filtered
// neighbours (host/common/kept_edges.h), the CPU reference.
#pragma once

#include <cstddef>

#include "host/image.h"

namespace mcd::ref {

// A value is kept where output and input are the same float. Each kept, finite value of a
// pixel with a 4-neighbour of other (objectId, partId) becomes the nearest value of [min,
// max] over the finite, not kept values of its channel at the other pixels of its 3x3
// window, where those include one of the pixel's own ids and one of others. Returns how many
// values changed.
size_t ClampKeptEdgeValues(const Image &input, const Image *objectId, const Image *partId,
                           Image *output);

}  // namespace mcd::ref
