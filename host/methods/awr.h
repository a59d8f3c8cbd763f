// Method `awr`: Adaptive Wavelet Rendering's reconstruction (Overbeck et al., section 4.2)
// on the GPU. The noisy image's DWT, the squared-filter DWT of its per-pixel variance
// (eq. 10: the variance of every coefficient), soft shrinkage of the details by cs times
// the coefficients' standard deviation (eq. 11), synthesis.
#pragma once

#include <string>
#include <vector>

#include "host/image.h"
#include "host/methods/staged_run.h"
#include "host/vk/context.h"
#include "host/vk/recorder.h"
#include "host/wavelet.h"

namespace mcd {

struct AwrOptions {
    WaveletBasis basis = WaveletBasis::Cdf97;
    int levels = -1;  // -1: as many as the image allows
    float cs = 1.f;   // smoothing constant
    // The squared 1D filters are renormalised to sum to these (the paper: 2^-1/2 for the
    // reconstruction, to damp coarse-scale smoothing).
    float lowSum = 0.70710678f, highSum = 0.70710678f;
    // Cycle spinning over spins x spins shifts (host/common/cycle_spin.h), 1 to 8; 1 is
    // the paper's reconstruction. Beyond the paper: the decimated DWT's soft shrinkage
    // depends on where its grid falls, and the mean over shifts removes that (README).
    int spins = 1;
    // Download every stage's buffer (for `mcdenoise diff`): one submission per stage, and
    // the shrinkage as a pass of its own (else it is fused into the synthesis).
    bool keepStages = false;
};

// With keepStages, stages "analysis", "variance analysis", "shrinkage", "synthesis" (the
// output), each the full-size buffer after its stage; empty when nothing ran. With spins >
// 1 these are the unshifted run's, then "cycle spinning" (the output). No warnings.
using AwrResult = MethodResult;

// Per-pixel variance of the mean from the sample range (AWR section 4.2: the functional
// variance (Imax - Imin)^2 over the pixel's N samples).
Image AwrVarianceFromRange(const Image &min, const Image &max, const Image &spp);

// Denoise `color` with per-pixel variance of the mean `variance` (same size and channels).
// Throws mcd::Error naming the first offending pixel when either holds NaN/Inf or the
// variance is negative.
AwrResult AwrReconstruct(vk::Context &context, const Image &color, const Image &variance,
                         const AwrOptions &options);

}  // namespace mcd
