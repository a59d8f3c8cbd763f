// Method `pivot`: the image-based filter of Ershov et al. (section 4) on the GPU. The noisy
// image is divided by the pivot (the deterministic render under unit ambient light, eq.
// 9), the pseudo-brightness z is filtered, and the result is multiplied back.
// `planefit` (default) is the paper's filter: squares grown from 5x5 per centre, weighted
// plane fits of the square and its quadrants (eq. 10), their combination (eqs. 11-12) and
// the two-stage averaging (eq. 13). `bilateral` is the cross-bilateral baseline of 4.1.
// Normals and object/part ids refine both when the frame has them. The readings of the
// paper are listed in cpu_reference/pivot_filter.h, the CPU twin.
#pragma once

#include <string>
#include <vector>

#include "host/image.h"
#include "host/methods/run_setup.h"
#include "host/methods/staged_run.h"
#include "host/params/pivot.h"
#include "host/vk/context.h"
#include "host/vk/recorder.h"

namespace mcd {

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

// With setup.keepStages, stages z, nu, the fits (planefit; 16 x channels planes as in
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
                         const PivotParams &params, const RunSetup &setup = {});

// Makes ahead (Context::PrepareKernel) the kernels PivotDenoise records on these inputs with
// these parameters: the guides' variants the frame has, the variance's where it has one.
void PreparePivotKernels(vk::Context &context, const PivotInputs &inputs,
                         const PivotParams &params);

}  // namespace mcd
