#include "tools/render/renderer.h"

#include <fmt/format.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <functional>
#include <mutex>
#include <sstream>
#include <system_error>
#include <thread>

#include "host/error.h"

namespace mcd::render {

unsigned ParseLayerGroups(const std::string &text) {
    unsigned groups = 0;
    std::stringstream in(text);
    std::string item;
    while (std::getline(in, item, ',')) {
        if (item == "hist")
            groups |= kLayersHist;
        else if (item == "split")
            groups |= kLayersSplit;
        else if (item == "pivot")
            groups |= kLayersPivot;
        else if (item == "gbuffer")
            groups |= kLayersGbuffer;
        else if (item == "partials")
            groups |= kLayersPartials;
        else if (item == "zhist")
            groups |= kLayersZHist | kLayersPivot;
        else if (item == "halves")
            groups |= kLayersHalves;
        else if (item == "all")
            groups |= kLayersAll;
        else if (!item.empty())
            throw Error(
                fmt::format("unknown layer group '{}' (hist, split, pivot, gbuffer, partials, "
                            "zhist, halves, "
                            "all)",
                            item));
    }
    return groups;
}

void AddToHistogram(const double color[3], int bins, float *histogram) {
    const double gamma = 2.2, scale = 2.5, saturation = 2.0;
    for (int c = 0; c < 3; ++c) {
        double v = std::max(color[c], 0.0);
        v = std::min(std::pow(v, 1 / gamma) / scale, saturation);
        double fbin = v * (bins - 2);
        int low = int(std::floor(fbin));
        double high;
        if (low < bins - 2) {
            high = fbin - low;
        } else {
            // The last bin stands for the saturation value: split [1, saturation] linearly.
            low = bins - 2;
            high = (v - 1) / (saturation - 1);
        }
        histogram[c * bins + low] += float(1 - high);
        histogram[c * bins + low + 1] += float(high);
    }
}

namespace {

void CheckRenderOptions(const RenderOptions &o) {
    if (o.width <= 0 || o.height <= 0)
        throw Error(fmt::format("image size {}x{} must be positive", o.width, o.height));
    if (o.spp <= 0)
        throw Error(fmt::format("samples per pixel must be positive, not {}", o.spp));
    // Sample keys are pixel << 24 | sample: more would reuse another sample's random numbers.
    if (o.spp >= (1 << 24))
        throw Error(fmt::format("at most {} samples per pixel, not {}", (1 << 24) - 1, o.spp));
    if (o.histBins < 3) throw Error("a histogram needs at least 3 bins per channel");
}

// Every layer the options ask for; the others stay empty.
struct FrameLayers {
    explicit FrameLayers(const RenderOptions &o) {
        const int w = o.width, h = o.height, bins = o.histBins;
        color = Image(w, h, 3), variance = Image(w, h, 3), spp = Image(w, h, 1);
        mn = Image(w, h, 3), mx = Image(w, h, 3);
        if (o.layers & kLayersHist) hist = Image(w, h, 3 * bins + 1);
        if (o.layers & kLayersZHist) zhist = Image(w, h, 3 * bins + 1);
        if (o.layers & kLayersSplit) direct = Image(w, h, 3), indirect = Image(w, h, 3);
        if (o.layers & (kLayersPivot | kLayersZHist)) pivot = Image(w, h, 3);
        if (o.layers & kLayersPartials)
            for (int k = 0; k <= kPartialTypes; ++k) {
                partialColors.emplace_back(w, h, 3);
                if (k < kPartialTypes)
                    partialPivots.emplace_back(w, h, 3), partialVariances.emplace_back(w, h, 3);
            }
        if (o.layers & kLayersHalves) half0 = Image(w, h, 3), half1 = Image(w, h, 3);
        if (o.layers & kLayersGbuffer) {
            albedo = Image(w, h, 3), normal = Image(w, h, 3), depth = Image(w, h, 1);
            objectId = Image(w, h, 1), partId = Image(w, h, 1);
        }
    }

    // Into result.layers, in ARCHITECTURE.md order.
    void MoveInto(RenderResult &result) {
        auto add = [&](const char *name, Image &image) {
            if (!image.Empty()) result.layers.emplace_back(name, std::move(image));
        };
        add("color", color);
        add("variance", variance);
        add("spp", spp);
        add("min", mn);
        add("max", mx);
        add("hist", hist);
        add("zhist", zhist);
        add("direct", direct);
        add("indirect", indirect);
        add("pivot", pivot);
        add("albedo", albedo);
        add("normal", normal);
        add("depth", depth);
        add("objectId", objectId);
        add("partId", partId);
        for (int k = 0; k < int(partialPivots.size()); ++k) {
            result.layers.emplace_back(fmt::format("partial{}.color", k),
                                       std::move(partialColors[k]));
            result.layers.emplace_back(fmt::format("partial{}.pivot", k),
                                       std::move(partialPivots[k]));
            result.layers.emplace_back(fmt::format("partial{}.variance", k),
                                       std::move(partialVariances[k]));
        }
        if (!partialColors.empty())
            result.layers.emplace_back("remainder", std::move(partialColors.back()));
        add("half0.color", half0);
        add("half1.color", half1);
    }

    Image color, variance, spp, mn, mx;
    Image hist, zhist, direct, indirect, pivot, albedo, normal, depth, objectId, partId;
    Image half0, half1;  // means of the even and of the odd samples
    // partial0.color, partial1.color, ..., remainder, then the partials' pivots.
    std::vector<Image> partialColors, partialPivots, partialVariances;
};

// Sums over one pixel's samples, and its histograms' buckets.
struct PixelSums {
    PixelSums() = default;
    explicit PixelSums(int bins) : bucket(3 * bins), zbucket(3 * bins) {}
    // Zero for the next pixel, keeping the buckets' memory.
    void Reset() {
        std::vector<float> keep = std::move(bucket), zkeep = std::move(zbucket);
        *this = PixelSums();
        bucket = std::move(keep), zbucket = std::move(zkeep);
        std::fill(bucket.begin(), bucket.end(), 0.f);
        std::fill(zbucket.begin(), zbucket.end(), 0.f);
    }

    double sum[3] = {}, sumSq[3] = {}, lo[3] = {INFINITY, INFINITY, INFINITY},
           hi[3] = {-INFINITY, -INFINITY, -INFINITY}, sumDirect[3] = {}, sumIndirect[3] = {},
           sumAlbedo[3] = {}, sumNormal[3] = {}, sumDepth = 0, sumHalf[2][3] = {};
    Vec3 sumPartial[kPartialTypes + 1], sumSqPartial[kPartialTypes + 1];
    int firstObject = 0, firstPart = 0;
    uint64_t nonFinite = 0;  // paths that produced NaN/Inf (counted as 0)
    std::vector<float> bucket, zbucket;
};

// Deterministic: a fixed 4x4 grid of pinhole rays per pixel.
void RenderPivot(const Scene &scene, int x, int y, int w, int h, Image &pivot) {
    Vec3 sumPivot(0);
    for (int j = 0; j < 16; ++j) {
        double sx = x + (j % 4 + 0.5) / 4, sy = y + (j / 4 + 0.5) / 4;
        sumPivot += PivotRadiance(scene, scene.camera.Generate(sx, sy, w, h, 0.0, 0.0));
    }
    for (int c = 0; c < 3; ++c) pivot.At(c, y, x) = float(sumPivot[c] / 16);
}

// Trace the pixel's samples into `sums` (the pivot layer, when there is one, is written).
void SamplePixel(const SampleSource &source, const RenderOptions &o, const FrameLayers &layers,
                 int x, int y, PixelSums &sums) {
    const int bins = o.histBins;
    uint64_t pixel = uint64_t(y) * o.width + x;
    for (int s = 0; s < o.spp; ++s) {
        // Box reconstruction filter: uniform positions inside the pixel.
        Rng jitter(Mix(o.seed ^ Mix(~(pixel << 24 | uint64_t(s)))), pixel);
        double px = x + Uniform(jitter), py = y + Uniform(jitter);
        PathSample p = source.Trace(px, py, pixel << 24 | uint64_t(s));
        double c3[3] = {p.color.x, p.color.y, p.color.z};
        if (!std::isfinite(c3[0]) || !std::isfinite(c3[1]) || !std::isfinite(c3[2])) {
            ++sums.nonFinite;
            p.color = p.direct = p.indirect = Vec3(0);
            for (Vec3 &part : p.partial) part = Vec3(0);
            c3[0] = c3[1] = c3[2] = 0;
        }
        for (int c = 0; c < 3; ++c) {
            sums.sum[c] += c3[c];
            sums.sumHalf[s % 2][c] += c3[c];
            sums.sumSq[c] += c3[c] * c3[c];
            sums.lo[c] = std::min(sums.lo[c], c3[c]);
            sums.hi[c] = std::max(sums.hi[c], c3[c]);
            sums.sumDirect[c] += p.direct[c];
            sums.sumIndirect[c] += p.indirect[c];
            sums.sumAlbedo[c] += p.albedo[c];
            sums.sumNormal[c] += p.normal[c];
        }
        for (int k = 0; k <= kPartialTypes; ++k) {
            sums.sumPartial[k] += p.partial[k];
            sums.sumSqPartial[k] += p.partial[k] * p.partial[k];
        }
        sums.sumDepth += p.depth;
        if (s == 0) sums.firstObject = p.objectId, sums.firstPart = p.partId;
        if (!layers.hist.Empty()) AddToHistogram(c3, bins, sums.bucket.data());
        if (!layers.zhist.Empty()) {
            // Divided by the layer's float pivot, as the denoiser will.
            double z3[3];
            for (int c = 0; c < 3; ++c) {
                float a = layers.pivot.At(c, y, x);
                z3[c] = a > 0 ? c3[c] / a : c3[c];
            }
            AddToHistogram(z3, bins, sums.zbucket.data());
        }
    }
}

// The pixel's means, variances of the mean, ranges, G-buffer and histograms.
void WritePixel(const PixelSums &sums, const RenderOptions &o, int x, int y,
                FrameLayers &layers) {
    const int bins = o.histBins;
    double n = o.spp;
    for (int c = 0; c < 3; ++c) {
        double mean = sums.sum[c] / n;
        layers.color.At(c, y, x) = float(mean);
        // Variance of the mean: the unbiased sample variance over n.
        double var = n > 1 ? std::max(0.0, (sums.sumSq[c] - n * mean * mean) / (n - 1)) : 0;
        layers.variance.At(c, y, x) = float(var / n);
        layers.mn.At(c, y, x) = float(sums.lo[c]);
        layers.mx.At(c, y, x) = float(sums.hi[c]);
        if (!layers.direct.Empty()) {
            layers.direct.At(c, y, x) = float(sums.sumDirect[c] / n);
            layers.indirect.At(c, y, x) = float(sums.sumIndirect[c] / n);
        }
        if (!layers.half0.Empty()) {
            // Sample s goes to half s % 2: ceil(n / 2) and floor(n / 2) samples.
            int even = (o.spp + 1) / 2, odd = o.spp / 2;
            layers.half0.At(c, y, x) = float(sums.sumHalf[0][c] / even);
            layers.half1.At(c, y, x) = odd > 0 ? float(sums.sumHalf[1][c] / odd) : 0.f;
        }
        if (!layers.albedo.Empty()) {
            layers.albedo.At(c, y, x) = float(sums.sumAlbedo[c] / n);
            layers.normal.At(c, y, x) = float(sums.sumNormal[c] / n);
        }
    }
    layers.spp.At(0, y, x) = float(n);
    if (!layers.depth.Empty()) {
        layers.depth.At(0, y, x) = float(sums.sumDepth / n);
        layers.objectId.At(0, y, x) = float(sums.firstObject);
        layers.partId.At(0, y, x) = float(sums.firstPart);
    }
    if (!layers.hist.Empty()) {
        for (int b = 0; b < 3 * bins; ++b) layers.hist.At(b, y, x) = sums.bucket[b];
        layers.hist.At(3 * bins, y, x) = float(n);
    }
    if (!layers.zhist.Empty()) {
        for (int b = 0; b < 3 * bins; ++b) layers.zhist.At(b, y, x) = sums.zbucket[b];
        layers.zhist.At(3 * bins, y, x) = float(n);
    }
}

// Ershov section 8: the partials' means and variances, and their pivots: the pivot's grid
// of rays, its terms split by mirror prefix.
void WritePartials(const Scene &scene, const PixelSums &sums, const RenderOptions &o, int x,
                   int y, FrameLayers &layers) {
    const int w = o.width, h = o.height;
    double n = o.spp;
    Vec3 sumPivot[kPartialTypes + 1];
    for (int j = 0; j < 16; ++j) {
        double sx = x + (j % 4 + 0.5) / 4, sy = y + (j / 4 + 0.5) / 4;
        Vec3 terms[kPartialTypes + 1];
        PivotPartials(scene, scene.camera.Generate(sx, sy, w, h, 0.0, 0.0), terms);
        for (int k = 0; k <= kPartialTypes; ++k) sumPivot[k] += terms[k];
    }
    for (int k = 0; k <= kPartialTypes; ++k)
        for (int c = 0; c < 3; ++c) {
            double mean = sums.sumPartial[k][c] / n;
            layers.partialColors[k].At(c, y, x) = float(mean);
            if (k == kPartialTypes) continue;
            layers.partialPivots[k].At(c, y, x) = float(sumPivot[k][c] / 16);
            // As the variance layer: of the mean, unbiased.
            double var =
                n > 1 ? std::max(0.0, (sums.sumSqPartial[k][c] - n * mean * mean) / (n - 1))
                      : 0;
            layers.partialVariances[k].At(c, y, x) = float(var / n);
        }
}

// Every layer's value at pixel (x, y); returns its non-finite paths.
uint64_t RenderPixel(const Scene &scene, const SampleSource &source, const RenderOptions &o,
                     int x, int y, PixelSums &sums, FrameLayers &layers) {
    sums.Reset();
    if (!layers.pivot.Empty()) RenderPivot(scene, x, y, o.width, o.height, layers.pivot);
    SamplePixel(source, o, layers, x, y, sums);
    WritePixel(sums, o, x, y, layers);
    if (!layers.partialColors.empty()) WritePartials(scene, sums, o, x, y, layers);
    return sums.nonFinite;
}

// Call `work` on `threads` threads, this one included. A thread that cannot start leaves
// its share to the rest.
void RunOnThreads(int threads, const std::function<void()> &work) {
    std::vector<std::thread> pool;
    for (int t = 1; t < threads; ++t) {
        try {
            pool.emplace_back(work);
        } catch (const std::system_error &) {
            break;
        }
    }
    work();
    for (std::thread &t : pool) t.join();
}

std::map<std::string, std::string> RenderMetadata(const Scene &scene, const RenderOptions &o,
                                                  const RenderResult &result) {
    return {{"mcd:scene", scene.name},
            {"mcd:spp", std::to_string(o.spp)},
            {"mcd:seed", std::to_string(o.seed)},
            {"mcd:size", fmt::format("{}x{}", o.width, o.height)},
            {"mcd:renderSeconds", fmt::format("{:.3f}", result.seconds)},
            {"mcd:renderer", fmt::format("mcdenoise path tracer {}", kRendererVersion)},
            {"mcd:nonFiniteSamples", std::to_string(result.nonFiniteSamples)}};
}

}  // namespace

PathSample SampleSource::Trace(double x, double y, uint64_t key) const {
    Rng rng(Mix(seed ^ Mix(key)), key);
    double lu = Uniform(rng), lv = Uniform(rng);
    return TracePath(scene, scene.camera.Generate(x, y, width, height, lu, lv), rng);
}

RenderResult Render(const Scene &scene, const RenderOptions &o) {
    CheckRenderOptions(o);
    auto start = std::chrono::steady_clock::now();
    FrameLayers layers(o);
    SampleSource source(scene, o.width, o.height, o.seed);
    std::atomic<int> nextRow{0}, rowsDone{0};
    std::atomic<uint64_t> nonFinite{0};
    std::mutex progressMutex;
    auto renderRows = [&] {
        PixelSums sums(o.histBins);
        for (int y = nextRow++; y < o.height; y = nextRow++) {
            for (int x = 0; x < o.width; ++x)
                nonFinite += RenderPixel(scene, source, o, x, y, sums, layers);
            int done = ++rowsDone;
            if (o.progress) {
                std::lock_guard<std::mutex> lock(progressMutex);
                o.progress(done, o.height);
            }
        }
    };
    // Rows are handed out one at a time, so any number of threads gives the same frame; more
    // threads than rows would idle.
    int threads =
        o.threads > 0 ? o.threads : int(std::max(1u, std::thread::hardware_concurrency()));
    RunOnThreads(std::clamp(threads, 1, std::min(o.height, 1024)), renderRows);

    RenderResult result;
    result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    result.nonFiniteSamples = nonFinite;
    layers.MoveInto(result);
    result.metadata = RenderMetadata(scene, o, result);
    return result;
}

}  // namespace mcd::render
