// Run the GPU wavelet transform on an image and bring the result back: one submit each.
#pragma once

#include "host/image.h"
#include "host/vk/context.h"
#include "host/wavelet.h"

namespace mcd::test {

Image GpuAnalyze(vk::Context &ctx, const Image &in, WaveletBasis basis, int levels);
Image GpuSynthesize(vk::Context &ctx, const Image &coefficients, WaveletBasis basis,
                    int levels);
Image GpuSqAnalyze(vk::Context &ctx, const Image &variance, WaveletBasis basis, int levels,
                   float lowSum, float highSum);

}  // namespace mcd::test
