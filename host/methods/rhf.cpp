#include "host/methods/rhf.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <memory>

#include "host/error.h"
#include "host/kernels/rhf_aggregate.h"
#include "host/kernels/rhf_combine.h"
#include "host/kernels/rhf_distance.h"
#include "host/kernels/rhf_downsample.h"
#include "host/kernels/rhf_select.h"
#include "host/kernels/rhf_terms.h"
#include "host/vk/gpu_image.h"
#include "rhf/terms.h"

namespace mcd {
namespace {

constexpr int kMaxSearchHalf = 20;
constexpr int kMaxScales = 8;

double SigmaOfScale(int s) {
    return 0.55 * std::sqrt(std::pow(4.0, s) - 1);
}

int Shrunk(int extent, int s) {
    return (extent + (1 << s) - 1) >> s;
}

// How much each full-resolution column (or row) weighs in the sum of D_s's output: the
// taps that land on it, clamped edges included. The downsampled histograms' total is then
// the full-resolution one weighted by column times row weights, known without reading
// anything back from the GPU.
std::vector<double> ColumnWeights(int extent, int s, const std::vector<float> &taps) {
    int radius = int(taps.size() / 2), step = 1 << s;
    std::vector<double> weights(extent, 0.0);
    for (int x = 0; x < Shrunk(extent, s); ++x)
        for (int i = -radius; i <= radius; ++i)
            weights[std::clamp(step * x + i, 0, extent - 1)] += taps[i + radius];
    return weights;
}

// Replace what the filter cannot use, and say how much of it there was.
std::vector<std::string> Sanitize(Image &color, Image &hist) {
    const int W = color.width, H = color.height, n3 = hist.channels - 1;
    size_t badColor = 0, badHist = 0, empty = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            bool colorOk = true, histOk = true;
            for (int c = 0; c < 3; ++c)
                if (!std::isfinite(color.At(c, y, x))) colorOk = false;
            double total = 0;
            for (int i = 0; i <= n3; ++i) {
                float &v = hist.At(i, y, x);
                if (!std::isfinite(v) || v < 0) {
                    histOk = false;
                    v = 0;
                }
                if (i < n3) total += v;
            }
            if (!colorOk) {
                // Nothing to average: a black pixel whose histogram matches nothing.
                for (int c = 0; c < 3; ++c) color.At(c, y, x) = 0;
                for (int i = 0; i <= n3; ++i) hist.At(i, y, x) = 0;
            }
            badColor += !colorOk;
            badHist += colorOk && !histOk;
            empty += colorOk && (hist.At(n3, y, x) == 0 || total == 0);
        }
    std::vector<std::string> warnings;
    if (badColor)
        warnings.push_back(fmt::format(
            "rhf: {} pixel(s) have a NaN/Inf colour; they were taken as black pixels without "
            "samples",
            badColor));
    if (badHist)
        warnings.push_back(fmt::format(
            "rhf: {} pixel(s) have NaN/Inf/negative histogram bins or counts; those were set "
            "to 0",
            badHist));
    if (empty)
        warnings.push_back(fmt::format(
            "rhf: {} pixel(s) have no samples (count 0 or an empty histogram); their patches "
            "are compared on their other pixels only",
            empty));
    return warnings;
}

}  // namespace

int RhfScalesUsed(int width, int height, const RhfOptions &options) {
    int side = 2 * options.searchHalf + 1, used = 1;
    while (used < options.scales && Shrunk(width, used) >= side && Shrunk(height, used) >= side)
        ++used;
    return used;
}

RhfResult RhfDenoise(vk::Context &context, const Image &colorIn, const Image &histIn,
                     const RhfOptions &o) {
    if (colorIn.channels != 3)
        throw Error(fmt::format("rhf: the color layer has {} channels; expected 3 (R, G, B)",
                                colorIn.channels));
    if (histIn.channels < 4 || (histIn.channels - 1) % 3 != 0)
        throw Error(
            fmt::format("rhf: the histogram layer has {} channels; expected 3n+1 (n "
                        "bins for each of R, G, B, then the sample count)",
                        histIn.channels));
    if (histIn.width != colorIn.width || histIn.height != colorIn.height)
        throw Error(fmt::format("rhf: the color layer is {}x{} but the histograms are {}x{}",
                                colorIn.width, colorIn.height, histIn.width, histIn.height));
    if (colorIn.width <= 0 || colorIn.height <= 0) throw Error("rhf: the image is empty");
    if (o.patchHalf < 0 || o.patchHalf > kMaxSearchHalf)
        throw Error(fmt::format("rhf: patch half-size must be in 0..{}, not {}", kMaxSearchHalf,
                                o.patchHalf));
    if (o.searchHalf < 0 || o.searchHalf > kMaxSearchHalf)
        throw Error(fmt::format("rhf: search half-window must be in 0..{}, not {}",
                                kMaxSearchHalf, o.searchHalf));
    int side = 2 * o.searchHalf + 1, offsets = side * side;
    if (o.knn < 0 || o.knn > offsets)
        throw Error(fmt::format("rhf: kNN must be in 0..{} (the search window), not {}",
                                offsets, o.knn));
    if (!std::isfinite(o.threshold) || o.threshold < 0)
        throw Error(fmt::format("rhf: the threshold must be a finite number >= 0, not {}",
                                o.threshold));
    if (!std::isfinite(o.brightVeto) || o.brightVeto < 0)
        throw Error(fmt::format("rhf: the bright veto must be a finite number >= 0, not {}",
                                o.brightVeto));
    if (o.scales < 1 || o.scales > kMaxScales)
        throw Error(fmt::format("rhf: scales must be in 1..{}, not {}", kMaxScales, o.scales));

    RhfResult result;
    Image color = colorIn, hist = histIn;
    result.warnings = Sanitize(color, hist);
    const int W = color.width, H = color.height, planes = hist.channels, n3 = planes - 1;
    const size_t pixels = color.PixelCount();
    const size_t maxFloats = std::min<size_t>(context.BindingBytes() / sizeof(float), 1u << 25);

    // The selection mask is one binding: refuse, before any work, a frame it cannot hold.
    size_t maskBytes = size_t(RhfMaskWords(o.searchHalf)) * pixels * sizeof(uint32_t);
    if (maskBytes > context.Limits().maxStorageBufferRange)
        throw Error(fmt::format(
            "rhf: a {}x{} frame with search half-window {} needs a {:.0f} MB selection mask, "
            "above this device's {:.0f} MB per binding; crop the frame or shrink the window",
            W, H, o.searchHalf, maskBytes / 1e6, context.Limits().maxStorageBufferRange / 1e6));

    // Histogram planes per buffer, and centre rows per distance strip.
    int perSlot = o.planesPerSlot > 0 ? o.planesPerSlot
                                      : int(std::min<size_t>(planes, maxFloats / pixels));
    if (perSlot < 1 || (planes + perSlot - 1) / perSlot > RHF_HIST_SLOTS)
        throw Error(
            fmt::format("rhf: a {}x{} frame's {} histogram planes do not fit in {} "
                        "buffers of {} floats",
                        W, H, planes, RHF_HIST_SLOTS, maxFloats));
    // A strip's distances take offsets x rows x W floats, its terms (b+1)(2b+1) x (rows +
    // 2w + b) x W: both within one binding.
    size_t rowFloats = size_t(offsets) * W, termRowFloats = size_t(o.searchHalf + 1) * side * W;
    int apron = 2 * o.patchHalf + o.searchHalf;
    int stripRows =
        o.stripRows > 0
            ? o.stripRows
            : int(std::min<size_t>(maxFloats / rowFloats, maxFloats / termRowFloats - apron));
    stripRows = std::min(stripRows, H);
    if (stripRows < 1 || maxFloats / termRowFloats <= size_t(apron))
        throw Error(
            fmt::format("rhf: a {}-pixel-wide image needs more than {} floats per "
                        "distance strip; reduce the search window",
                        W, maxFloats));
    int termRowsMax = std::min(H, stripRows + apron);

    int scales = RhfScalesUsed(W, H, o);
    result.scalesUsed = scales;
    for (int s = scales; s < o.scales; ++s)
        result.plan.push_back(
            fmt::format("left out: scale {} ({}x{} is smaller than the "
                        "{}x{} search window)",
                        s, Shrunk(W, s), Shrunk(H, s), side, side));

    // The total of the bins, kept at every scale (Algorithm 3, line 4).
    double total = 0;
    std::vector<double> pixelTotal(pixels, 0.0);
    for (int i = 0; i < n3; ++i)
        for (size_t p = 0; p < pixels; ++p) pixelTotal[p] += hist.Plane(i)[p];
    for (double v : pixelTotal) total += v;

    // Uploads: colour and histograms at full resolution.
    vk::GpuImage colorGpu(context, W, H, 3, "rhf.color");
    colorGpu.Upload(color);
    RhfHistogram full;
    full.width = W;
    full.height = H;
    full.planes = planes;
    full.planesPerSlot = perSlot;
    for (int first = 0; first < planes; first += perSlot) {
        int count = std::min(perSlot, planes - first);
        full.slots.emplace_back(context, size_t(count) * pixels * sizeof(float),
                                fmt::format("rhf.hist{}", first / perSlot));
        full.slots.back().Upload(hist.Plane(first), size_t(count) * pixels * sizeof(float));
    }

    result.plan.push_back(fmt::format(
        "histograms: {} planes ({} bins per colour + the count) in {} buffer(s) of up to {} "
        "planes; distances in strips of up to {} rows",
        planes, n3 / 3, full.slots.size(), perSlot, stripRows));

    // Work buffers, sized for the finest scale and reused by every scale.
    vk::Buffer termSum(context, termRowFloats * termRowsMax * sizeof(float), "rhf.termSum");
    vk::Buffer termCount(context, termRowFloats * termRowsMax * sizeof(float), "rhf.termCount");
    vk::Buffer dist(context, rowFloats * stripRows * sizeof(float), "rhf.distance");
    vk::Buffer mask(context, size_t(RhfMaskWords(o.searchHalf)) * pixels * sizeof(uint32_t),
                    "rhf.mask");
    std::deque<vk::GpuImage> images;
    std::deque<vk::Buffer> buffers;
    std::deque<RhfHistogram> histograms;
    auto taps = [&](double sigma) -> std::pair<const vk::Buffer *, int> {
        std::vector<float> g = RhfGaussianTaps(sigma);
        buffers.emplace_back(context, g.size() * sizeof(float), "rhf.taps");
        buffers.back().UploadFloats(g);
        return {&buffers.back(), int(g.size() / 2)};
    };
    // D_s of `planes` planes of a W x H buffer into dst.
    auto downsample = [&](const vk::Buffer &src, int srcW, int srcH, int count, int s,
                          double sigma, vk::Buffer &dst, vk::Recorder &recorder) {
        auto [weights, radius] = taps(sigma);
        buffers.emplace_back(context, size_t(count) * srcH * Shrunk(srcW, s) * sizeof(float),
                             "rhf.scratch");
        RecordRhfDownsample(context, recorder, src, srcW, srcH, count, 1 << s, *weights, radius,
                            buffers.back(), dst);
    };

    vk::Recorder recorder(context);
    const vk::GpuImage *previous = nullptr;
    std::vector<std::pair<std::string, const vk::GpuImage *>> kept;
    for (int s = scales - 1; s >= 0; --s) {
        const int Ws = Shrunk(W, s), Hs = Shrunk(H, s);
        const vk::GpuImage *u = &colorGpu;
        const RhfHistogram *h = &full;
        float histScale = 1.f;
        if (s > 0) {
            double sigma = SigmaOfScale(s);
            vk::GpuImage &coarseColor =
                images.emplace_back(context, Ws, Hs, 3, fmt::format("rhf.color{}", s));
            u = &coarseColor;
            downsample(colorGpu.buffer, W, H, 3, s, sigma, coarseColor.buffer, recorder);
            kept.push_back({fmt::format("color s{}", s), u});
            RhfHistogram &coarse = histograms.emplace_back();
            coarse.width = Ws;
            coarse.height = Hs;
            coarse.planes = planes;
            coarse.planesPerSlot = perSlot;
            for (size_t slot = 0; slot < full.slots.size(); ++slot) {
                int count = std::min(perSlot, planes - int(slot) * perSlot);
                coarse.slots.emplace_back(context, size_t(count) * Ws * Hs * sizeof(float),
                                          fmt::format("rhf.hist{}.{}", slot, s));
                downsample(full.slots[slot], W, H, count, s, sigma, coarse.slots.back(),
                           recorder);
            }
            h = &coarse;
            // Count-preserving rescale: the coarse bins' total, from the tap weights.
            std::vector<float> g = RhfGaussianTaps(sigma);
            std::vector<double> wx = ColumnWeights(W, s, g), wy = ColumnWeights(H, s, g);
            double coarseTotal = 0;
            for (int y = 0; y < H; ++y)
                for (int x = 0; x < W; ++x)
                    coarseTotal += pixelTotal[size_t(y) * W + x] * wx[x] * wy[y];
            histScale = coarseTotal > 0 ? float(total / coarseTotal) : 1.f;
            result.plan.push_back(fmt::format(
                "scale {}: Gaussian downsampling by {} (sigma {:.4g}) of color and {} "
                "histogram planes to {}x{}; histograms rescaled by {:.9g} to keep the sample "
                "total",
                s, 1 << s, sigma, planes, Ws, Hs, histScale));
        }
        int knn = s == 0 ? o.knn : 0;
        int strips = 0;
        for (int y0 = 0; y0 < Hs; y0 += stripRows, ++strips) {
            int rows = std::min(stripRows, Hs - y0);
            int termBase = std::max(0, y0 - o.patchHalf - o.searchHalf);
            int termRows = std::min(Hs, y0 + rows + o.patchHalf) - termBase;
            RecordRhfTerms(context, recorder, *h, o.searchHalf, termBase, termRows, histScale,
                           o.brightVeto / histScale, termSum, termCount);
            RecordRhfDistance(context, recorder, Ws, Hs, o.patchHalf, o.searchHalf, termBase,
                              termRows, y0, rows, termSum, termCount, dist);
            RecordRhfSelect(context, recorder, Ws, Hs, o.searchHalf, y0, rows, knn, o.threshold,
                            dist, mask);
        }
        vk::GpuImage &filtered =
            images.emplace_back(context, Ws, Hs, 3, fmt::format("rhf.filtered{}", s));
        RecordRhfAggregate(context, recorder, *u, mask, o.patchHalf, o.searchHalf, filtered);
        kept.push_back({fmt::format("filtered s{}", s), &filtered});
        result.plan.push_back(fmt::format(
            "scale {} ({}x{}): chi-square pixel terms for {} offsets x {} bins, {}x{} patch "
            "distances{}, selection of {} nearest + distance < {} in {} strip(s), aggregation",
            s, Ws, Hs, offsets, n3, 2 * o.patchHalf + 1, 2 * o.patchHalf + 1,
            o.brightVeto > 0
                ? fmt::format(" with bright veto {} (in the frame's sample counts)",
                              o.brightVeto)
                : std::string(" (no bright veto)"),
            knn, o.threshold, strips));
        if (previous) {
            double sigma = SigmaOfScale(1);
            vk::GpuImage &low =
                images.emplace_back(context, previous->width, previous->height, 3, "rhf.low");
            downsample(filtered.buffer, Ws, Hs, 3, 1, sigma, low.buffer, recorder);
            vk::GpuImage &combined =
                images.emplace_back(context, Ws, Hs, 3, fmt::format("rhf.combined{}", s));
            RecordRhfCombine(context, recorder, filtered, low, *previous, combined);
            kept.push_back({fmt::format("combined s{}", s), &combined});
            result.plan.push_back(fmt::format(
                "scale {}: u_{} - U(D(u_{})) + U(u_{}) with bicubic U (Keys, a = -0.5)", s, s,
                s, s + 1));
            previous = &combined;
        } else {
            previous = &filtered;
        }
    }
    recorder.Submit();
    result.timings = recorder.Timings();
    result.image = previous->Download();
    if (o.clampNegative) {
        size_t negative = 0;
        for (float &v : result.image.data)
            if (v < 0) {
                v = 0;
                ++negative;
            }
        result.plan.push_back(fmt::format(
            "clamped {} negative value(s) to 0 (the bicubic recombination overshoots at strong "
            "edges; --keep-negative keeps them)",
            negative));
    }
    if (o.keepStages)
        for (const auto &[name, image] : kept)
            result.stages.push_back({name, image->Download()});
    return result;
}

}  // namespace mcd
