// Values a filter kept at their input beside other ids, held to the range of their filtered
// neighbours (beyond the papers). pivot keeps a pixel beside other ids at its input where it
// mixes in a side far from its own (shaders/pivot/ratio.comp): its fits would lift or lose
// the other side's light. Kept, its noise stays, a sparse line of light and dark dots along
// the edge (a room's ceiling edge). Its true value lies between the two sides' values around
// it, so the input is clamped to the range of the filtered values in its 3x3 window, of its
// own ids and of the others. Where a value lacks filtered values of both kinds around it (in
// a part at most two pixels wide, a wire, a fence's mesh, a blade of grass, every pixel is
// kept; beside a side kept whole, a light or alpha-0 pixels, that side has none), the range
// also takes its own ids' level within 2 pixels (along the part): the lower
// of their values' median and its pivot times their ratios' to the pivot (its coverage and
// texture), so a value no sample lit, or a firefly, does not stand out of its line as a dot;
// and the other ids' values around it, kept ones too, so a light's rim seen as the wall keeps
// the light's share.
#pragma once

#include <cstddef>

#include "host/image.h"

namespace mcd {

// A value a filter wrote, never its input but for 0: where it equals a nonzero input and is
// finite, the next float away from zero (the largest finite magnitude steps toward zero). The
// passes after a filter tell the values it kept by equality, and one that rounds onto its
// input would count as kept on the GPU or in the CPU twin alone. A zero on an input of zero
// (+0 or -0) becomes the input itself, kept: both sides fit 0 exactly where every z around
// is 0, and a black channel stays black. shaders/pivot/fitted.glsl is its kernels' copy.
float FilteredValue(float value, float input);
// FilteredValue on every value of `output` against the same value of `input` (its shape):
// for a filter whose kernels see another colour than the one its restore compares with (rhf
// reads its spikes and rims cut).
void MarkFiltered(const Image &input, Image *output);

// For each value of `output` equal to `input`'s (bit for bit: kept) at a pixel with a
// 4-neighbour of another object or part id (`objectId`, `partId`: one channel each, or null),
// the range of the other values of its channel in its 3x3 window (clipped to the image) that
// are not kept and finite; where that range has values of the pixel's own ids and of others,
// the value is clamped to it. Where it lacks either kind, the range also spans the level of
// the other pixels of its own ids in its 5x5 window whose output is finite: the lower of the
// upper median of their outputs and, where the pixel's `pivot` is above 0, that pivot times
// the upper median of output / pivot over those whose pivot is above 0, and every finite
// value of other ids in its 3x3 window, kept or not; without such pixels the value is left.
struct KeptEdges {
    size_t clamped = 0;  // values moved
    // Of those, values without filtered neighbours of both kinds (a thin part, or a side
    // kept whole around them).
    size_t thin = 0;
    size_t alone = 0;  // thin values without a pixel of their own ids within 2: left
};
KeptEdges ClampKeptEdgeValues(const Image &input, const Image &pivot, const Image *objectId,
                              const Image *partId, Image *output);

// Filtered values beside other ids held between their two sides (beyond the papers). A pixel
// beside other ids is no fit centre; it gathers its own ids' planes from beyond it, and where
// those extrapolate it can come out far darker or brighter than both sides (a cabinet's
// outline dotted black on a sunlit room). With an albedo-like pivot a pixel that mixes two
// sides has its z = value / pivot between theirs; an outline of its own (a glass's dark
// silhouette) is not, and the inputs along it say so. For each filtered value (not equal to
// its input) at a pixel with a 4-neighbour of other ids and a pivot above 0: [lo, hi], min
// and max of output / pivot over the pixels of its 5x5 window (clipped to the image) that
// have no 4-neighbour of other ids, a pivot above 0 and a finite output not equal to their
// input, where those hold a pixel of its own ids and one of others, widened to the upper
// median of input / pivot over the pixels of its own ids beside other ids in that window
// (itself too) whose pivot is above 0 and ratio finite (its outline's level, which one
// unlucky input does not move); its z is clamped to that range, times its pivot. Returns
// how many values moved.
size_t ClampEdgeFitsToSides(const Image &input, const Image &pivot, const Image *objectId,
                            const Image *partId, Image *output);

}  // namespace mcd
