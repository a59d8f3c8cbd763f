#include "host/methods/pivot.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "host/error.h"
#include "host/kernels/pivot_bilateral.h"
#include "host/kernels/pivot_fit.h"
#include "host/kernels/pivot_gather.h"
#include "host/kernels/pivot_ratio.h"
#include "host/methods/checks.h"
#include "host/vk/gpu_image.h"
#include "pivot/pivot.h"

namespace mcd {
namespace {

void CheckLayer(const Image &image, const char *what, int width, int height, int channels,
                bool nonNegative) {
    if (image.width != width || image.height != height ||
        (channels > 0 && image.channels != channels))
        throw Error(fmt::format("pivot: {} is {}x{}x{}, expected {}x{}x{}", what, image.width,
                                image.height, image.channels, width, height,
                                channels > 0 ? channels : image.channels));
    CheckFinite("pivot", image, what, nonNegative);
}

void Append(std::vector<vk::DispatchTiming> &to, const std::vector<vk::DispatchTiming> &from) {
    to.insert(to.end(), from.begin(), from.end());
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

PivotResult PivotDenoiseOne(vk::Context &context, const PivotInputs &in,
                            const PivotOptions &options) {
    if (!in.color || !in.pivot) throw Error("pivot: needs the color and pivot layers");
    const Image &color = *in.color;
    int w = color.width, h = color.height, channels = color.channels;
    if (channels < 1 || channels > PIVOT_MAX_CHANNELS)
        throw Error(fmt::format("pivot: color has {} channels; 1 to {} are supported", channels,
                                PIVOT_MAX_CHANNELS));
    if (w < 1 || h < 1) throw Error("pivot: the image is empty");
    // Each of the two fit buffers holds PIVOT_PLANES_PER_BUFFER planes per channel in one
    // binding (written by the fit, read by the gather as a texel view): refuse, before any
    // work, a frame the device cannot hold.
    double fitBytes = double(PIVOT_PLANES_PER_BUFFER) * channels * w * h * sizeof(float);
    double binding = double(context.BindingBytes());
    if (fitBytes > binding)
        throw Error(fmt::format(
            "pivot: a {}x{}x{} frame needs {:.0f} MB per fit buffer, above this device's "
            "{:.0f} MB per binding (at most {:.0f} pixels of {} channels); crop or tile the "
            "frame",
            w, h, channels, fitBytes / 1e6, binding / 1e6,
            std::floor(binding / (PIVOT_PLANES_PER_BUFFER * channels * 4)), channels));
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
            "noise, disagreement and k finite and >= 0");
    if (options.maxRadius < 2 || options.maxRadius > 64)
        throw Error(fmt::format("pivot: maximum radius {}; 2..64 allowed", options.maxRadius));
    if (options.bilateralRadius < 0 || options.bilateralRadius > 64)
        throw Error(
            fmt::format("pivot: bilateral radius {}; 0..64 allowed", options.bilateralRadius));

    PivotResult result;
    std::vector<float> thresholds = PivotThresholds(*in.pivot, options.floor);
    for (int c = 0; c < channels; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                float la = in.pivot->At(c, y, x);
                if (!(la > thresholds[c]) ||
                    !(std::fabs(double(color.At(c, y, x)) / la) <= PIVOT_Z_MAX))
                    ++result.pixelsWithoutZ;
            }
    result.plan.push_back(fmt::format(
        "pseudo-brightness z = color / pivot ({}x{}x{}); {} pixel-channels with pivot <= {} x "
        "the channel mean keep their input",
        w, h, channels, result.pixelsWithoutZ, options.floor));
    result.plan.push_back(in.variance
                              ? "noise of z: the variance layer / pivot^2"
                              : "noise of z: estimated from the 3x3 neighbours (no variance "
                                "layer)");

    vk::GpuImage colorGpu(context, w, h, channels, "pivot.color");
    vk::GpuImage pivotGpu(context, w, h, channels, "pivot.pivot");
    colorGpu.Upload(color);
    pivotGpu.Upload(*in.pivot);
    vk::GpuImage z(context, w, h, channels, "pivot.z");
    vk::GpuImage s(context, w, h, channels, "pivot.s");
    vk::GpuImage nu(context, w, h, channels, "pivot.nu");
    vk::GpuImage out(context, w, h, channels, "pivot.out");
    std::optional<vk::GpuImage> varianceGpu, guideGpu;
    if (in.variance) {
        varianceGpu.emplace(context, w, h, channels, "pivot.variance");
        varianceGpu->Upload(*in.variance);
    }
    PivotGpuGuides guides;
    guides.normals = in.normal != nullptr;
    guides.ids = in.objectId || in.partId;
    if (guides.normals || guides.ids) {
        // One guide image: normal x, y, z, object id, part id (absent parts stay zero).
        Image guide(w, h, PIVOT_GUIDE_PLANES);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                for (int c = 0; c < 3 && in.normal; ++c)
                    guide.At(c, y, x) = in.normal->At(c, y, x);
                if (in.objectId) guide.At(3, y, x) = in.objectId->At(0, y, x);
                if (in.partId) guide.At(4, y, x) = in.partId->At(0, y, x);
            }
        guideGpu.emplace(context, w, h, PIVOT_GUIDE_PLANES, "pivot.guides");
        guideGpu->Upload(guide);
        guides.image = &*guideGpu;
    }
    result.plan.push_back(guides.normals
                              ? "normal term (n.n0)^4, n.n0 > 1/2: on"
                              : "left out: the normal term (the frame has no normals)");
    result.plan.push_back(
        guides.ids ? fmt::format("object/part and boundary terms: on ({}{}); pixels next to "
                                 "other ids keep their input",
                                 in.objectId ? "objectId" : "",
                                 in.partId ? (in.objectId ? ", partId" : "partId") : "")
                   : "left out: the object, part and boundary terms (the frame has no ids)");

    vk::Recorder recorder(context);
    RecordPivotRatio(context, recorder, colorGpu, pivotGpu,
                     varianceGpu ? &*varianceGpu : nullptr, thresholds, guides, z, s, nu);

    if (options.filter == PivotFilter::Bilateral) {
        PivotBilateralSettings settings{options.bilateralRadius, options.sigmaRange,
                                        options.goodNoise};
        result.plan.push_back(fmt::format(
            "bilateral: cross-bilateral filter of z, radius {}, spatial sigma {}, range sigma "
            "{} on the pivot's relative difference; times the pivot",
            settings.radius, std::max(0.5f, settings.radius / 2.f), settings.sigmaRange));
        RecordPivotBilateral(context, recorder, colorGpu, pivotGpu, z, nu, guides, settings,
                             out);
        recorder.Submit();
        result.timings = recorder.Timings();
        result.image = out.Download();
        if (options.keepStages)
            result.stages = {
                {"z", z.Download()}, {"nu", nu.Download()}, {"output", result.image}};
        return result;
    }

    vk::GpuImage fitLo(context, w, h, PIVOT_PLANES_PER_BUFFER * channels, "pivot.fitLo");
    vk::GpuImage fitHi(context, w, h, PIVOT_PLANES_PER_BUFFER * channels, "pivot.fitHi");
    PivotFitSettings settings{options.maxRadius,    options.targetNoise, options.goodNoise,
                              options.disagreement, options.k,           options.sigmaWeight};
    // Row strips, one submission each: progress on long frames, and no dispatch long enough
    // to trip a GPU watchdog. The ratio stage recorded above runs with the first strip.
    const int stripRows =
        options.stripPixels > 0 ? std::clamp(options.stripPixels / w, 1, h) : h;
    auto inStrips = [&](const char *stage, const std::function<void(int, int)> &record) {
        for (int rowBase = 0; rowBase < h; rowBase += stripRows) {
            int rows = std::min(stripRows, h - rowBase);
            record(rowBase, rows);
            recorder.Submit();
            Append(result.timings, recorder.Timings());
            if (options.progress) options.progress(stage, rowBase + rows, h);
        }
    };
    inStrips("fit", [&](int rowBase, int rows) {
        RecordPivotFit(context, recorder, z, s, nu, guides, settings, fitLo, fitHi, rowBase,
                       rows);
    });
    // The radii decide how far the gather looks, tile by tile.
    Image radii(w, h, channels);
    fitHi.buffer.Download(
        radii.data.data(), radii.Size() * sizeof(float),
        size_t(PIVOT_PLANES - 1 - PIVOT_PLANES_PER_BUFFER) * radii.Size() * sizeof(float));
    double sum = 0;
    size_t fitted = 0;
    for (float r : radii.data)
        if (r >= 0) sum += r, ++fitted;
    result.meanRadius = fitted ? sum / fitted : 0;
    Image tileRadii = PivotTileRadii(radii, &result.largestRadius);
    vk::GpuImage tiles(context, tileRadii.width, tileRadii.height, channels, "pivot.tiles");
    tiles.Upload(tileRadii);
    result.plan.push_back(fmt::format(
        "planefit: squares grown from 5x5 to at most {}x{} (stop at relative noise {}, "
        "square-vs-quadrant disagreement {}); mean radius {:.2f}, largest {}; fits of the "
        "square and 4 quadrants with eq. 10 (k = {}, pixels with relative noise > {} left "
        "out)",
        2 * options.maxRadius + 1, 2 * options.maxRadius + 1, options.targetNoise,
        options.disagreement, result.meanRadius, result.largestRadius, options.k,
        options.goodNoise));
    result.plan.push_back(
        "eqs. 11-13: combined square/quadrant fits averaged over every square holding the "
        "pixel (a gather), times the pivot");
    inStrips("gather", [&](int rowBase, int rows) {
        RecordPivotGather(context, recorder, colorGpu, pivotGpu, nu, fitLo, fitHi, guides,
                          tiles, result.largestRadius, out, rowBase, rows);
    });
    // Per kernel, summed over the strips.
    std::vector<std::pair<std::string, double>> perKernel;
    for (const vk::DispatchTiming &t : result.timings) {
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
    result.plan.push_back(fmt::format("GPU time: {} ({} row strip(s) of up to {} rows)", times,
                                      (h + stripRows - 1) / stripRows, stripRows));
    result.image = out.Download();
    if (options.keepStages) {
        Image fits(w, h, PIVOT_PLANES * channels);
        Image lo = fitLo.Download(), hi = fitHi.Download();
        std::copy(lo.data.begin(), lo.data.end(), fits.data.begin());
        std::copy(hi.data.begin(), hi.data.end(), fits.data.begin() + lo.data.size());
        result.stages = {{"z", z.Download()},
                         {"nu", nu.Download()},
                         {"fits", std::move(fits)},
                         {"output", result.image}};
    }
    return result;
}

}  // namespace

PivotResult PivotDenoise(vk::Context &context, const PivotInputs &in,
                         const PivotOptions &options) {
    if (in.partials.empty()) return PivotDenoiseOne(context, in, options);
    if (!in.color || !in.pivot) throw Error("pivot: needs the color and pivot layers");
    int w = in.color->width, h = in.color->height, channels = in.color->channels;
    if (channels < 1 || channels > PIVOT_MAX_CHANNELS || w < 1 || h < 1)
        throw Error(fmt::format("pivot: color is {}x{}x{}; 1 to {} channels are supported", w,
                                h, channels, PIVOT_MAX_CHANNELS));
    CheckLayer(*in.pivot, "pivot", w, h, channels, false);
    if (!in.remainder) throw Error("pivot: partial images need the remainder layer");
    CheckLayer(*in.remainder, "remainder", w, h, channels, false);
    PivotResult result;
    result.image = Image(w, h, channels);
    double radiusSum = 0;
    for (size_t k = 0; k < in.partials.size(); ++k) {
        const PivotPartial &partial = in.partials[k];
        std::string name = fmt::format("partial{}", k);
        if (!partial.color || !partial.pivot)
            throw Error(fmt::format("pivot: {} needs its color and pivot", name));
        CheckLayer(*partial.color, (name + ".color").c_str(), w, h, channels, false);
        CheckLayer(*partial.pivot, (name + ".pivot").c_str(), w, h, channels, false);
        if (partial.variance)
            CheckLayer(*partial.variance, (name + ".variance").c_str(), w, h, channels, true);
        PivotInputs one = in;
        one.color = partial.color;
        one.pivot = partial.pivot;
        one.variance = partial.variance;
        one.partials.clear();
        one.remainder = nullptr;
        PivotResult r = PivotDenoiseOne(context, one, options);
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
