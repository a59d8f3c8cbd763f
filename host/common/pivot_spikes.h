// Pixels whose pivot is a lone spike (beyond the papers). The pivot stands for a noise-free
// image of the frame's structure, but a renderer's albedo follows a mirror to what it
// reflects, a light's emission included: a pixel one of whose few samples saw a small light
// in a chrome sphere carries the firefly in its albedo as in its colour. Its z = colour /
// pivot is then its neighbours', and the filter's output, the fitted z times the pivot, gives
// the firefly back whole. Such a pixel takes its fitted z times its neighbours' pivot. A
// light seen directly, or a highlight most samples saw, is steady in its colour and stays.
#pragma once

#include <cstddef>
#include <vector>

#include "host/image.h"

namespace mcd {

// A lone spike of the pivot: its channels summed over kPivotSpike times the median of its 8
// neighbours' (within the image, at least one; the lower middle of an even count; above 0),
// fewer than 2 of them so, every value finite. One whose colour (channels summed, above 0) has
// a standard deviation (`variance` of the pixel mean, 1 or the colour's channels, summed; every
// value finite and not negative) of at least kPivotSpikeNoise of it is a few samples' firefly.
constexpr double kPivotSpike = 16, kPivotSpikeNoise = 0.25;

// Each such pixel's output, where it is not its input (a value the filter kept), scaled per
// channel by its neighbours' median pivot over its own (of that channel, or the pivot's one
// channel; where its own and the median are above 0). Returns the pixels scaled (y * width + x,
// ascending).
std::vector<size_t> ScalePivotSpikes(const Image &color, const Image &pivot,
                                     const Image &variance, Image *output);

// Pixels whose pivot is a spike with 2 or more of its 8 neighbours so too (a light seen in a
// mirror by a few pixels: the albedo followed the mirror to it) hold no surface the fits
// around them describe: their fits cut the light, and the restore of local means gave it
// back spread over its tents, a halo round the reflection. Each keeps its input (finite
// channels), which the restore leaves, where its neighbours not over kPivotSpike times the
// median (the dark ones) all have its ids (`objectId`, `partId`: one channel each, or null;
// each present): a reflection has its mirror's ids, while a thin bright part (a wire, a
// small bright patch of its own id) would keep its noisy input. Returns the pixels changed
// (ascending).
std::vector<size_t> KeepPivotSpikeClusters(const Image &color, const Image &pivot,
                                           const Image *objectId, const Image *partId,
                                           Image *output);

}  // namespace mcd
