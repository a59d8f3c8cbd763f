#include "tools/render/renderer.h"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <sstream>
#include <system_error>
#include <thread>

#include "cpu_reference/tracing_filter.h"
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
                            item),
                ErrorKind::InvalidArgument);
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
        throw Error(fmt::format("image size {}x{} must be positive", o.width, o.height),
                    ErrorKind::InvalidArgument);
    if (o.spp <= 0)
        throw Error(fmt::format("samples per pixel must be positive, not {}", o.spp),
                    ErrorKind::InvalidArgument);
    // Sample keys are pixel << 24 | sample: more would reuse another sample's random numbers.
    if (o.spp >= (1 << 24))
        throw Error(fmt::format("at most {} samples per pixel, not {}", (1 << 24) - 1, o.spp),
                    ErrorKind::InvalidArgument);
    if (o.histBins < 3)
        throw Error("a histogram needs at least 3 bins per channel",
                    ErrorKind::InvalidArgument);
    if (o.tracing.enabled) {
        const TracingParams &p = o.tracing.params;
        if (p.radius < 0 || p.radius > 1000)
            throw Error(fmt::format("tracing filter radius {} is not in 0..1000", p.radius),
                        ErrorKind::InvalidArgument);
        for (auto [name, v] : {std::pair{"alpha", p.alpha},
                               {"beta", p.beta},
                               {"gamma", p.gamma},
                               {"self floor", p.selfFloor}})
            if (!std::isfinite(v) || v < 0)
                throw Error(
                    fmt::format("tracing filter {} {} must be finite and >= 0", name, v),
                    ErrorKind::InvalidArgument);
        if (p.selfFloor > 1)
            throw Error(fmt::format("tracing filter self floor {} is above 1", p.selfFloor),
                        ErrorKind::InvalidArgument);
        if (o.tracing.partials < 1 || o.tracing.partials > kPartialTypes)
            throw Error(fmt::format("tracing filter partials {} is not in 1..{}",
                                    o.tracing.partials, kPartialTypes),
                        ErrorKind::InvalidArgument);
    }
}

// Every layer the options ask for; the others stay empty.
struct FrameLayers {
    explicit FrameLayers(const RenderOptions &o) {
        const int w = o.width, h = o.height, bins = o.histBins;
        color = Image(w, h, 3), variance = Image(w, h, 3), spp = Image(w, h, 1);
        mn = Image(w, h, 3), mx = Image(w, h, 3);
        if (o.layers & kLayersHist) hist = Image(w, h, 3 * bins + 1);
        if (o.layers & kLayersZHist) zhist = Image(w, h, 3 * bins + 1);
        if (o.layers & kLayersSplit) {
            direct = Image(w, h, 3), indirect = Image(w, h, 3);
            directVariance = Image(w, h, 3), indirectVariance = Image(w, h, 3);
        }
        if (o.layers & (kLayersPivot | kLayersZHist)) pivot = Image(w, h, 3);
        if (o.layers & kLayersPartials)
            for (int k = 0; k <= kPartialTypes; ++k) {
                partialColors.emplace_back(w, h, 3);
                if (k < kPartialTypes)
                    partialPivots.emplace_back(w, h, 3), partialVariances.emplace_back(w, h, 3);
            }
        if (o.layers & kLayersHalves) {
            half1 = Image(w, h, 3);
            // half0's own layers from two even samples on (one has no variance), as
            // accumulate writes them from three frames on: auto's runs on half0 read them.
            if (o.spp >= 3) {
                half0Own = std::make_unique<FrameLayers>(Half0Options(o));
                half0Own->objectId = half0Own->partId = Image();  // the first sample's
            } else
                half0 = Image(w, h, 3);
        }
        if (o.tracing.enabled) unfiltered = Image(w, h, 3);
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
        add("color.unfiltered", unfiltered);
        add("variance", variance);
        add("spp", spp);
        add("min", mn);
        add("max", mx);
        add("hist", hist);
        add("zhist", zhist);
        add("direct", direct);
        add("indirect", indirect);
        add("direct.variance", directVariance);
        add("indirect.variance", indirectVariance);
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
        if (half0Own) {
            // half0's colour, then its own layers under "half0.".
            RenderResult own;
            half0Own->MoveInto(own);
            result.layers.emplace_back("half0.color", std::move(own.layers.front().second));
            add("half1.color", half1);
            for (size_t i = 1; i < own.layers.size(); ++i)
                result.layers.emplace_back("half0." + own.layers[i].first,
                                           std::move(own.layers[i].second));
            return;
        }
        add("half0.color", half0);
        add("half1.color", half1);
    }

    // The layers the even samples alone give: no ids, pivot, halves, partials nor tracing.
    static RenderOptions Half0Options(const RenderOptions &o) {
        RenderOptions own = o;
        own.spp = (o.spp + 1) / 2;
        own.layers = o.layers & (kLayersHist | kLayersSplit | kLayersGbuffer);
        own.tracing.enabled = false;
        return own;
    }

    Image color, variance, spp, mn, mx;
    Image hist, zhist, direct, indirect, pivot, albedo, normal, depth, objectId, partId;
    // Variances of the direct and indirect means: with the color's they give the
    // covariance that auto's estimate of bayes's split output needs.
    Image directVariance, indirectVariance;
    Image half0, half1;  // means of the even and of the odd samples
    // From three samples on, half0's own layers (its colour among them) in place of half0.
    std::unique_ptr<FrameLayers> half0Own;
    Image unfiltered;  // color before the tracing filter
    // partial0.color, partial1.color, ..., remainder, then the partials' pivots.
    std::vector<Image> partialColors, partialPivots, partialVariances;
};

// One set of samples' sums: a layer set's means, variances, ranges, G-buffer and histogram.
struct Moments {
    Moments() = default;
    explicit Moments(int bins) : bucket(3 * bins) {}
    // Zero for the next pixel, keeping the bucket's memory.
    void Reset() {
        std::vector<float> keep = std::move(bucket);
        *this = Moments();
        bucket = std::move(keep);
        std::fill(bucket.begin(), bucket.end(), 0.f);
    }
    // Add one sample (its colour c3, already 0 where it was not finite).
    void Add(const PathSample &p, const double c3[3], int bins, bool hist) {
        for (int c = 0; c < 3; ++c) {
            sum[c] += c3[c];
            sumSq[c] += c3[c] * c3[c];
            lo[c] = std::min(lo[c], c3[c]);
            hi[c] = std::max(hi[c], c3[c]);
            sumDirect[c] += p.direct[c];
            sumIndirect[c] += p.indirect[c];
            sumSqDirect[c] += p.direct[c] * p.direct[c];
            sumSqIndirect[c] += p.indirect[c] * p.indirect[c];
            sumAlbedo[c] += p.albedo[c];
            sumNormal[c] += p.normal[c];
        }
        sumDepth += p.depth;
        if (hist) AddToHistogram(c3, bins, bucket.data());
    }

    double sum[3] = {}, sumSq[3] = {}, lo[3] = {INFINITY, INFINITY, INFINITY},
           hi[3] = {-INFINITY, -INFINITY, -INFINITY}, sumDirect[3] = {}, sumIndirect[3] = {},
           sumSqDirect[3] = {}, sumSqIndirect[3] = {}, sumAlbedo[3] = {}, sumNormal[3] = {},
           sumDepth = 0;
    std::vector<float> bucket;
};

// Sums over one pixel's samples: all of them, the even ones alone (half0's own layers),
// the odd ones' colour (half1), the partials and the z histogram.
struct PixelSums {
    PixelSums() = default;
    explicit PixelSums(int bins) : all(bins), even(bins), zbucket(3 * bins) {}
    // Zero for the next pixel, keeping the buckets' memory.
    void Reset() {
        all.Reset(), even.Reset();
        std::fill(zbucket.begin(), zbucket.end(), 0.f);
        for (int c = 0; c < 3; ++c) sumHalf[0][c] = sumHalf[1][c] = 0;
        for (int k = 0; k <= kPartialTypes; ++k) sumPartial[k] = sumSqPartial[k] = Vec3(0);
        firstObject = firstPart = 0;
        nonFinite = 0;
    }

    Moments all, even;
    double sumHalf[2][3] = {};
    Vec3 sumPartial[kPartialTypes + 1], sumSqPartial[kPartialTypes + 1];
    int firstObject = 0, firstPart = 0;
    uint64_t nonFinite = 0;  // paths that produced NaN/Inf (counted as 0)
    std::vector<float> zbucket;
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

// The pixel's surface for the tracing filter from its samples' first hits: the mean
// position, normal and view direction over the samples that have an A (the geometry the
// pixel's own filtered light comes from, jitter included, without the noise of one
// sample), and lobe weights summed over those samples and divided by all of them, so that
// a pixel partly covered by the sky gets that share of the BSDF, as its own samples do.
// Partial k's surface is the same from its A_k (lobe weights times the mirror chain's).
TracingSurface MakeSurface(const TracingPath *paths, int spp, int k) {
    TracingSurface surface{};
    Vec3 position(0), normal(0), wo(0), diffuse(0), glossy(0);
    double kappa = 0;
    int count = 0;
    for (int s = 0; s < spp; ++s) {
        const TracingPartial &p = paths[s].partial[k];
        if (!p.hasSurface) continue;
        position += p.position, normal += p.normal, wo += p.wo;
        diffuse += p.diffuse, glossy += p.glossy, kappa += p.kappa;
        ++count;
    }
    if (count == 0 || Length(normal) <= 0 || Length(wo) <= 0) return surface;
    position = position / count, normal = Normalize(normal), wo = Normalize(wo);
    diffuse = diffuse / spp, glossy = glossy / spp;
    for (int c = 0; c < 3; ++c) {
        surface.position[c] = float(position[c]);
        surface.normal[c] = float(normal[c]);
        surface.wo[c] = float(wo[c]);
        surface.diffuse[c] = float(diffuse[c]);
        surface.glossy[c] = float(glossy[c]);
    }
    surface.kappa = float(kappa / count);
    // Neighbours lend from this share only (the rest hit the sky, an emitter, a mirror).
    surface.valid = float(count) / float(spp);
    return surface;
}

// Where a pixel's tracing-filter records go: per filtered partial k, its surface and spp
// samples; `paths`, spp of scratch.
struct PixelRecords {
    int partials = 0;
    TracingSurface *surface[kPartialTypes] = {};
    TracingSample *samples[kPartialTypes] = {};
    TracingPath *paths = nullptr;
};

// Trace the pixel's samples into `sums` (the pivot layer, when there is one, is written),
// and with `records` the tracing filter's records of the pixel.
void SamplePixel(const SampleSource &source, const RenderOptions &o, const FrameLayers &layers,
                 int x, int y, PixelSums &sums, const PixelRecords *records = nullptr) {
    const int bins = o.histBins;
    uint64_t pixel = uint64_t(y) * o.width + x;
    for (int s = 0; s < o.spp; ++s) {
        // Box reconstruction filter: uniform positions inside the pixel.
        Rng jitter(Mix(o.seed ^ Mix(~(pixel << 24 | uint64_t(s)))), pixel);
        double px = x + Uniform(jitter), py = y + Uniform(jitter);
        TracingPath *path = records ? &records->paths[s] : nullptr;
        if (path) path->partials = records->partials;
        PathSample p = source.Trace(px, py, pixel << 24 | uint64_t(s), path);
        double c3[3] = {p.color.x, p.color.y, p.color.z};
        bool finite = std::isfinite(c3[0]) && std::isfinite(c3[1]) && std::isfinite(c3[2]);
        if (!finite) {
            ++sums.nonFinite;
            p.color = p.direct = p.indirect = Vec3(0);
            for (Vec3 &part : p.partial) part = Vec3(0);
            c3[0] = c3[1] = c3[2] = 0;
        }
        for (int k = 0; records && k < records->partials; ++k) {
            // A sample counted as 0 hands the filter nothing either.
            TracingSample &record = records->samples[k][s];
            record = TracingSample{};
            const TracingPartial &a = path->partial[k];
            if (finite && a.record) {
                for (int c = 0; c < 3; ++c) {
                    record.direction[c] = float(a.direction[c]);
                    record.radiance[c] = float(a.radiance[c]);
                    record.own[c] = float(a.own[c]);
                }
                record.pdf = float(a.pdf);
            }
        }
        const bool hist = !layers.hist.Empty();
        sums.all.Add(p, c3, bins, hist);
        if (layers.half0Own && s % 2 == 0) sums.even.Add(p, c3, bins, hist);
        for (int c = 0; c < 3; ++c) sums.sumHalf[s % 2][c] += c3[c];
        for (int k = 0; k <= kPartialTypes; ++k) {
            sums.sumPartial[k] += p.partial[k];
            sums.sumSqPartial[k] += p.partial[k] * p.partial[k];
        }
        if (s == 0) sums.firstObject = p.objectId, sums.firstPart = p.partId;
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
    for (int k = 0; records && k < records->partials; ++k)
        *records->surface[k] = MakeSurface(records->paths, o.spp, k);
}

// The unbiased sample variance over n: the variance of the mean of n samples.
double VarianceOfMean(double sum, double sumSq, double n) {
    double mean = sum / n;
    return n > 1 ? std::max(0.0, (sumSq - n * mean * mean) / (n - 1)) / n : 0;
}

// A layer set's means, variances of the mean, ranges, G-buffer and histogram from n samples'
// sums.
void WriteMoments(const Moments &m, int bins, double n, int x, int y, FrameLayers &layers) {
    for (int c = 0; c < 3; ++c) {
        layers.color.At(c, y, x) = float(m.sum[c] / n);
        layers.variance.At(c, y, x) = float(VarianceOfMean(m.sum[c], m.sumSq[c], n));
        layers.mn.At(c, y, x) = float(m.lo[c]);
        layers.mx.At(c, y, x) = float(m.hi[c]);
        if (!layers.direct.Empty()) {
            layers.direct.At(c, y, x) = float(m.sumDirect[c] / n);
            layers.indirect.At(c, y, x) = float(m.sumIndirect[c] / n);
            layers.directVariance.At(c, y, x) =
                float(VarianceOfMean(m.sumDirect[c], m.sumSqDirect[c], n));
            layers.indirectVariance.At(c, y, x) =
                float(VarianceOfMean(m.sumIndirect[c], m.sumSqIndirect[c], n));
        }
        if (!layers.albedo.Empty()) {
            layers.albedo.At(c, y, x) = float(m.sumAlbedo[c] / n);
            layers.normal.At(c, y, x) = float(m.sumNormal[c] / n);
        }
    }
    layers.spp.At(0, y, x) = float(n);
    if (!layers.depth.Empty()) layers.depth.At(0, y, x) = float(m.sumDepth / n);
    if (!layers.hist.Empty()) {
        for (int b = 0; b < 3 * bins; ++b) layers.hist.At(b, y, x) = m.bucket[b];
        layers.hist.At(3 * bins, y, x) = float(n);
    }
}

// The pixel's layers: its samples' moments, ids, half-buffers and z histogram.
void WritePixel(const PixelSums &sums, const RenderOptions &o, int x, int y,
                FrameLayers &layers) {
    const int bins = o.histBins;
    // Sample s goes to half s % 2: ceil(n / 2) and floor(n / 2) samples.
    const int even = (o.spp + 1) / 2, odd = o.spp / 2;
    WriteMoments(sums.all, bins, o.spp, x, y, layers);
    if (layers.half0Own) WriteMoments(sums.even, bins, even, x, y, *layers.half0Own);
    for (int c = 0; c < 3; ++c) {
        if (!layers.half0.Empty()) layers.half0.At(c, y, x) = float(sums.sumHalf[0][c] / even);
        if (!layers.half1.Empty())
            layers.half1.At(c, y, x) = odd > 0 ? float(sums.sumHalf[1][c] / odd) : 0.f;
    }
    if (!layers.objectId.Empty()) {
        layers.objectId.At(0, y, x) = float(sums.firstObject);
        layers.partId.At(0, y, x) = float(sums.firstPart);
    }
    if (!layers.zhist.Empty()) {
        for (int b = 0; b < 3 * bins; ++b) layers.zhist.At(b, y, x) = sums.zbucket[b];
        layers.zhist.At(3 * bins, y, x) = float(o.spp);
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
            layers.partialVariances[k].At(c, y, x) =
                float(VarianceOfMean(sums.sumPartial[k][c], sums.sumSqPartial[k][c], n));
        }
}

// Every layer's value at pixel (x, y); returns its non-finite paths.
uint64_t RenderPixel(const Scene &scene, const SampleSource &source, const RenderOptions &o,
                     int x, int y, PixelSums &sums, FrameLayers &layers,
                     const PixelRecords *records = nullptr) {
    sums.Reset();
    if (!layers.pivot.Empty()) RenderPivot(scene, x, y, o.width, o.height, layers.pivot);
    SamplePixel(source, o, layers, x, y, sums, records);
    WritePixel(sums, o, x, y, layers);
    if (!layers.partialColors.empty()) WritePartials(scene, sums, o, x, y, layers);
    return sums.nonFinite;
}

// Call `work` on `threads` threads, this one included. A thread that cannot start leaves
// its share to the rest.
void RunOnThreads(int threads, const std::function<void()> &work) {
    // An exception (an allocation failing in the CPU gather) is kept, every thread joined,
    // and the first one rethrown here: escaping a thread would end the process.
    std::mutex mutex;
    std::exception_ptr failure;
    auto guarded = [&] {
        try {
            work();
        } catch (...) {
            std::lock_guard<std::mutex> lock(mutex);
            if (!failure) failure = std::current_exception();
        }
    };
    std::vector<std::thread> pool;
    for (int t = 1; t < threads; ++t) {
        try {
            pool.emplace_back(guarded);
        } catch (const std::system_error &) {
            break;
        }
    }
    guarded();
    for (std::thread &t : pool) t.join();
    if (failure) std::rethrow_exception(failure);
}

// The tracing filter's own mean of a pixel, in the reference's arithmetic (eq. 16 with
// self weight 1): a pixel the gather leaves to itself keeps its color bit for bit.
float OwnMean(const TracingSurface &surface, const TracingSample *samples, int spp, int c) {
    double sum = 0;
    if (surface.valid > 0) {
        for (int s = 0; s < spp; ++s) sum += 1.0 * samples[s].own[c] / spp;
        return float(sum);
    }
    for (int s = 0; s < spp; ++s) sum += samples[s].own[c];
    return float(sum / spp);
}

// Rows [y0, y0 + rows) of the frame take partial k's filtered part in place of its own
// mean: color (which starts as its unfiltered copy), and the layers that split color
// (partial k, indirect: the light after A_k is indirect), so that their sums still equal
// color.
void ApplyFiltered(const TracingRecords &window, const std::vector<float> &filtered, int y0,
                   int rows, int k, FrameLayers &layers) {
    const int w = window.width, spp = window.spp;
    for (int y = y0; y < y0 + rows; ++y)
        for (int x = 0; x < w; ++x) {
            size_t pixel = size_t(y - window.y0) * w + x;
            const TracingSample *samples = &window.samples[pixel * spp];
            for (int c = 0; c < 3; ++c) {
                double delta = double(filtered[(size_t(y - y0) * w + x) * 3 + c]) -
                               double(OwnMean(window.surfaces[pixel], samples, spp, c));
                auto shift = [&](Image &image) {
                    if (!image.Empty()) image.At(c, y, x) = float(image.At(c, y, x) + delta);
                };
                shift(layers.color);
                shift(layers.indirect);
                if (!layers.partialColors.empty()) shift(layers.partialColors[k]);
            }
        }
}

// The reference gather on `threads` threads, a row at a time (each pixel is computed on
// its own, so the result does not depend on the split).
std::vector<float> ReferenceGather(const TracingRecords &records, const TracingParams &params,
                                   int outY0, int outRows, int threads) {
    std::vector<float> out(size_t(records.width) * outRows * 3);
    std::atomic<int> next{0};
    RunOnThreads(std::clamp(threads, 1, outRows), [&] {
        for (int r = next++; r < outRows; r = next++) {
            std::vector<float> row = ref::TracingFilter(records, params, outY0 + r, 1);
            std::copy(row.begin(), row.end(), out.begin() + size_t(r) * records.width * 3);
        }
    });
    return out;
}

// The band height of the tracing filter's render (rows filtered per gather), from the
// memory budget and the gather's largest window; sets the stats' band and partials.
int TracedBandRows(const RenderOptions &o, int partials, int radius, TracingStats &stats) {
    const TracingFilterOptions &t = o.tracing;
    // A row's records for every filtered partial image.
    const size_t rowBytes = size_t(partials) * size_t(o.width) *
                            (sizeof(TracingSurface) + size_t(o.spp) * sizeof(TracingSample));
    int band = t.bandRows;
    if (band <= 0) {
        long fit = long(t.memoryBudget / rowBytes) - 2L * radius;
        stats.overBudget = fit < 1;
        band = int(std::clamp(fit, 1L, long(o.height)));
    }
    if (t.maxWindowRows > 0) {
        if (t.maxWindowRows - 2 * radius < 1)
            throw Error(fmt::format("tracing filter: the gather takes at most {} rows of "
                                    "records, fewer than one "
                                    "band row and a radius of {} above and below",
                                    t.maxWindowRows, radius),
                        ErrorKind::OutOfMemory);
        band = std::min(band, t.maxWindowRows - 2 * radius);
    }
    band = std::min(band, o.height);
    stats.bandRows = band;
    stats.partials = partials;
    return band;
}

// The capacity of the windows' records, in bytes.
size_t RecordBytes(const std::vector<TracingRecords> &windows) {
    size_t bytes = 0;
    for (const TracingRecords &window : windows)
        bytes += window.surfaces.capacity() * sizeof(TracingSurface) +
                 window.samples.capacity() * sizeof(TracingSample);
    return bytes;
}

// Slide each window to rows [keepFrom, need): drop the rows no later band reads, make room
// for the new ones.
void SlideWindows(std::vector<TracingRecords> &windows, int keepFrom, int need) {
    for (TracingRecords &window : windows) {
        const int w = window.width, spp = window.spp;
        if (int drop = keepFrom - window.y0; drop > 0) {
            window.surfaces.erase(window.surfaces.begin(),
                                  window.surfaces.begin() + size_t(drop) * w);
            window.samples.erase(window.samples.begin(),
                                 window.samples.begin() + size_t(drop) * w * spp);
            window.y0 = keepFrom;
        }
        window.rows = need - window.y0;
        window.surfaces.resize(size_t(window.rows) * w);
        window.samples.resize(size_t(window.rows) * w * spp);
    }
}

// The state of a render with the tracing filter, shared by its bands.
struct TracedRender {
    const Scene &scene;
    const RenderOptions &o;
    int threads;
    FrameLayers &layers;
    std::atomic<uint64_t> &nonFinite;
    SampleSource source;
    std::vector<TracingRecords> windows;
    std::atomic<int> rowsDone{0};
    std::mutex progressMutex;
};

// Trace rows [from, need) on the threads, each pixel's records into the windows.
void TraceRows(TracedRender &r, int from, int need) {
    const int w = r.o.width, spp = r.o.spp, partials = int(r.windows.size());
    std::atomic<int> nextRow{from};
    RunOnThreads(std::clamp(r.threads, 1, std::max(1, need - from)), [&] {
        PixelSums sums(r.o.histBins);
        std::vector<TracingPath> paths(spp);
        for (int y = nextRow++; y < need; y = nextRow++) {
            for (int x = 0; x < w; ++x) {
                PixelRecords records;
                records.partials = partials;
                records.paths = paths.data();
                for (int k = 0; k < partials; ++k) {
                    size_t pixel = size_t(y - r.windows[k].y0) * w + x;
                    records.surface[k] = &r.windows[k].surfaces[pixel];
                    records.samples[k] = &r.windows[k].samples[pixel * spp];
                }
                r.nonFinite +=
                    RenderPixel(r.scene, r.source, r.o, x, y, sums, r.layers, &records);
                for (int c = 0; c < 3; ++c)
                    r.layers.unfiltered.At(c, y, x) = r.layers.color.At(c, y, x);
            }
            int done = ++r.rowsDone;
            if (r.o.progress) {
                std::lock_guard<std::mutex> lock(r.progressMutex);
                r.o.progress(done, r.o.height);
            }
        }
    });
}

// Section 8: each partial image of rows [y0, y0 + rows) filtered on its own, with the same
// gather.
void FilterBand(TracedRender &r, int y0, int rows) {
    const TracingFilterOptions &t = r.o.tracing;
    const int w = r.o.width;
    for (int k = 0; k < int(r.windows.size()); ++k) {
        // No surface in the band's rows (no mirror seen there): the gather would hand
        // every pixel its own mean, a change of 0.
        auto first = r.windows[k].surfaces.begin() + size_t(y0 - r.windows[k].y0) * w;
        if (k > 0 && std::none_of(first, first + size_t(rows) * w,
                                  [](const TracingSurface &s) { return s.valid > 0; }))
            continue;
        std::vector<float> filtered =
            t.gather ? t.gather(r.windows[k], t.params, y0, rows)
                     : ReferenceGather(r.windows[k], t.params, y0, rows, r.threads);
        if (filtered.size() != size_t(w) * rows * 3)
            throw Error(fmt::format("tracing gather returned {} values for {} rows of {}",
                                    filtered.size(), rows, w),
                        ErrorKind::Internal);
        ApplyFiltered(r.windows[k], filtered, y0, rows, k, r.layers);
    }
}

// Render with the tracing filter: bands of rows, each filtered once its records and
// `radius` rows below it are traced; a sliding window keeps `radius` rows above.
void RenderTraced(const Scene &scene, const RenderOptions &o, int threads, FrameLayers &layers,
                  RenderResult &result, std::atomic<uint64_t> &nonFinite) {
    using Clock = std::chrono::steady_clock;
    const int h = o.height;
    const int radius = std::max(0, o.tracing.params.radius);
    // Partial images past 0 need a mirror in the scene: without one their records would
    // all be empty, so they get no memory and no gather (the frame is the same).
    const bool anyMirror = std::any_of(scene.materials.begin(), scene.materials.end(),
                                       [](const Material &m) { return !m.mirror.IsBlack(); });
    const int partials = anyMirror ? std::clamp(o.tracing.partials, 1, kPartialTypes) : 1;
    TracingStats &stats = result.tracing;
    const int band = TracedBandRows(o, partials, radius, stats);
    const int windowRows = std::min(h, band + 2 * radius);
    // One window of records per filtered partial image, all over the same rows.
    TracedRender r{scene,
                   o,
                   threads,
                   layers,
                   nonFinite,
                   SampleSource(scene, o.width, h, o.seed),
                   std::vector<TracingRecords>(partials)};
    for (TracingRecords &window : r.windows) {
        window.width = o.width, window.spp = o.spp, window.y0 = 0, window.rows = 0;
        window.surfaces.reserve(size_t(windowRows) * o.width);
        window.samples.reserve(size_t(windowRows) * o.width * o.spp);
    }
    stats.peakRecordBytes = RecordBytes(r.windows);
    int traced = 0;  // rows [0, traced) are rendered
    for (int y0 = 0; y0 < h; y0 += band) {
        const int rows = std::min(band, h - y0);
        const int keepFrom = std::max(0, y0 - radius), need = std::min(h, y0 + rows + radius);
        SlideWindows(r.windows, keepFrom, need);
        auto start = Clock::now();
        TraceRows(r, traced, need);
        traced = need;
        auto gathered = Clock::now();
        FilterBand(r, y0, rows);
        auto end = Clock::now();
        stats.renderSeconds += std::chrono::duration<double>(gathered - start).count();
        stats.gatherSeconds += std::chrono::duration<double>(end - gathered).count();
        ++stats.bands;
        stats.peakRecordBytes = std::max(stats.peakRecordBytes, RecordBytes(r.windows));
    }
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

PathSample SampleSource::Trace(double x, double y, uint64_t key, TracingPath *tracing) const {
    Rng rng(Mix(seed ^ Mix(key)), key);
    double lu = Uniform(rng), lv = Uniform(rng);
    return TracePath(scene, scene.camera.Generate(x, y, width, height, lu, lv), rng, tracing);
}

RenderResult Render(const Scene &scene, const RenderOptions &o) {
    CheckRenderOptions(o);
    auto start = std::chrono::steady_clock::now();
    FrameLayers layers(o);
    int threads =
        o.threads > 0 ? o.threads : int(std::max(1u, std::thread::hardware_concurrency()));
    RenderResult result;
    if (o.tracing.enabled) {
        std::atomic<uint64_t> nonFinite{0};
        RenderTraced(scene, o, std::min(threads, 1024), layers, result, nonFinite);
        result.seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        result.nonFiniteSamples = nonFinite;
        layers.MoveInto(result);
        result.metadata = RenderMetadata(scene, o, result);
        const TracingParams &p = o.tracing.params;
        result.metadata["mcd:tracingFilter"] = fmt::format(
            "radius {} alpha {} beta {} gamma {} selfFloor {} partials {} of {}", p.radius,
            p.alpha, p.beta, p.gamma, p.selfFloor, result.tracing.partials, o.tracing.partials);
        result.metadata["mcd:tracingSeconds"] =
            fmt::format("render {:.3f} gather {:.3f}", result.tracing.renderSeconds,
                        result.tracing.gatherSeconds);
        return result;
    }
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
    RunOnThreads(std::clamp(threads, 1, std::min(o.height, 1024)), renderRows);

    result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    result.nonFiniteSamples = nonFinite;
    layers.MoveInto(result);
    result.metadata = RenderMetadata(scene, o, result);
    return result;
}

}  // namespace mcd::render
