#include "host/methods/pivot.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <optional>
#include <string>

#include "host/error.h"
#include "host/kernels/pivot_bilateral.h"
#include "host/kernels/pivot_fit.h"
#include "host/kernels/pivot_gather.h"
#include "host/kernels/pivot_ratio.h"
#include "host/methods/checks.h"
#include "host/methods/staged_run.h"
#include "host/vk/gpu_image.h"
#include "pivot/pivot.h"

namespace mcd {
namespace {

void CheckLayer(const Image &image, const char *what, int width, int height, int channels,
                bool nonNegative) {
    mcd::CheckLayer("pivot", image, what, width, height, channels, nonNegative);
}

}  // namespace

std::vector<float> PivotThresholds(const Image &pivot, float floor) {
    std::vector<float> thresholds;
    for (int c = 0; c < pivot.channels; ++c) {
        double sum = 0;
        for (int y = 0; y < pivot.height; ++y)
            for (int x = 0; x < pivot.width; ++x)
                sum += std::max(0.0, double(pivot.At(c, y, x)));
        thresholds.push_back(float(floor * sum / double(pivot.PixelCount())));
    }
    return thresholds;
}

namespace {

// Throw on missing or misshapen layers, NaN/Inf, bad options, or a frame whose fits do not
// fit one binding.
void CheckPivotInputs(vk::Context &context, const PivotInputs &in, const PivotParams &options) {
    if (!in.color || !in.pivot)
        throw Error("pivot: needs the color and pivot layers", ErrorKind::MissingLayer);
    const Image &color = *in.color;
    int w = color.width, h = color.height, channels = color.channels;
    if (channels < 1 || channels > PIVOT_MAX_CHANNELS)
        throw Error(fmt::format("pivot: color has {} channels; 1 to {} are supported", channels,
                                PIVOT_MAX_CHANNELS),
                    ErrorKind::InvalidArgument);
    if (w < 1 || h < 1) throw Error("pivot: the image is empty", ErrorKind::InvalidArgument);
    // The largest bindings: a channel's fit buffer of PIVOT_PLANES_PER_BUFFER planes
    // (written by the fit, read by the gather as a texel view) and a channel's packed z, s,
    // nu, level and noise (8 floats): refuse, before any work, a frame the device cannot bind.
    double pixelBytes = std::max(PIVOT_PLANES_PER_BUFFER, 8) * sizeof(float);
    double bindingBytes = pixelBytes * w * h, binding = double(context.BindingBytes());
    if (bindingBytes > binding)
        throw Error(fmt::format("pivot: a {}x{}x{} frame needs {:.0f} MB in one binding, above "
                                "this device's {:.0f} MB (at most {:.0f} pixels of {} "
                                "channels); crop or tile the frame",
                                w, h, channels, bindingBytes / 1e6, binding / 1e6,
                                std::floor(binding / pixelBytes), channels),
                    ErrorKind::OutOfMemory);
    CheckLayer(color, "color", w, h, channels, false);
    CheckLayer(*in.pivot, "pivot", w, h, channels, false);
    if (in.variance) CheckLayer(*in.variance, "variance", w, h, channels, true);
    if (in.normal) CheckLayer(*in.normal, "normal", w, h, 3, false);
    if (in.objectId) CheckLayer(*in.objectId, "objectId", w, h, 1, false);
    if (in.partId) CheckLayer(*in.partId, "partId", w, h, 1, false);
    auto finitePositive = [](float v) { return std::isfinite(v) && v > 0; };
    if (!finitePositive(options.floor) || !finitePositive(options.goodNoise) ||
        !(std::isfinite(options.targetNoise) && options.targetNoise >= 0) ||
        !(std::isfinite(options.disagreement) && options.disagreement >= 0) ||
        !(std::isfinite(options.k) && options.k >= 0) ||
        !(std::isfinite(options.sigmaWeight) && options.sigmaWeight >= 0) ||
        !finitePositive(options.sigmaRange))
        throw Error(
            "pivot: floor, noise threshold and range sigma must be finite and > 0; target "
            "noise, disagreement and k finite and >= 0",
            ErrorKind::InvalidArgument);
    if (options.maxRadius < 2 || options.maxRadius > 64)
        throw Error(fmt::format("pivot: maximum radius {}; 2..64 allowed", options.maxRadius),
                    ErrorKind::InvalidArgument);
    if (options.bilateralRadius < 0 || options.bilateralRadius > 64)
        throw Error(
            fmt::format("pivot: bilateral radius {}; 0..64 allowed", options.bilateralRadius),
            ErrorKind::InvalidArgument);
}

// Pixel-channels without z: pivot below the threshold, or |z| beyond PIVOT_Z_MAX.
size_t CountWithoutZ(const Image &color, const Image &pivot,
                     const std::vector<float> &thresholds) {
    size_t count = 0;
    for (int c = 0; c < color.channels; ++c)
        for (int y = 0; y < color.height; ++y)
            for (int x = 0; x < color.width; ++x) {
                float la = pivot.At(c, y, x);
                if (!(la > thresholds[c]) ||
                    !(std::fabs(double(color.At(c, y, x)) / la) <= PIVOT_Z_MAX))
                    ++count;
            }
    return count;
}

// One guide image: normal x, y, z, object id, part id (absent parts stay zero).
Image GuideImage(const PivotInputs &in) {
    int w = in.color->width, h = in.color->height;
    Image guide(w, h, PIVOT_GUIDE_PLANES);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            for (int c = 0; c < 3 && in.normal; ++c) guide.At(c, y, x) = in.normal->At(c, y, x);
            if (in.objectId) guide.At(3, y, x) = in.objectId->At(0, y, x);
            if (in.partId) guide.At(4, y, x) = in.partId->At(0, y, x);
        }
    return guide;
}

// The GPU side of a run: the inputs, z, its weights s and noise nu, the output, and the
// guides when the frame has normals or ids. `edgeInputs`: the packed z, s, nu carry the
// shading-edge test's level and noise (8 floats a pixel, else 4).
struct PivotGpu {
    PivotGpu(vk::Context &context, const PivotInputs &in, bool edgeInputs)
        : color(context, in.color->width, in.color->height, in.color->channels, "pivot.color"),
          pivot(context, in.color->width, in.color->height, in.color->channels, "pivot.pivot"),
          z(context, in.color->width, in.color->height, in.color->channels, "pivot.z"),
          s(context, in.color->width, in.color->height, in.color->channels, "pivot.s"),
          nu(context, in.color->width, in.color->height, in.color->channels, "pivot.nu"),
          out(context, in.color->width, in.color->height, in.color->channels, "pivot.out"),
          unusedSlot(context, kPivotUnusedSlotBytes, "pivot.unused") {
        int w = in.color->width, h = in.color->height, channels = in.color->channels;
        // Each channel's packed z, s, nu in a buffer of its own: a binding holds one. A run
        // without the edge test holds 4 floats a pixel, not 8.
        for (int c = 0; c < channels; ++c)
            zsn.emplace_back(context, w, h,
                             edgeInputs ? PIVOT_ZSN_EDGE_PLANES : PIVOT_ZSN_PLANES,
                             fmt::format("pivot.zsn{}", c));
        color.Upload(*in.color);
        pivot.Upload(*in.pivot);
        if (in.variance) {
            variance.emplace(context, w, h, channels, "pivot.variance");
            variance->Upload(*in.variance);
        }
        guides.normals = in.normal != nullptr;
        guides.ids = in.objectId || in.partId;
        if (guides.normals || guides.ids) {
            guide.emplace(context, w, h, PIVOT_GUIDE_STRIDE, "pivot.guides");
            guide->Upload(PivotGuideBuffer(GuideImage(in)));
            guides.image = &*guide;
        }
    }

    vk::GpuImage color, pivot, z, s, nu, out;
    std::vector<vk::GpuImage> zsn;
    vk::Buffer unusedSlot;  // the ratio's packed slots of the channels the frame lacks
    std::optional<vk::GpuImage> variance, guide;
    PivotGpuGuides guides;
};

void PlanInputs(StagedRun &run, const PivotInputs &in, const PivotGpuGuides &guides,
                size_t pixelsWithoutZ, const PivotParams &options) {
    const Image &color = *in.color;
    run.Plan(fmt::format(
        "pseudo-brightness z = color / pivot ({}x{}x{}); {} pixel-channels with pivot <= {} x "
        "the channel mean keep their input",
        color.width, color.height, color.channels, pixelsWithoutZ, options.floor));
    run.Plan(in.variance ? "noise of z: the variance layer / pivot^2"
                         : "noise of z: estimated from the 3x3 neighbours (no variance "
                           "layer)");
    run.Plan(guides.normals ? "normal term (n.n0)^4, n.n0 > 1/2: on"
                            : "left out: the normal term (the frame has no normals)");
    run.Plan(guides.ids
                 ? fmt::format("object/part terms: on ({}{}); each fit reads and each pixel "
                               "gathers the pixels of its own ids, those beside other ids "
                               "included (as data, not as fit centres; one whose z lies "
                               "toward a side far from its own keeps its input)",
                               in.objectId ? "objectId" : "",
                               in.partId ? (in.objectId ? ", partId" : "partId") : "")
                 : "left out: the object and part terms (the frame has no ids)");
}

// The cross-bilateral baseline of 4.1 into gpu.out, one submission with the ratio.
void RecordBilateral(StagedRun &run, PivotGpu &gpu, const PivotParams &options) {
    PivotBilateralSettings settings{options.bilateralRadius, options.sigmaRange,
                                    options.goodNoise};
    run.Plan(fmt::format(
        "bilateral: cross-bilateral filter of z, radius {}, spatial sigma {}, range sigma "
        "{} on the pivot's relative difference; times the pivot",
        settings.radius, std::max(0.5f, settings.radius / 2.f), settings.sigmaRange));
    RecordPivotBilateral(run.Context(), run.Recorder(), gpu.color, gpu.pivot, gpu.z, gpu.nu,
                         gpu.guides, settings, gpu.out);
    run.Submit();
}

// Record rows [rowBase, rowBase + rows) in strips of stripRows, one submission each.
void InStrips(StagedRun &run, int h, int stripRows, const char *stage, const RunSetup &setup,
              const std::function<void(int, int)> &record) {
    for (int rowBase = 0; rowBase < h; rowBase += stripRows) {
        int rows = std::min(stripRows, h - rowBase);
        record(rowBase, rows);
        run.Submit();
        if (setup.progress) setup.progress(stage, rowBase + rows, h);
    }
}

// "GPU time: " per kernel, summed over the strips.
std::string TimePerKernel(const std::vector<vk::DispatchTiming> &timings) {
    std::vector<std::pair<std::string, double>> perKernel;
    for (const vk::DispatchTiming &t : timings) {
        auto it = std::find_if(perKernel.begin(), perKernel.end(),
                               [&](const auto &p) { return p.first == t.label; });
        if (it == perKernel.end())
            perKernel.push_back({t.label, t.gpuMs});
        else
            it->second += t.gpuMs;
    }
    std::string times;
    for (const auto &[label, ms] : perKernel)
        times += fmt::format("{}{} {:.1f} ms", times.empty() ? "" : ", ", label, ms);
    return times;
}

// The paper's filter into gpu.out: fits in row strips, the radii read back to size the
// gather's reach per tile, the gather in row strips; the fits kept as a stage.
void RecordPlaneFit(StagedRun &run, PivotGpu &gpu, const PivotParams &options,
                    const RunSetup &setup, PivotResult &result) {
    vk::Context &context = run.Context();
    int w = gpu.z.width, h = gpu.z.height, channels = gpu.z.channels;
    PivotFitBuffers fits(context, w, h, channels, "pivot.fit");
    PivotFitSettings settings{options.maxRadius,    options.targetNoise, options.goodNoise,
                              options.disagreement, options.k,           options.sigmaWeight,
                              options.edge};
    // Row strips, one submission each: progress on long frames, and no dispatch long enough
    // to trip a GPU watchdog. The ratio stage recorded before runs with the first strip.
    const int stripRows = setup.stripPixels > 0 ? std::clamp(setup.stripPixels / w, 1, h) : h;
    InStrips(run, h, stripRows, "fit", setup, [&](int rowBase, int rows) {
        RecordPivotFit(context, run.Recorder(), gpu.zsn, gpu.guides, settings, fits, rowBase,
                       rows);
    });
    // The radii decide how far the gather looks, tile by tile.
    Image radii = fits.Radii();
    double sum = 0;
    size_t fitted = 0;
    for (float r : radii.data)
        if (r >= 0) sum += r, ++fitted;
    result.meanRadius = fitted ? sum / fitted : 0;
    Image tileOrder = PivotTileOrder(radii, &result.largestRadius);
    vk::GpuImage tiles(context, tileOrder.width, tileOrder.height, tileOrder.channels,
                       "pivot.tiles");
    tiles.Upload(tileOrder);
    run.Plan(fmt::format(
        "planefit: squares grown from 5x5 to at most {}x{} (stop at relative noise {}, "
        "square-vs-quadrant disagreement {}; a centre about to leave eq. 13's lattice stops at "
        "3, 7 or "
        "16); mean radius {:.2f}, largest {}; fits of the square and 4 quadrants with eq. 10 "
        "(k = {}, pixels with relative noise > {} left out){}",
        2 * options.maxRadius + 1, 2 * options.maxRadius + 1, options.targetNoise,
        options.disagreement, result.meanRadius, result.largestRadius, options.k,
        options.goodNoise,
        options.edge > 0
            ? fmt::format("; shading edges the pivot does not show: the final fits leave out, "
                          "and the gather skips centres of, what lies across one (3x3 medians "
                          "of z over {}x apart and over {} standard deviations of their "
                          "noise)",
                          1 + PIVOT_EDGE_CONTRAST, options.edge)
            : std::string()));
    run.Plan(
        "eqs. 11-13: combined square/quadrant fits averaged over the squares holding the "
        "pixel whose centres lie on their lattice (step: largest power of two <= radius / 2, "
        "at most 8; weight x step^2; a gather), times the pivot");
    InStrips(run, h, stripRows, "gather", setup, [&](int rowBase, int rows) {
        RecordPivotGather(context, run.Recorder(), gpu.color, gpu.pivot, gpu.zsn, fits,
                          gpu.guides, tiles, result.largestRadius, options.edge, gpu.out,
                          rowBase, rows);
    });
    run.Plan(fmt::format("GPU time: {} ({} row strip(s) of up to {} rows)",
                         TimePerKernel(run.Timings()), (h + stripRows - 1) / stripRows,
                         stripRows));
    if (run.KeepsStages()) {
        run.AddStage("fits", fits.Download());
    }
}

PivotResult PivotDenoiseOne(vk::Context &context, const PivotInputs &in,
                            const PivotParams &options, const RunSetup &setup) {
    CheckPivotInputs(context, in, options);
    PivotResult result;
    StagedRun run(context, setup.keepStages);
    std::vector<float> thresholds =
        in.thresholds.empty() ? PivotThresholds(*in.pivot, options.floor) : in.thresholds;
    if (int(thresholds.size()) != in.pivot->channels)
        throw Error(fmt::format("pivot: {} thresholds for {} channels", thresholds.size(),
                                in.pivot->channels),
                    ErrorKind::Internal);
    result.pixelsWithoutZ = CountWithoutZ(*in.color, *in.pivot, thresholds);
    PivotGpu gpu(context, in, options.edge > 0);
    PlanInputs(run, in, gpu.guides, result.pixelsWithoutZ, options);
    RecordPivotRatio(context, run.Recorder(), gpu.color, gpu.pivot,
                     gpu.variance ? &*gpu.variance : nullptr, thresholds, gpu.guides, gpu.z,
                     gpu.s, gpu.nu, gpu.zsn, gpu.unusedSlot);
    run.StageAtEnd("z", gpu.z);
    run.StageAtEnd("nu", gpu.nu);
    if (options.filter == PivotFilter::Bilateral)
        RecordBilateral(run, gpu, options);
    else
        RecordPlaneFit(run, gpu, options, setup, result);
    result.image = gpu.out.Download();
    run.AddStage("output", result.image);
    run.Finish(result);
    return result;
}

}  // namespace

void PreparePivotKernels(vk::Context &context, const PivotInputs &in,
                         const PivotParams &params) {
    if (!in.color || !in.pivot) return;
    // As PivotGpu and PivotDenoiseOne make them: each partial with its own variance.
    const bool normals = in.normal != nullptr, ids = in.objectId || in.partId;
    const int zsnTexels = (params.edge > 0 ? PIVOT_ZSN_EDGE_PLANES : PIVOT_ZSN_PLANES) / 4;
    std::vector<bool> variances;
    if (in.partials.empty()) variances.push_back(in.variance != nullptr);
    for (const PivotPartial &partial : in.partials)
        variances.push_back(partial.variance != nullptr);
    for (bool variance : variances)
        context.PrepareKernel(PivotRatioKernel(variance, ids, zsnTexels));
    if (params.filter == PivotFilter::Bilateral) {
        context.PrepareKernel(PivotBilateralKernel(normals, ids));
        return;
    }
    context.PrepareKernel(PivotFitKernel(normals, ids, zsnTexels));
    context.PrepareKernel(PivotGatherKernel(normals, ids, zsnTexels));
}

PivotResult PivotDenoise(vk::Context &context, const PivotInputs &in, const PivotParams &params,
                         const RunSetup &setup) {
    if (in.partials.empty()) return PivotDenoiseOne(context, in, params, setup);
    if (!in.color || !in.pivot)
        throw Error("pivot: needs the color and pivot layers", ErrorKind::MissingLayer);
    int w = in.color->width, h = in.color->height, channels = in.color->channels;
    if (channels < 1 || channels > PIVOT_MAX_CHANNELS || w < 1 || h < 1)
        throw Error(fmt::format("pivot: color is {}x{}x{}; 1 to {} channels are supported", w,
                                h, channels, PIVOT_MAX_CHANNELS),
                    ErrorKind::InvalidArgument);
    CheckLayer(*in.pivot, "pivot", w, h, channels, false);
    if (!in.remainder)
        throw Error("pivot: partial images need the remainder layer", ErrorKind::MissingLayer);
    CheckLayer(*in.remainder, "remainder", w, h, channels, false);
    PivotResult result;
    result.image = Image(w, h, channels);
    double radiusSum = 0;
    for (size_t k = 0; k < in.partials.size(); ++k) {
        const PivotPartial &partial = in.partials[k];
        std::string name = fmt::format("partial{}", k);
        if (!partial.color || !partial.pivot)
            throw Error(fmt::format("pivot: {} needs its color and pivot", name),
                        ErrorKind::MissingLayer);
        CheckLayer(*partial.color, (name + ".color").c_str(), w, h, channels, false);
        CheckLayer(*partial.pivot, (name + ".pivot").c_str(), w, h, channels, false);
        if (partial.variance)
            CheckLayer(*partial.variance, (name + ".variance").c_str(), w, h, channels, true);
        PivotInputs one = in;
        one.color = partial.color;
        one.pivot = partial.pivot;
        one.variance = partial.variance;
        one.thresholds = partial.thresholds;
        one.partials.clear();
        one.remainder = nullptr;
        PivotResult r = PivotDenoiseOne(context, one, params, setup);
        for (size_t i = 0; i < result.image.Size(); ++i)
            result.image.data[i] += r.image.data[i];
        for (const std::string &line : r.plan) result.plan.push_back(name + ": " + line);
        for (vk::DispatchTiming &t : r.timings) {
            t.label = name + "." + t.label;
            result.timings.push_back(std::move(t));
        }
        for (auto &[stage, image] : r.stages)
            result.stages.emplace_back(name + "." + stage, std::move(image));
        radiusSum += r.meanRadius;
        result.largestRadius = std::max(result.largestRadius, r.largestRadius);
        result.pixelsWithoutZ += r.pixelsWithoutZ;
    }
    result.meanRadius = radiusSum / double(in.partials.size());
    for (size_t i = 0; i < result.image.Size(); ++i)
        result.image.data[i] += in.remainder->data[i];
    result.plan.insert(
        result.plan.begin(),
        fmt::format("section 8: {} partial images, each filtered against its own pivot "
                    "(partial<k>.color / partial<k>.pivot), summed, plus the remainder "
                    "unfiltered; the frame's pivot and variance layers are not used",
                    in.partials.size()));
    return result;
}

}  // namespace mcd
