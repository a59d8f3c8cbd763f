// Round trips of images through the GPU wavelet transform, for the CLI.
#pragma once

#include "host/image.h"
#include "host/vk/context.h"
#include "host/wavelet.h"

namespace mcd::tool {

struct WaveletRoundTrip {
    Image coefficients, reconstruction;
    double analysisMs = 0, synthesisMs = 0;  // GPU timestamps, summed over levels
};

WaveletRoundTrip RunWaveletRoundTrip(vk::Context &context, const Image &image,
                                     WaveletBasis basis, int levels);

}  // namespace mcd::tool
