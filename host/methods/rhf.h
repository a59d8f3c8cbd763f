// Method `rhf`: Ray Histogram Fusion (Delbracio et al., IPOL 2015) on the GPU, with the
// choices of the authors' tool where the paper leaves them open (issue #4). Per scale,
// coarse to fine: Gaussian downsampling of the colour and the histograms (count-preserving
// rescale), per-offset chi-square pixel terms, patch distances by box sums, kNN +
// threshold selection, gather aggregation; scales recombined as
// u_s - U(D(u_s)) + U(u_{s+1}) with bicubic U.
#pragma once

#include <string>
#include <vector>

#include "host/image.h"
#include "host/methods/run_setup.h"
#include "host/methods/staged_run.h"
#include "host/params/rhf.h"
#include "host/vk/context.h"
#include "host/vk/recorder.h"

namespace mcd {

// warnings: bad pixels found in the input, with counts. With setup.keepStages, stages coarse to
// fine: "color s<k>" (D_k of the colour, k >= 1), "filtered s<k>" (that scale's RHF),
// "combined s<k>" (the recombination, k below the coarsest); the last one is the output.
struct RhfResult : MethodResult {
    int scalesUsed = 0;
};

// Scales filtered: scale s >= 1 only while its image is at least the search window's size
// both ways; coarser scales would compare clamped windows of a handful of pixels.
int RhfScalesUsed(int width, int height, const RhfParams &params);

// The count-preserving rescale of the histograms at scales 1..scales-1 (index s; index 0
// holds 1) that RhfDenoise computes on this frame, NaN/Inf/negative bins taken as 0 as it
// does, without copying the histograms.
std::vector<float> RhfHistScales(const Image &color, const Image &hist, int scales);

// How far, in full-resolution pixels, an output pixel reads the input (both ways, each
// axis) with these options and scales: the farthest of the scales' chains, each the patch
// and search reach 2w + b at 2^s plus the downsampler's taps, then the recombinations'
// bicubic U and D up to the finest scale.
int RhfReach(const RhfParams &params, int scales);

// The pooled bright veto's counts (RhfParams::brightPool): per pixel the sum over its
// (2 patchHalf + 1)^2 box (cut at the image's edges) of the last two bins of each colour, in
// row-major order, the colours and bins of a pixel summed first.
std::vector<float> RhfBrightPool(const Image &hist, int patchHalf);

// Denoise `color` (3 channels) with its histograms `hist` (3n+1 channels: channel c*n+b is
// bin b of colour c, the last is the sample count; ReadFrame's "hist" layer). NaN/Inf
// colours are taken as black pixels without samples, NaN/Inf/negative bins and counts as
// 0; each kind is counted in a warning. Throws mcd::Error on bad shapes or options.
RhfResult RhfDenoise(vk::Context &context, const Image &color, const Image &hist,
                     const RhfParams &params, const RunSetup &setup = {});

// Makes ahead (Context::PrepareKernel) the kernels RhfDenoise records on a width x height
// frame with `planes` histogram planes where it selects at every scale (no earlier run's
// selection in the memo): each only where the run records it.
void PrepareRhfKernels(vk::Context &context, int width, int height, int planes,
                       const RhfParams &params, const RunSetup &setup = {});

}  // namespace mcd
