// CPU reference of the lone pivot spikes' scaling (host/common/pivot_spikes.h): a pixel whose
// pivot is a firefly of its own (an albedo that followed a mirror to a light in one of a few
// samples) takes its filtered z times its neighbours' pivot.
#pragma once

#include <cstddef>
#include <vector>

#include "host/image.h"

namespace mcd::ref {

// s(p): the pivot's channels summed at p. A pixel whose s and its 8 neighbours' (within the
// image) are all finite, with s over 16 x m, m the lower middle of the sorted neighbours' s,
// at most one neighbour's s over 16 x m, and whose colour sum C > 0 and summed variance V
// (a one-channel variance counted once per colour channel; every value finite, >= 0) have
// sqrt(V) >= 0.25 C: each channel c whose output differs from its colour and whose pivot
// P_c(p) > 0 becomes output x m_c / P_c(p), m_c the lower middle of the neighbours' P_c.
// Returns the pixels changed (y * width + x, ascending).
std::vector<size_t> ScalePivotSpikes(const Image &color, const Image &pivot,
                                     const Image &variance, Image *output);

// With s and m as above: a pixel whose s and its neighbours' are finite, s over 16 x m (m >
// 0) and 2 or more neighbours' s over 16 x m, and whose neighbours with s at most 16 x m
// all have its object id and part id (each layer given; one channel each, or null), takes
// its colour in each channel where that is finite. Returns the pixels changed (ascending).
std::vector<size_t> KeepPivotSpikeClusters(const Image &color, const Image &pivot,
                                           const Image *objectId, const Image *partId,
                                           Image *output);

}  // namespace mcd::ref
