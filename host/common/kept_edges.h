// Values a filter kept at their input beside other ids, held to the range of their filtered
// neighbours (beyond the papers). pivot keeps a pixel beside other ids at its input where it
// mixes in a side far from its own (shaders/pivot/ratio.comp): its fits would lift or lose
// the other side's light. Kept, its noise stays, a sparse line of light and dark dots along
// the edge (a room's ceiling edge). Its true value lies between the two sides' values around
// it, so the input is clamped to the range of the filtered values in its 3x3 window, of its
// own ids and of the others. A value without filtered neighbours of both kinds (a part at most
// two pixels wide, whose every pixel is kept) stays as it is.
#pragma once

#include <cstddef>

#include "host/image.h"

namespace mcd {

// For each value of `output` equal to `input`'s (bit for bit: kept) at a pixel with a
// 4-neighbour of another object or part id (`objectId`, `partId`: one channel each, or null),
// the range of the other values of its channel in its 3x3 window (clipped to the image) that
// are not kept and finite; where that range has values of the pixel's own ids and of others,
// the value is clamped to it.
struct KeptEdges {
    size_t clamped = 0;  // values moved
    size_t alone = 0;    // kept values without filtered neighbours of both kinds: left
};
KeptEdges ClampKeptEdgeValues(const Image &input, const Image *objectId, const Image *partId,
                              Image *output);

}  // namespace mcd
