// Values a filter kept at their input beside other ids, held to the range of their filtered
// neighbours (host/common/kept_edges.h), the CPU reference.
#pragma once

#include <cstddef>

#include "host/image.h"

namespace mcd::ref {

// A value a filter wrote, never its input but for 0: where it equals a nonzero input and is
// finite, the next float away from zero (the largest finite magnitude steps toward zero); a
// zero on an input of zero (+0 or -0) is the input itself, kept. Kept values are told by
// equality, and a filtered value that rounds onto its input would count as kept on one side
// of a GPU/CPU comparison only.
float FilteredValue(float value, float input);

// A value is kept where output and input are the same float. Each kept, finite value of a
// pixel with a 4-neighbour of other (objectId, partId) becomes the nearest value of [min,
// max] over the finite, not kept values of its channel at the other pixels of its 3x3
// window, where those include one of the pixel's own ids and one of others. Where they do not
// (a part at most two pixels wide, or a side kept whole), the range also spans, over the
// other pixels of its own ids in its 5x5 window whose output is finite, the lower of the
// upper median of their outputs and (where the pixel's pivot is above 0) the pixel's pivot
// times the upper median of output / pivot over those whose pivot is above 0, and every
// finite value of other ids in its 3x3 window, kept or not; without such pixels the value
// stays.
// Returns how many values changed.
size_t ClampKeptEdgeValues(const Image &input, const Image &pivot, const Image *objectId,
                           const Image *partId, Image *output);

// At a pixel with a 4-neighbour of other (objectId, partId) and a pivot above 0, a finite
// value not equal to its input has its z = value / pivot clamped to [lo, hi] and becomes z
// times its pivot: over the other pixels of its 5x5 window without such a neighbour, with a
// pivot above 0 and a finite value not equal to their input (where those include one of the
// pixel's own ids and one of others), lo and hi are the least and the largest value / pivot,
// widened to the upper median of input / pivot (finite) over the window's pixels of its own
// ids with such a neighbour and a pivot above 0, itself included. Returns how many values
// changed.
size_t ClampEdgeFitsToSides(const Image &input, const Image &pivot, const Image *objectId,
                            const Image *partId, Image *output);

}  // namespace mcd::ref
