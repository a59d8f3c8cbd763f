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
#include "host/methods/staged_run.h"
#include "host/vk/context.h"
#include "host/vk/recorder.h"

namespace mcd {

struct RhfOptions {
    int patchHalf = 1;       // w: patches are (2w+1)^2
    int searchHalf = 6;      // b: the search window is (2b+1)^2
    float threshold = 0.8f;  // kappa, on the normalised chi-square patch distance
    int knn = 2;             // nearest patches always averaged, finest scale only
    // Requested; see RhfScalesUsed. One, not the tool's two: with the scales aligned as
    // the tool aligns them (issue #20), one scale had the lower error in 16 of 21 cells of
    // README's quality table (geometric mean 0.81x) and on an accumulated Cycles frame.
    int scales = 1;
    // The bright veto (beyond the authors' tool; 0 is theirs): a candidate patch is left
    // out when one pixel pair's counted terms in the saturated bins (the last two of each
    // colour: samples above the histogram's range M) sum to more than brightVeto x the
    // harmonic mean of the pair's sample counts (in the frame's counts at every scale).
    // The tool's distance is a mean over a patch's counted terms, so a visible light's large
    // terms are diluted by the zero terms of its alike neighbours and the light leaks into
    // dark patches at few samples; a lone firefly sample, at most 1 in its bins, stays below
    // the tool's "more than 1" and is still averaged away (README, "The bright veto").
    float brightVeto = 0.3f;
    // Clamp negative output to 0 (beyond the authors' tool): the recombination's bicubic U
    // overshoots below 0 at strong edges (README). The clamp follows the last stage, so
    // `diff --method rhf` compares raw stages.
    bool clampNegative = true;
    // Splitting knobs (0: automatic, from the device's binding limit). Tests use them to
    // exercise the split paths on small frames.
    int planesPerSlot = 0;  // histogram planes per buffer
    int stripRows = 0;      // centre rows per distance strip
    // Download every scale's images after the run (for `mcdenoise diff`).
    bool keepStages = false;
    // For a tile of a larger frame (host/api/tiled_run.h): the scales filtered and the
    // histograms' count-preserving rescale of each scale s >= 1 (histScales[s]), taken from
    // the whole frame, so that the tile filters as the untiled run does. 0 and empty: from
    // the image itself.
    int scalesUsed = 0;
    std::vector<float> histScales;
    // The window's origin in its whole frame (a multiple of 2^(scales - 1)) and the frame's
    // size (0: the image is the frame): the recombination's upsampler maps through the
    // frame's sizes, which differ from the window's by more than a factor 2^s.
    int frameX0 = 0, frameY0 = 0, frameWidth = 0, frameHeight = 0;
};

// warnings: bad pixels found in the input, with counts. With keepStages, stages coarse to
// fine: "color s<k>" (D_k of the colour, k >= 1), "filtered s<k>" (that scale's RHF),
// "combined s<k>" (the recombination, k below the coarsest); the last one is the output.
struct RhfResult : MethodResult {
    int scalesUsed = 0;
};

// Scales filtered: scale s >= 1 only while its image is at least the search window's size
// both ways; coarser scales would compare clamped windows of a handful of pixels.
int RhfScalesUsed(int width, int height, const RhfOptions &options);

// The count-preserving rescale of the histograms at scales 1..scales-1 (index s; index 0
// holds 1) that RhfDenoise computes on this frame, NaN/Inf/negative bins taken as 0 as it
// does, without copying the histograms.
std::vector<float> RhfHistScales(const Image &color, const Image &hist, int scales);

// How far, in full-resolution pixels, an output pixel reads the input (both ways, each
// axis) with these options and scales: the farthest of the scales' chains, each the patch
// and search reach 2w + b at 2^s plus the downsampler's taps, then the recombinations'
// bicubic U and D up to the finest scale.
int RhfReach(const RhfOptions &options, int scales);

// Denoise `color` (3 channels) with its histograms `hist` (3n+1 channels: channel c*n+b is
// bin b of colour c, the last is the sample count; ReadFrame's "hist" layer). NaN/Inf
// colours are taken as black pixels without samples, NaN/Inf/negative bins and counts as
// 0; each kind is counted in a warning. Throws mcd::Error on bad shapes or options.
RhfResult RhfDenoise(vk::Context &context, const Image &color, const Image &hist,
                     const RhfOptions &options);

}  // namespace mcd
