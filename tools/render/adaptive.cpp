#include "tools/render/adaptive.h"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <mutex>
#include <optional>
#include <system_error>
#include <thread>

#include "host/error.h"
#include "host/vk/gpu_image.h"
#include "host/wavelet/transform.h"

namespace mcd::render {
namespace {

// Position of a sample drawn from |phi| (profile CDF) around a coefficient at `centre`,
// folded back into [0, n) like the transform folds the image.
double DrawPosition(const ScaleProfile &profile, double centre, int n, double u1, double u2) {
    int index =
        int(std::upper_bound(profile.cdf.begin(), profile.cdf.end(), u1) - profile.cdf.begin());
    index = std::min(index, int(profile.cdf.size()) - 1);
    double p = centre + profile.origin + index + u2;
    for (int k = 0; k < 4 && (p < 0 || p >= n); ++k) p = p < 0 ? -p : 2.0 * n - p;
    return std::clamp(p, 0.0, std::nextafter(double(n), 0.0));
}

struct PixelStats {
    double sum[3] = {}, sumSq[3] = {};
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    double lumLo = INFINITY, lumHi = -INFINITY;
    uint32_t n = 0;
    double levelSum = 0;  // over the adaptive samples: the level that placed each
    uint32_t adaptiveN = 0;
};

// A placed sample waiting to be traced; `level` < 0 for the initial uniform samples.
struct PendingSample {
    double x, y;
    uint64_t key;
    int level;
};

// A priority the sort can order: NaN (from a non-finite transform) goes last.
double Ordered(double priority) {
    return std::isnan(priority) ? -INFINITY : priority;
}

using Clock = std::chrono::steady_clock;

double Seconds(Clock::duration d) {
    return std::chrono::duration<double>(d).count();
}

// The GPU side of a round: both transforms in one submission.
class GpuPriorityTransforms {
  public:
    GpuPriorityTransforms(vk::Context &context, int w, int h, int levels)
        : luminance(context, w, h, 1, "adaptive.luminance"),
          variance(context, w, h, 1, "adaptive.variance"),
          coef(context, w, h, 1, "adaptive.coef"),
          transform(context, w, h, 1),
          context(context),
          levels(levels) {
        for (int k = 1; k <= levels; ++k)
            scaleVariance.emplace_back(context, w, h, 1,
                                       fmt::format("adaptive.scaleVariance{}", k));
    }

    void Run(const Image &lum, const Image &var, WaveletBasis basis, float lowSum,
             Image *details, std::vector<Image> *scaleVariances) {
        luminance.Upload(lum);
        variance.Upload(var);
        vk::Recorder recorder(context);
        transform.RecordAnalysis(recorder, basis, levels, luminance, coef);
        // Scale variances of every level, each level from the one before (eq. 9).
        for (int k = 1; k <= levels; ++k)
            transform.RecordSqAnalysisLevel(recorder, basis, k - 1,
                                            k == 1 ? variance : scaleVariance[k - 2],
                                            scaleVariance[k - 1], lowSum, 0.f);
        recorder.Submit();
        *details = coef.Download();
        scaleVariances->clear();
        for (const vk::GpuImage &image : scaleVariance)
            scaleVariances->push_back(image.Download());
    }

  private:
    vk::GpuImage luminance, variance, coef;
    std::vector<vk::GpuImage> scaleVariance;
    WaveletTransform transform;
    vk::Context &context;
    int levels;
};

// A candidate for step 3: a scale coefficient (level, i, j) and its priority (eq. 8).
struct Candidate {
    double priority;
    int level, i, j;
};

// The sampler of SampleAdaptive, its state across rounds.
class AdaptiveSampler {
  public:
    AdaptiveSampler(vk::Context &context, const TraceFunction &trace, const AdaptiveOptions &o)
        : context(context),
          trace(trace),
          o(o),
          w(o.width),
          h(o.height),
          floor2(4.0 * double(o.sampler.contrastFloor) * o.sampler.contrastFloor),
          budget(uint64_t(o.averageSpp) * w * h),
          pixels(size_t(w) * h) {}

    AdaptiveResult Run();

  private:
    void Add(const PendingSample &p, Vec3 color);
    void TraceBatch();
    void TraceInitial();
    void SetUpTransforms();
    void Prioritize();
    uint64_t RankCandidates();
    void PlaceSamples(uint64_t round);
    void WriteLayers();

    vk::Context &context;
    const TraceFunction &trace;
    const AdaptiveOptions &o;
    const int w, h;
    const double floor2;
    const uint64_t budget;
    Clock::time_point start = Clock::now();
    std::vector<PixelStats> pixels;
    std::vector<PendingSample> batch;
    std::vector<Vec3> colors;
    uint64_t samples = 0, counter = 0;
    int levels = 0;
    std::vector<ScaleProfile> profiles;
    PriorityTransforms transforms;
    std::optional<GpuPriorityTransforms> gpu;
    Image lum, var, details;
    std::vector<Image> scaleVariances;
    std::vector<Candidate> candidates;
    AdaptiveResult result;
};

// Fold a traced sample into its pixel.
void AdaptiveSampler::Add(const PendingSample &p, Vec3 color) {
    PixelStats &s = pixels[size_t(int(p.y)) * w + int(p.x)];
    if (p.level >= 0) s.levelSum += p.level, ++s.adaptiveN;
    double lum = color.Luminance();
    if (!std::isfinite(lum)) color = Vec3(0), lum = 0;  // as the uniform renderer does
    for (int c = 0; c < 3; ++c) {
        s.sum[c] += color[c];
        s.sumSq[c] += color[c] * color[c];
        s.lo[c] = std::min(s.lo[c], color[c]);
        s.hi[c] = std::max(s.hi[c], color[c]);
    }
    s.lumLo = std::min(s.lumLo, lum);
    s.lumHi = std::max(s.lumHi, lum);
    ++s.n;
}

// Trace the batch on every core, then fold the samples into their pixels in batch order,
// so the frame is the same for any number of threads.
void AdaptiveSampler::TraceBatch() {
    colors.resize(batch.size());
    std::atomic<size_t> next = 0;
    std::exception_ptr failure;
    std::mutex failureMutex;
    auto work = [&] {
        try {
            for (size_t begin; (begin = next.fetch_add(256)) < batch.size();)
                for (size_t i = begin; i < std::min(begin + 256, batch.size()); ++i)
                    colors[i] = trace(batch[i].x, batch[i].y, batch[i].key);
        } catch (...) {  // rethrown on the calling thread after the join
            std::lock_guard<std::mutex> lock(failureMutex);
            if (!failure) failure = std::current_exception();
            next = batch.size();
        }
    };
    int threads = o.threads > 0 ? o.threads : int(std::thread::hardware_concurrency());
    threads = std::clamp<int>(threads, 1, int(batch.size() / 256 + 1));
    std::vector<std::thread> pool;
    for (int t = 1; t < threads; ++t) {
        try {
            pool.emplace_back(work);
        } catch (const std::system_error &) {
            break;  // the threads that started share the work
        }
    }
    work();
    for (std::thread &t : pool) t.join();
    if (failure) std::rethrow_exception(failure);
    for (size_t i = 0; i < batch.size(); ++i) Add(batch[i], colors[i]);
    batch.clear();
}

// Step 1: coarse uniform sampling.
void AdaptiveSampler::TraceInitial() {
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int s = 0; s < o.sampler.initialSpp; ++s) {
                uint64_t key = (uint64_t(y) * w + x) << 24 | uint64_t(s);
                Rng jitter(Mix(o.seed ^ Mix(~key)), key);
                batch.push_back({x + Uniform(jitter), y + Uniform(jitter), key, -1});
            }
    TraceBatch();
    result.traceSeconds = Seconds(Clock::now() - start);
    samples = uint64_t(o.sampler.initialSpp) * w * h;
}

// The scale functions' profiles and the transforms of a round (the tests' or the GPU's).
void AdaptiveSampler::SetUpTransforms() {
    levels = std::min(o.sampler.maxLevel, MaxWaveletLevels(w, h));
    for (int k = 0; k <= levels; ++k)
        profiles.push_back(ScaleFunctionProfile(o.sampler.basis, k));
    transforms = o.transforms;
    if (!transforms) {
        gpu.emplace(context, w, h, levels);
        transforms = [this](const Image &lum, const Image &var, WaveletBasis basis, int,
                            float lowSum, Image *details, std::vector<Image> *scaleVariances) {
            gpu->Run(lum, var, basis, lowSum, details, scaleVariances);
        };
    }
    lum = Image(w, h, 1), var = Image(w, h, 1);
    result.samplesPerLevel.assign(levels + 1, 0);
}

// Step 2: priorities from the pixel means and Mitchell-contrast variances, every scale
// coefficient of levels 0..levels a candidate.
void AdaptiveSampler::Prioritize() {
    for (size_t p = 0; p < pixels.size(); ++p) {
        const PixelStats &s = pixels[p];
        if (s.n == 0) {  // every sample non-finite: unknown, as uncertain as can be
            lum.data[p] = 0, var.data[p] = 1;
            continue;
        }
        lum.data[p] = float((0.2126 * s.sum[0] + 0.7152 * s.sum[1] + 0.0722 * s.sum[2]) / s.n);
        // Eq. 5 with a floor under the mean (AwrSamplerParams::contrastFloor).
        double sum = s.lumHi + s.lumLo, spread = s.lumHi - s.lumLo;
        double scale = sum * sum + floor2;
        var.data[p] = float(scale > 0 ? spread * spread / scale / s.n : 0);
    }
    transforms(lum, var, o.sampler.basis, levels, o.sampler.lowSum, &details, &scaleVariances);
    candidates.clear();
    for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i) candidates.push_back({Ordered(var.At(0, j, i)), 0, i, j});
    for (int k = 1; k <= levels; ++k) {
        const Image &sv = scaleVariances[k - 1];
        int pw = LevelExtent(w, k - 1), ph = LevelExtent(h, k - 1);
        int hw = pw > 1 ? (pw + 1) / 2 : pw, hh = ph > 1 ? (ph + 1) / 2 : ph;
        for (int j = 0; j < LevelExtent(h, k); ++j)
            for (int i = 0; i < LevelExtent(w, k); ++i) {
                // Mean square of the wavelets at this position (those the size has).
                double squares = 0;
                int count = 0;
                auto take = [&](int x, int y) {
                    if (x < pw && y < ph)
                        squares += double(details.At(0, y, x)) * details.At(0, y, x), ++count;
                };
                if (pw > 1) take(hw + i, j);
                if (ph > 1) take(i, hh + j);
                if (pw > 1 && ph > 1) take(hw + i, hh + j);
                double wavelets = count ? squares / count : 0;
                candidates.push_back({Ordered(sv.At(0, j, i) - wavelets), k, i, j});
            }
    }
}

// Step 3, batched: the top coefficients, 64 x 2^k samples each, until an eighth of what is
// left (at least 1/64 of the budget) is placed; returns that round's count. Each takes at
// least 64, so only the top round / 64 + 1 need ordering; ties go to the finer level, then
// to the lower row and column, a total order whatever the sort's algorithm.
uint64_t AdaptiveSampler::RankCandidates() {
    uint64_t round = std::max((budget - samples) / 8, budget / 64);
    size_t top = std::min<size_t>(candidates.size(), round / 64 + 1);
    std::partial_sort(candidates.begin(), candidates.begin() + top, candidates.end(),
                      [](const Candidate &a, const Candidate &b) {
                          if (a.priority != b.priority) return a.priority > b.priority;
                          if (a.level != b.level) return a.level < b.level;
                          return a.j != b.j ? a.j < b.j : a.i < b.i;
                      });
    candidates.resize(top);
    return round;
}

// The ranked coefficients' samples, placed by importance sampling |phi_k| along each axis.
void AdaptiveSampler::PlaceSamples(uint64_t round) {
    uint64_t used = 0;
    for (const Candidate &c : candidates) {
        uint64_t count = std::min<uint64_t>(uint64_t(64) << c.level, budget - samples);
        double centreX = double(c.i << c.level), centreY = double(c.j << c.level);
        for (uint64_t s = 0; s < count; ++s) {
            uint64_t key = (uint64_t(1) << 62) + counter++;
            Rng place(Mix(o.seed ^ Mix(key ^ 0x5a5a5a5a)), key);
            double u1 = Uniform(place), u2 = Uniform(place), u3 = Uniform(place),
                   u4 = Uniform(place);
            batch.push_back({DrawPosition(profiles[c.level], centreX, w, u1, u2),
                             DrawPosition(profiles[c.level], centreY, h, u3, u4), key,
                             c.level});
        }
        result.samplesPerLevel[c.level] += count;
        samples += count;
        used += count;
        if (used >= round || samples >= budget) break;
    }
}

// The frame's layers from the pixels' sums, and where the adaptive samples came from.
void AdaptiveSampler::WriteLayers() {
    Image color(w, h, 3), variance3(w, h, 3), spp(w, h, 1), mn(w, h, 3), mx(w, h, 3);
    result.placementLevel = Image(w, h, 1);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const PixelStats &s = pixels[size_t(y) * w + x];
            double n = s.n;
            spp.At(0, y, x) = float(n);
            result.placementLevel.At(0, y, x) =
                s.adaptiveN ? float(s.levelSum / s.adaptiveN) : -1.f;
            for (int c = 0; c < 3; ++c) {
                double mean = s.sum[c] / n;
                color.At(c, y, x) = float(mean);
                double v = n > 1 ? std::max(0.0, (s.sumSq[c] - n * mean * mean) / (n - 1)) : 0;
                variance3.At(c, y, x) = float(v / n);
                mn.At(c, y, x) = float(s.lo[c]);
                mx.At(c, y, x) = float(s.hi[c]);
            }
        }
    result.layers = {{"color", std::move(color)},
                     {"variance", std::move(variance3)},
                     {"spp", std::move(spp)},
                     {"min", std::move(mn)},
                     {"max", std::move(mx)}};
}

AdaptiveResult AdaptiveSampler::Run() {
    TraceInitial();
    SetUpTransforms();
    while (samples < budget) {
        Clock::time_point priorityStart = Clock::now();
        Prioritize();
        uint64_t round = RankCandidates();
        Clock::time_point traceStart = Clock::now();
        result.prioritySeconds += Seconds(traceStart - priorityStart);
        PlaceSamples(round);
        TraceBatch();
        result.traceSeconds += Seconds(Clock::now() - traceStart);
        ++result.rounds;
        if (o.progress) o.progress(samples, budget);
    }
    WriteLayers();
    result.samples = samples;
    result.seconds = Seconds(Clock::now() - start);
    return std::move(result);
}

}  // namespace

ScaleProfile ScaleFunctionProfile(WaveletBasis basis, int level) {
    // Synthesis low-pass taps (AWR appendix A; Haar: the pair (2n, 2n+1)), by offset.
    std::vector<std::pair<int, double>> taps;
    const double r = 1 / std::sqrt(2.0);
    if (basis == WaveletBasis::Cdf97) {
        const double half[4] = {1.115087052456994, 0.5912717631142470, -0.05754352622849957,
                                -0.09127176311424948};
        for (int k = -3; k <= 3; ++k) taps.push_back({k, r * half[std::abs(k)]});
    } else if (basis == WaveletBasis::LeGall53) {
        taps = {{-1, r * 0.5}, {0, r}, {1, r * 0.5}};
    } else {
        taps = {{0, r}, {1, r}};
    }
    // Cascade: phi_{j+1}[n] = sum_m phi_j[m] g0[n - 2m], upsampling by 2 each level.
    std::vector<double> phi = {1.0};
    int origin = 0;
    for (int j = 0; j < level; ++j) {
        int lo = taps.front().first, hi = taps.back().first;
        std::vector<double> next(2 * (phi.size() - 1) + 1 + (hi - lo), 0.0);
        for (size_t m = 0; m < phi.size(); ++m)
            for (auto [offset, tap] : taps) next[2 * m + (offset - lo)] += phi[m] * tap;
        origin = 2 * origin + lo;
        phi = std::move(next);
    }
    ScaleProfile profile;
    profile.origin = origin;
    double total = 0;
    for (double v : phi) total += std::fabs(v);
    double running = 0;
    for (double v : phi) profile.cdf.push_back((running += std::fabs(v)) / total);
    profile.cdf.back() = 1;
    return profile;
}

AdaptiveResult SampleAdaptive(vk::Context &context, const TraceFunction &trace,
                              const AdaptiveOptions &o) {
    if (o.width <= 0 || o.height <= 0)
        throw Error(fmt::format("image size {}x{} must be positive", o.width, o.height),
                    ErrorKind::InvalidArgument);
    if (o.sampler.initialSpp < 1 || o.averageSpp < o.sampler.initialSpp)
        throw Error(fmt::format("the adaptive sampler starts with {} samples per pixel: the "
                                "average must be at least that, not {}",
                                o.sampler.initialSpp, o.averageSpp),
                    ErrorKind::InvalidArgument);
    if (!(o.sampler.contrastFloor >= 0 && o.sampler.contrastFloor < 1e18f))
        throw Error(fmt::format("the contrast floor must be finite and at least 0, not {}",
                                o.sampler.contrastFloor),
                    ErrorKind::InvalidArgument);
    return AdaptiveSampler(context, trace, o).Run();
}

AdaptiveResult RenderAdaptive(vk::Context &context, const Scene &scene,
                              const AdaptiveOptions &o) {
    SampleSource source(scene, o.width, o.height, o.seed);
    AdaptiveResult result = SampleAdaptive(
        context,
        [&](double x, double y, uint64_t key) { return source.Trace(x, y, key).color; }, o);
    int levels = std::min(o.sampler.maxLevel, MaxWaveletLevels(o.width, o.height));
    result.metadata = {
        {"mcd:scene", scene.name},
        {"mcd:spp", std::to_string(o.averageSpp)},
        {"mcd:sampler",
         fmt::format("awr adaptive, {} levels of {}, renorm {}, contrast floor {}, {} rounds",
                     levels, WaveletName(o.sampler.basis), o.sampler.lowSum,
                     o.sampler.contrastFloor, result.rounds)},
        {"mcd:seed", std::to_string(o.seed)},
        {"mcd:size", fmt::format("{}x{}", o.width, o.height)},
        {"mcd:renderSeconds", fmt::format("{:.3f}", result.seconds)},
        {"mcd:renderer", fmt::format("mcdenoise path tracer {}", kRendererVersion)}};
    return result;
}

}  // namespace mcd::render
