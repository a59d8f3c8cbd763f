// The built-in renderer: every layer of ARCHITECTURE.md for a built-in scene, on all cores,
// bit-identical for any thread count (each pixel's samples come from their own PCG
// streams, keyed by seed, pixel and sample index).
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "host/image.h"
#include "host/tracing.h"
#include "tools/render/integrator.h"
#include "tools/render/scene.h"

namespace mcd::render {

// Bumped whenever a change alters what a scene renders to: it keys cached references.
constexpr const char *kRendererVersion = "r3";

// Opt-in layer groups; color, variance, spp, min and max are always written.
enum LayerGroup : unsigned {
    kLayersHist = 1,     // RHF histograms (layer "hist", Bin_NNNN in files)
    kLayersSplit = 2,    // direct, indirect, direct.variance, indirect.variance
    kLayersPivot = 4,    // pivot (Ershov eq. 9)
    kLayersGbuffer = 8,  // albedo, normal, depth, objectId, partId
    kLayersAll = 15,
    // Ershov section 8 (not in "all"): partial<k>.color, .pivot and .variance for k <
    // kPartialTypes mirror bounces before the first diffuse/glossy hit, and "remainder",
    // the rest of color (see PathSample).
    kLayersPartials = 16,
    // Histograms of z = sample / pivot (not in "all"; implies pivot): layer "zhist", laid
    // out as "hist", so that rhf can filter the demodulated frame (Ershov 4.1 with
    // `denoise --method rhf --demodulate pivot`). Where a channel's pivot is 0, z is the
    // sample itself, as --demodulate leaves such pixels undivided.
    kLayersZHist = 32,
    // Half-buffers (not in "all"): half0.color and half1.color, the means of the even and
    // of the odd samples, two independent estimates of color (as `accumulate` writes from
    // N frames); with 1 spp half1 has no sample and is 0. From 3 spp on also half0's own
    // layers (half0.variance, .spp, .min, .max and the hist, split and gbuffer layers but the
    // ids), of the even samples alone, as accumulate writes them.
    kLayersHalves = 64,
};

// Parse "hist,split,pivot,gbuffer,partials,zhist,halves", "all" or "" (none); throws
// mcd::Error.
unsigned ParseLayerGroups(const std::string &text);

// Ershov section 5's tracing filter, run while rendering: the frame is rendered in bands of
// rows, each band's records (and `radius` rows above and below it, kept in a sliding
// window, so every row is traced once) handed to `gather`.
using TracingGatherFn = std::function<std::vector<float>(
    const TracingRecords &records, const TracingParams &params, int outY0, int outRows)>;

struct TracingFilterOptions {
    bool enabled = false;
    TracingParams params;
    // Ershov section 8: how many partial images (0: the first hit is diffuse or glossy; k:
    // after k mirror bounces) are filtered, each on its own, 1..kPartialTypes; the rest of
    // the light stays unfiltered. Each takes its own records (memoryBudget covers them all).
    // 2 measured: glossy-cornell's relMSE halved, scenes without mirrors unchanged (notes).
    int partials = 2;
    // Bound on the window's records (40 B per sample and filtered partial image): the band
    // height follows from it.
    size_t memoryBudget = size_t(256) << 20;
    int bandRows = 0;       // > 0: this band height whatever the budget (tests)
    int maxWindowRows = 0;  // > 0: the gather takes at most this many rows of records
    // The gather; empty: ref::TracingFilter on the render's threads.
    TracingGatherFn gather;
};

struct TracingStats {
    double renderSeconds = 0, gatherSeconds = 0;
    size_t peakRecordBytes = 0;  // the window's capacity at its largest
    int bands = 0, bandRows = 0;
    int partials = 0;         // partial images filtered (1 when the scene has no mirror)
    bool overBudget = false;  // one band and its halo did not fit in memoryBudget
};

struct RenderOptions {
    int width = 256, height = 256, spp = 16;
    uint64_t seed = 1;
    unsigned layers = 0;
    int threads = 0;    // 0: all cores
    int histBins = 20;  // per channel
    // With tracing.enabled, color is the filtered frame (rest + the filtered part), its
    // unfiltered mean is kept as "color.unfiltered", and partial0.color and indirect take
    // the same change, so the partials and direct + indirect still sum to color. The
    // other statistics (variance, min, max, histograms, halves) are the plain samples'.
    TracingFilterOptions tracing;
    // Called with (rows done, rows total) from the rendering threads, serialised.
    std::function<void(int, int)> progress;
};

struct RenderResult {
    std::vector<std::pair<std::string, Image>> layers;  // in ARCHITECTURE.md order
    std::map<std::string, std::string> metadata;
    double seconds = 0;
    uint64_t nonFiniteSamples = 0;  // paths that produced NaN/Inf (counted as 0)
    TracingStats tracing;           // with options.tracing.enabled
};

RenderResult Render(const Scene &scene, const RenderOptions &options);

// RHF Algorithm 1 (the authors' tool's constants): add one sample of weight 1 to the
// 3 x bins histogram of a pixel (channel c's bins start at c * bins).
void AddToHistogram(const double color[3], int bins, float *histogram);

// The sample source of ARCHITECTURE.md: one sample at a continuous image position, for the
// renderer's own per-pixel loop and for AWR's adaptive sampler. `key` picks the random
// stream, so the same (x, y, key) always gives the same sample.
class SampleSource {
  public:
    SampleSource(const Scene &scene, int width, int height, uint64_t seed)
        : scene(scene), width(width), height(height), seed(seed) {}
    PathSample Trace(double x, double y, uint64_t key, TracingPath *tracing = nullptr) const;

  private:
    const Scene &scene;
    int width, height;
    uint64_t seed;
};

}  // namespace mcd::render
