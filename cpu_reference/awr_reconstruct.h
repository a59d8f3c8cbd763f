// AWR wavelet reconstruction (Overbeck et al., section 4.2), the CPU reference: the soft
// shrinkage of eq. 11 written as a plain loop, and the whole reconstruction composed from
// the wavelet references.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "host/image.h"
#include "host/params/awr.h"
#include "host/wavelet.h"

namespace mcd::ref {

// W = sign(W~) max(0, |W~| - cs sqrt(var)) on every coefficient outside the top-left
// lowWidth x lowHeight band.
Image AwrShrink(const Image &coefficients, const Image &variance, int lowWidth, int lowHeight,
                double cs);

// Analysis of `color`, squared-filter analysis of `variance` (squared 1D filters summing
// to lowSum / highSum), shrinkage, synthesis.
Image AwrReconstruct(const Image &color, const Image &variance, WaveletBasis basis, int levels,
                     double cs, double lowSum, double highSum);

// Cycle spinning: the mean of AwrReconstruct over the shifts (dx, dy) in [0, spins)^2, each
// of the image and variance padded on the left by dx and on top by dy with their mirror
// image (-k-1 -> k), reconstructed with the same `levels`, and cropped back.
Image AwrReconstructSpun(const Image &color, const Image &variance, WaveletBasis basis,
                         int levels, double cs, double lowSum, double highSum, int spins);

// The whole method as `mcdenoise diff` compares it (both squared filters renormalised to
// params.renorm; the parameters taken as doubles). With `stages`, also the images the GPU
// run keeps (host/methods/awr.h), by the same names: "analysis", "variance analysis",
// "shrinkage", "synthesis" (of the unshifted image), and "cycle spinning" (the output) when
// spins > 1. Where the GPU run is idle (no variance anywhere, cs 0, 0 levels) the output is
// the input and there are no stages.
Image AwrReconstruct(const Image &color, const Image &variance, const AwrParams &params,
                     std::vector<std::pair<std::string, Image>> *stages = nullptr);

}  // namespace mcd::ref
