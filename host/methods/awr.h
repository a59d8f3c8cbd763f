// Method `awr`: Adaptive Wavelet Rendering's reconstruction (Overbeck et al., section 4.2)
// on the GPU. The noisy image's DWT, the squared-filter DWT of its per-pixel variance
// (eq. 10: the variance of every coefficient), soft shrinkage of the details by cs times
// the coefficients' standard deviation (eq. 11), synthesis.
#pragma once

#include <string>
#include <vector>

#include "host/image.h"
#include "host/methods/run_setup.h"
#include "host/methods/staged_run.h"
#include "host/params/awr.h"
#include "host/vk/context.h"
#include "host/vk/recorder.h"
#include "host/wavelet.h"

namespace mcd {

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
                         const AwrParams &params, const RunSetup &setup = {});

}  // namespace mcd
