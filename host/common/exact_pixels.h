// Pixels a frame knows exactly (beyond the papers). A pixel-channel whose variance of the mean
// is 0 while its value is finite and above 0 had every sample equal and not black: an emitter
// or the environment seen directly. A filter that averages it with its neighbours can only
// move it away from its value; worse, a bright neighbour's energy spread into a dim, exact
// light (a small light's rim, a point inside an emitter) costs far more relative error than it
// saves. awr and rhf give such values back after they run. Zero values with zero variance stay
// the method's: at a few samples every sample of a dim pixel can be 0 without the pixel being
// 0.
#pragma once

#include <cstddef>

#include "host/image.h"

namespace mcd {

// Set `output` to `input` where `variance` (one channel for all, or the input's channels) is
// exactly 0 and the input finite and > 0; returns how many values were set. A variance of
// another size keeps nothing. With reach > 0 the energy the method had moved into an exact
// value (output - input there) goes back to where it came from: to the other values of its
// channel within the square of radius `reach` around it that the method had lowered, in
// proportion to how much (and energy it had taken out, to those it had raised); no value is
// given back more than it lost (or took), so none passes its input.
size_t KeepExactPixels(const Image &input, const Image &variance, Image *output, int reach = 0);

// The variance of the pixel mean a frame's layers tell: `variance`, else (max - min)^2 / spp
// from the sample range (zero exactly where every sample was equal), else empty.
struct ExactLayers {
    const Image *variance = nullptr, *min = nullptr, *max = nullptr, *spp = nullptr;
};
Image ExactVariance(const ExactLayers &layers);

}  // namespace mcd
