// Method `pivot`: the image-based filter of Ershov et al. (section 4) on the GPU. The noisy
// image is divided by the pivot (the deterministic render under unit ambient light, eq.
// 9), the pseudo-brightness z is filtered, and the result is multiplied back.
// `planefit` (default) is the paper's filter: squares grown from 5x5 per centre, weighted
// plane fits of the square and its quadrants (eq. 10), their combination (eqs. 11-12) and
// the two-stage averaging (eq. 13). `bilateral` is the cross-bilateral baseline of 4.1.
// Normals and object/part ids refine both when the frame has them. The readings of the
// paper are listed in cpu_reference/pivot_filter.h, the CPU twin.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "host/image.h"
#include "host/methods/staged_run.h"
#include "host/vk/context.h"
#include "host/vk/recorder.h"

namespace mcd {

enum class PivotFilter { PlaneFit, Bilateral };

struct PivotOptions {
    PivotFilter filter = PivotFilter::PlaneFit;
    float floor = 1e-3f;  // pixels with pivot <= floor x channel mean have no z
    // planefit
    int maxRadius = 30;         // paper: 30-40
    float targetNoise = 0.02f;  // relative std of a centre's fit that stops growth
    // Relative std above which a pixel is not fitted (section 4.2's threshold). Measured at
    // 16 spp (cornell, relief-abc, double-textured, glossy-cornell, 128x128): 100 beats 1 and
    // 3 on PSNR in all four; 1 darkens heavy-tailed scenes (the fireflies carry the energy).
    float goodNoise = 100.f;
    float disagreement = 0.1f;  // square-vs-quadrant limit, relative
    // eq. 10; k = 1 darkened cornell at 16 spp by 5% (it down-weights the bright tail of
    // the noise), 0 and 0.3 measure the same.
    float k = 0.3f;
    // Multiplies sigma in eq. 10. With heavy-tailed noise the pixels that carry the energy
    // (fireflies) have the largest sigma: 1 (the paper) halved relief-abc's plane at 16 spp;
    // 0 measured better PSNR on all four scenes above (e.g. glossy-cornell 24.5 -> 25.9 dB).
    float sigmaWeight = 0.f;
    // bilateral
    int bilateralRadius = 8;
    float sigmaRange = 0.2f;
    // Keep every stage's output in PivotResult::stages (for `mcdenoise diff`).
    bool keepStages = false;
    // Planefit runs its fit and gather in row strips of about stripPixels centres, one
    // submission each, and calls progress(stage, rowsDone, rows) after each ("fit",
    // "gather"; with partials, per partial). 0: one strip.
    int stripPixels = 1 << 16;
    std::function<void(const std::string &stage, int done, int total)> progress;
};

// One partial image of section 8 and its own pivot (the same camera ray path before the
// first diffuse hit).
struct PivotPartial {
    const Image *color = nullptr, *pivot = nullptr;
    const Image *variance = nullptr;  // of the partial's pixel mean; absent: estimated
    std::vector<float> thresholds;    // as PivotInputs::thresholds, for this pivot
};

// The frame's layers the method reads; all but color and pivot may be absent (nullptr).
struct PivotInputs {
    const Image *color = nullptr, *pivot = nullptr;
    const Image *variance = nullptr;                     // of the pixel mean, as color
    const Image *normal = nullptr;                       // 3 channels
    const Image *objectId = nullptr, *partId = nullptr;  // 1 channel each
    // Section 8: with partials, each is filtered against its own pivot by the pipeline
    // above (with its own variance, else estimated: the variance layer is the whole
    // color's), the results
    // are summed in order and the remainder (required then) is added unfiltered; color
    // and pivot are then only checked for shape.
    std::vector<PivotPartial> partials;
    const Image *remainder = nullptr;
    // Per channel, the pivot below which a pixel keeps its input (PivotThresholds); a tile
    // of a larger frame (host/api/tiled_run.h) passes the whole frame's. Empty: this pivot's.
    std::vector<float> thresholds;
};

// With keepStages, stages z, nu, the fits (planefit; 16 x channels planes as in
// cpu_reference/pivot_filter.h) and the output, by name (with partials, each partial's
// prefixed "partial<k>."). No warnings: bad inputs are refused.
struct PivotResult : MethodResult {
    double meanRadius = 0;  // planefit: over the centres with a fit
    int largestRadius = 0;  // (with partials: of all partials)
    // Pixel-channels (with partials: summed over them) whose pivot is below the floor.
    size_t pixelsWithoutZ = 0;
};

// Per-channel pivot threshold: floor x the mean of max(L_a, 0).
std::vector<float> PivotThresholds(const Image &pivot, float floor);

// Throws mcd::Error naming the layer and pixel when an input holds NaN/Inf (or a negative
// variance), when shapes differ or options are out of range.
PivotResult PivotDenoise(vk::Context &context, const PivotInputs &inputs,
                         const PivotOptions &options);

}  // namespace mcd
