#include "host/methods/bayes.h"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

#include "bayes/bayes.h"
#include "host/common/cycle_spin.h"
#include "host/common/local_mean.h"
#include "host/common/parallel.h"
#include "host/error.h"
#include "host/kernels/bayes_exp.h"
#include "host/kernels/bayes_log.h"
#include "host/kernels/bayes_mix.h"
#include "host/kernels/bayes_moments.h"
#include "host/kernels/bayes_shrink.h"
#include "host/kernels/bayes_solve.h"
#include "host/kernels/bayes_swt_moments.h"
#include "host/kernels/bayes_swt_shrink.h"
#include "host/kernels/bayes_table.h"
#include "host/methods/staged_run.h"
#include "host/vk/buffer.h"
#include "host/vk/gpu_image.h"
#include "host/wavelet/swt.h"
#include "host/wavelet/transform.h"
#include "wavelet/swt.h"

namespace mcd {
namespace {

bool Finite(float v) {
    return std::isfinite(v);
}

// Whether the exp kernel keeps a zero of channel c at (x, y) black with --zeros restore: both
// neighbours along a row, column or diagonal (clamped to the frame) black in channel c, not
// finite positive.
bool InsideBlack(const Image &color, int c, int y, int x) {
    auto black = [&](int yy, int xx) {
        yy = std::clamp(yy, 0, color.height - 1), xx = std::clamp(xx, 0, color.width - 1);
        float v = color.At(c, yy, xx);
        return !(Finite(v) && v > 0);
    };
    for (auto [dx, dy] : {std::pair{1, 0}, std::pair{0, 1}, std::pair{1, 1}, std::pair{1, -1}})
        if (black(y + dy, x + dx) && black(y - dy, x - dx)) return true;
    return false;
}

// Whether the log kernel fills the pixel at (x, y) with --zeros restore: dark (no channel
// finite and above its floor) and not inside dark (no pair of opposite 3x3 neighbour pixels,
// clamped to the frame, both dark).
bool MissedSample(const Image &color, const std::vector<float> &floors, int y, int x) {
    auto dark = [&](int yy, int xx) {
        yy = std::clamp(yy, 0, color.height - 1), xx = std::clamp(xx, 0, color.width - 1);
        for (int c = 0; c < color.channels; ++c)
            if (float v = color.At(c, yy, xx); Finite(v) && v > floors[c]) return false;
        return true;
    };
    if (!dark(y, x)) return false;
    for (auto [dx, dy] : {std::pair{1, 0}, std::pair{0, 1}, std::pair{1, 1}, std::pair{1, -1}})
        if (dark(y + dy, x + dx) && dark(y - dy, x - dx)) return false;
    return true;
}

// Whether a 3x3 neighbour of (x, y) inside the frame is lit in channel c (finite, above 0).
bool BesideLight(const Image &color, int c, int y, int x) {
    for (int v = std::max(0, y - 1); v <= std::min(color.height - 1, y + 1); ++v)
        for (int u = std::max(0, x - 1); u <= std::min(color.width - 1, x + 1); ++u)
            if (float value = color.At(c, v, u); Finite(value) && value > 0) return true;
    return false;
}

// Zeros kept black too dense to be black: at least this share of the frame's values, and
// at least half of them beside a lit value of their channel (low-spp indirect light, where
// most pixels' few samples missed it, not black regions, whose zeros are mostly inside).
constexpr double kDenseZerosShare = 0.1;

// Refuse --zeros restore where its zeros kept black are too dense to be black: the output
// would keep black holes wherever the few samples missed dim light.
void CheckZerosRestorable(const Image &color, const std::string &layer) {
    size_t keptBlack = 0, keptBesideLight = 0;
    for (int c = 0; c < color.channels; ++c)
        for (int y = 0; y < color.height; ++y)
            for (int x = 0; x < color.width; ++x)
                if (color.At(c, y, x) == 0 && InsideBlack(color, c, y, x))
                    ++keptBlack, keptBesideLight += BesideLight(color, c, y, x);
    if (double(keptBlack) < kDenseZerosShare * double(color.data.size()) ||
        2 * keptBesideLight < keptBlack)
        return;
    throw Error(
        fmt::format("bayes{}: --zeros restore refused: zeros too dense to tell black from "
                    "samples that missed the light ({} of the {} values would stay black, "
                    "at least {:.0f}%, and {} of them are beside a lit value of their "
                    "channel): the output would keep black holes where the light is dim; use "
                    "--zeros denoise or more samples per pixel",
                    layer, keptBlack, color.data.size(), 100 * kDenseZerosShare,
                    keptBesideLight),
        ErrorKind::InvalidArgument);
}

// Count what the log domain cannot take as is, with the first place of each. Black and
// nearly black values are ordinary in a render: one line says what became of them.
void CountSpecials(const Image &color, const std::vector<float> &floors, bool restoreZeros,
                   StagedRun &run) {
    struct Count {
        size_t n = 0;
        int x = 0, y = 0, c = 0;
    } nonFinite, negative, zero, dark;
    size_t keptBlack = 0, filled = 0;
    auto add = [](Count &count, int c, int y, int x) {
        if (count.n++ == 0) count.x = x, count.y = y, count.c = c;
    };
    for (int c = 0; c < color.channels; ++c)
        for (int y = 0; y < color.height; ++y)
            for (int x = 0; x < color.width; ++x) {
                float v = color.At(c, y, x);
                if (!Finite(v))
                    add(nonFinite, c, y, x);
                else if (v < 0)
                    add(negative, c, y, x);
                else if (v <= floors[c]) {
                    add(dark, c, y, x);
                    bool kept = restoreZeros && v == 0 && InsideBlack(color, c, y, x);
                    zero.n += v == 0, keptBlack += kept;
                    filled += restoreZeros && !kept && MissedSample(color, floors, y, x);
                }
            }
    auto say = [&](const Count &count, const char *what, const std::string &then) {
        if (count.n)
            run.Warn(fmt::format(
                "bayes: {} {} value{} (first at pixel ({}, {}), channel {}): {}", count.n, what,
                count.n == 1 ? "" : "s", count.x, count.y, count.c, then));
    };
    say(nonFinite, "NaN/Inf", "taken as the log floor, output 0");
    say(negative, "negative", "taken as the log floor, output 0");
    std::string black;
    if (!restoreZeros && zero.n)
        black = fmt::format(", the {} black one{} too (--zeros denoise)", zero.n,
                            zero.n == 1 ? "" : "s");
    if (restoreZeros) {
        size_t floored = dark.n - keptBlack - filled;
        if (keptBlack)
            black = fmt::format(
                "; the {} black one{} stay{} black (zeros inside black in "
                "their channel)",
                keptBlack, keptBlack == 1 ? "" : "s", keptBlack == 1 ? "s" : "");
        if (filled)
            black += fmt::format(
                "; {} in dark pixels lone among lit pixels, samples that "
                "missed the light, filled from their lit neighbours' mean "
                "log and denoised",
                filled);
        if (floored) black += fmt::format("; {} denoised from the floor", floored);
    }
    say(dark, "black or nearly black",
        (restoreZeros ? std::string("below the log domain's floor (--log-floor x the "
                                    "channel's median)")
                      : std::string("below the log domain's floor (--log-floor x the "
                                    "channel's median), denoised from it")) +
            black);
}

// Element n/2 of the values in order (0 when empty).
double MedianOf(std::vector<float> &values) {
    if (values.empty()) return 0;
    auto mid = values.begin() + values.size() / 2;
    std::nth_element(values.begin(), mid, values.end());
    return *mid;
}

// The MAD's sample: |y| of a finest HH coefficient, left out where it is exactly 0 (a 2x2
// block of one value: in the log domain, black pixels at the floor). A frame mostly black at
// a few samples per pixel would otherwise read a noise near 0 and be left as it is.
void AddNonZero(float v, std::vector<float> *values) {
    if (v != 0) values->push_back(std::fabs(v));
}

// Median of |x| of the pooled finest-level HH bands' non-zero values.
double FinestMad(const Image &coef) {
    int lowW = (coef.width + 1) / 2, lowH = (coef.height + 1) / 2;
    std::vector<float> values;
    for (int c = 0; c < coef.channels; ++c)
        for (int y = lowH; y < coef.height; ++y)
            for (int x = lowW; x < coef.width; ++x) AddNonZero(coef.At(c, y, x), &values);
    return MedianOf(values);
}

// The non-zero |y| of the stationary transform's finest HH planes of `channels` channels
// (downloaded alone), appended to `values`; none when level 0 does not transform both axes.
void CollectFinestHH(const vk::GpuImage &coef, int channels, int levels,
                     std::vector<float> *values) {
    if (!shader::SwtTransformsAxis(coef.width, 0) || !shader::SwtTransformsAxis(coef.height, 0))
        return;
    size_t plane = size_t(coef.width) * coef.height;
    for (int c = 0; c < channels; ++c) {
        size_t at =
            (size_t(c) * shader::SwtPlaneCount(levels) + shader::SwtDetailPlane(0, 2)) * plane;
        for (float v : coef.buffer.DownloadFloats(plane, at)) AddNonZero(v, values);
    }
}

// Scale each channel of result->image to the mean of color's finite non-negative values.
void KeepMean(const Image &color, BayesResult *result) {
    std::string scales;
    for (int c = 0; c < color.channels; ++c) {
        double in = 0, outSum = 0;
        for (size_t i = 0; i < color.PixelCount(); ++i) {
            float v = color.Plane(c)[i];
            if (Finite(v) && v >= 0) in += v;
            outSum += result->image.Plane(c)[i];
        }
        double scale = outSum > 0 ? in / outSum : 1.0;
        for (size_t i = 0; i < color.PixelCount(); ++i)
            result->image.Plane(c)[i] = float(result->image.Plane(c)[i] * scale);
        scales += fmt::format("{}{:.4g}", c ? ", " : "", scale);
    }
    result->plan.push_back(fmt::format(
        "keep mean: channels scaled by {} to the input's mean (log-domain bias)", scales));
}

// The values bayes leaves as they were: the zeros it keeps black (--zeros restore), 0 in and
// out. A positive value is always filtered, even where its exp lands on its input: the twin
// (double, rounded once) can land there where the GPU (float) misses it by its rounding, and an
// equality test would keep it on one side only.
std::vector<bool> KeptZeros(const Image &color, const Image &output) {
    std::vector<bool> kept(color.data.size());
    for (size_t i = 0; i < kept.size(); ++i)
        kept[i] = color.data[i] == 0 && output.data[i] == 0;
    return kept;
}

// Restore the input's local means (BayesParams::meanRadius), keeping only KeptZeros.
void LocalMean(const Image &color, int radius, const Image *variance, BayesResult *result) {
    std::vector<bool> kept = KeptZeros(color, result->image);
    LocalMeanFactors f =
        RestoreLocalMeans(color, radius, &result->image, variance, -1, false, &kept);
    result->plan.push_back(
        fmt::format("local mean: the input's means over tents of radius {}, then {} restored "
                    "(the log domain's bias; factors {:.3g} to {:.3g})",
                    8 * radius, 2 * radius, f.lo, f.hi));
}

// Whether color's value of channel c at (x, y) is above each of its 8 neighbours inside the
// frame in that channel (NaN never is).
bool LoneMaximum(const Image &color, int c, int y, int x) {
    const float v = color.At(c, y, x);
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
            const int u = x + dx, t = y + dy;
            if ((dx || dy) && u >= 0 && u < color.width && t >= 0 && t < color.height &&
                !(v > color.At(c, t, u)))
                return false;
        }
    return std::isfinite(v);
}

// Lower each value of the output above its input where that input stands above its 8
// neighbours: such a lone peak is a firefly or a maximum of the noise, and a denoiser has no
// cause to raise it (the log domain's bias and its restore did, by a little).
void CapLonePeaks(const Image &color, BayesResult *result) {
    Image &out = result->image;
    std::atomic<size_t> capped{0};
    // One row of one channel an index: each writes its own values and reads only the input.
    ParallelFor(color.channels * color.height, 12 * color.Size(), [&](int begin, int end) {
        size_t count = 0;
        for (int row = begin; row < end; ++row) {
            const int c = row / color.height, y = row % color.height;
            for (int x = 0; x < color.width; ++x) {
                float &o = out.At(c, y, x);
                const float v = color.At(c, y, x);
                if (o > v && LoneMaximum(color, c, y, x)) {
                    o = v;
                    ++count;
                }
            }
        }
        capped += count;
    });
    if (capped.load() > 0)
        result->plan.push_back(fmt::format(
            "lone peaks: {} values above their 8 neighbours in the input, raised by the log "
            "domain's bias or its restore, lowered to their input",
            capped.load()));
}

// keepMean, then the local mean, each a stage when kept.
void RestoreMeans(const Image &color, const BayesParams &params, bool keepStages,
                  const Image *variance, BayesResult *result) {
    if (params.keepMean) {
        KeepMean(color, result);
        if (keepStages) result->stages.push_back({"keep mean", result->image});
    }
    if (params.meanRadius > 0) {
        LocalMean(color, params.meanRadius, variance, result);
        if (keepStages) result->stages.push_back({"local mean", result->image});
    }
}

}  // namespace

const char *BayesTransformName(BayesTransform transform) {
    return transform == BayesTransform::Swt ? "swt" : "dwt";
}

const char *BayesFitName(int fit) {
    switch (fit) {
        case BAYES_FIT_SOLVED:
            return "solved";
        case BAYES_FIT_NO_SIGNAL:
            return "no signal (variance <= noise's): zeroed";
        case BAYES_FIT_P_LOW:
            return "kurtosis above reach: p_c clamped low";
        case BAYES_FIT_P_HIGH:
            return "kurtosis below reach: p_c clamped high";
        case BAYES_FIT_NO_NOISE:
            return "no noise: kept";
        case BAYES_FIT_EMPTY:
            return "empty";
    }
    return "?";
}

std::vector<float> BayesFloors(const Image &color, float floorRel) {
    std::vector<float> floors(color.channels);
    // Each channel's median on its own: the channels split among the cores.
    ParallelFor(color.channels, color.data.size() * 16, [&](int begin, int end) {
        for (int c = begin; c < end; ++c) {
            std::vector<float> positive;
            for (size_t i = 0; i < color.PixelCount(); ++i) {
                float v = color.Plane(c)[i];
                if (Finite(v) && v > 0) positive.push_back(v);
            }
            float median = 1.f;
            if (!positive.empty()) {
                auto mid = positive.begin() + positive.size() / 2;
                std::nth_element(positive.begin(), mid, positive.end());
                median = *mid;
            }
            floors[c] = float(std::max(double(floorRel) * median, 1e-30));
        }
    });
    return floors;
}

double BayesScaleFromMad(double mad, double p) {
    // For s = 1: find m with int_0^m exp(-t^p) dt = Gamma(1/p) / (2p), by Simpson's rule
    // on a fine grid up to where the density is below e^-40.
    double total = std::exp(std::lgamma(1 / p)) / p, end = std::pow(40.0, 1 / p);
    const int steps = 20000;
    double h = end / steps, acc = 0;
    auto f = [p](double t) { return std::exp(-std::pow(t, p)); };
    for (int i = 0; i < steps; ++i) {
        double a = i * h, piece = h / 6 * (f(a) + 4 * f(a + h / 2) + f(a + h));
        if (acc + piece >= total / 2) {
            // Inside this step: the density is nearly flat over h, interpolate linearly.
            double median = a + h * (total / 2 - acc) / piece;
            return mad / median;
        }
        acc += piece;
    }
    return mad / end;
}

namespace {

// The mean of each plane of a stationary transform's coefficients (`part`: `channels`
// channels of SwtPlaneCount(levels) planes of w x h), 0 for the low-pass plane and a band
// whose axis is not transformed at its level (it is empty). Each plane comes back alone,
// through one plane's memory, and is summed in order.
std::vector<double> SwtBandMeans(const vk::GpuImage &part, int w, int h, int channels,
                                 int levels) {
    const int count = shader::SwtPlaneCount(levels);
    const size_t pixels = size_t(w) * h;
    std::vector<double> means(size_t(channels) * count, 0.0);
    std::vector<float> plane(pixels);
    for (int c = 0; c < channels; ++c)
        for (int level = 0; level < levels; ++level)
            for (int o = 0; o < 3; ++o) {
                bool tx = shader::SwtTransformsAxis(w, level);
                bool ty = shader::SwtTransformsAxis(h, level);
                if (!(o == 0 ? tx : (o == 1 ? ty : tx && ty))) continue;
                const size_t index = size_t(c) * count + shader::SwtDetailPlane(level, o);
                part.buffer.Download(plane.data(), pixels * sizeof(float),
                                     index * pixels * sizeof(float));
                double sum = 0;
                for (float v : plane) sum += v;
                means[index] = sum / double(pixels);
            }
    return means;
}

// The mean of each detail band of the squared analysis `coef`, channel by channel, level by
// level, in the order (high x, low y), (low x, high y), (high x, high y): each band summed in
// order on its own, the bands split among the cores.
std::vector<double> BandMeans(const Image &coef, int levels) {
    struct Band {
        int c, x0, y0, x1, y1;
    };
    std::vector<Band> bands;
    for (int c = 0; c < coef.channels; ++c)
        for (int level = 0; level < levels; ++level) {
            int lw = LevelExtent(coef.width, level), lh = LevelExtent(coef.height, level);
            int lowW = (lw + 1) / 2, lowH = (lh + 1) / 2;
            bands.push_back({c, lowW, 0, lw, lowH});
            bands.push_back({c, 0, lowH, lowW, lh});
            bands.push_back({c, lowW, lowH, lw, lh});
        }
    std::vector<double> means(bands.size(), 0.0);
    ParallelFor(int(bands.size()), coef.data.size(), [&](int begin, int end) {
        for (int k = begin; k < end; ++k) {
            const Band &b = bands[k];
            double sum = 0;
            size_t n = 0;
            for (int y = b.y0; y < b.y1; ++y)
                for (int x = b.x0; x < b.x1; ++x, ++n) sum += coef.At(b.c, y, x);
            means[k] = n ? sum / double(n) : 0.0;
        }
    });
    return means;
}

}  // namespace

// --noise variance. Derivation:
// 1. Log domain. The method shrinks z = log(max(Y, floor)). For a pixel mean Y with
//    variance V (the variance layer), the delta method gives var(z) ~ V / Y^2 to first
//    order. We use log(1 + V / max(Y, floor)^2), which agrees with it to first order and is
//    exact for log-normal Y (var(log Y) = log(1 + V / E[Y]^2)); it grows only
//    logarithmically where V >> Y^2 (dark pixels at low spp), so one such pixel cannot
//    swamp the band's estimate, and it is finite for any finite V (V = FLT_MAX over a
//    1e-30 floor gives about 227). Y is the noisy mean itself: the best we have per pixel.
// 2. Through the DWT. Pixel noises are independent, so a coefficient sum_i h_i z_i has
//    noise variance sum_i h_i^2 var(z_i): the DWT with every tap squared (AWR eqs. 9-10,
//    the foundation's squared analysis at natural sums) turns the per-pixel log variance
//    into every coefficient's noise variance, per level and orientation: orthonormal Haar
//    keeps white noise's variance at every level (its squared taps are (1/2, 1/2)), the
//    biorthogonal 5/3 and 9/7 scale it per band by their squared-tap sums. So no fixed
//    high-pass factor: each band gets its own. Exact for Haar at every level and for any
//    basis at the finest level; at coarser levels of 5/3 and 9/7 the cascade treats the
//    previous low-pass outputs as independent though their overlapping filters correlate
//    them (tests/methods/bayes_test.cpp measures 0.88 to 1.18 of the true variance).
// 3. Per band, the noise variance sigma^2 is the mean of those over the band's
//    coefficients (a heteroscedastic mixture has the mean variance), and a generalised
//    Laplacian of shape p has variance s^2 Gamma(3/p) / Gamma(1/p), so
//    s_n = sigma sqrt(Gamma(1/p) / Gamma(3/p)).
// With --colour opponent the orthonormal mix gives each opponent channel a weighted mean of
// the RGB variances with weights summing to 1; we use the plain mean over channels.
// In the split the variance is that of the whole colour over the indirect value: an upper
// bound on the indirect part's relative noise (the direct part's variance is in V).
// The stationary transform (--bayes-transform swt) filters with the same taps without
// decimating, so steps 2 and 3 carry over: its squared analysis at every position, the
// mean over the full-size band.
std::vector<float> BayesVarianceNoise(vk::Context &context, const Image &color,
                                      const Image &variance, const std::vector<float> &floors,
                                      WaveletBasis basis, int levels, float pn, bool opponent,
                                      std::vector<vk::DispatchTiming> *timings,
                                      BayesTransform kind, int swtGroupChannels) {
    if (!variance.SameShape(color))
        throw Error(
            fmt::format("bayes: the variance layer is {}x{}x{} but the image is {}x{}x{}",
                        variance.width, variance.height, variance.channels, color.width,
                        color.height, color.channels),
            ErrorKind::InvalidArgument);
    int w = color.width, h = color.height, channels = color.channels;
    Image logVar(w, h, channels);
    const size_t pixels = color.PixelCount();
    ParallelValues(logVar.data.size(), 32, [&](size_t begin, size_t end) {
        for (size_t k = begin; k < end; ++k) {
            const int c = int(k / pixels);
            float y = color.data[k], v = variance.data[k];
            if (!(v > 0)) v = 0;  // NaN and negatives: no information
            if (!Finite(v)) v = std::numeric_limits<float>::max();
            double base = Finite(y) ? std::max(double(y), double(floors[c])) : floors[c];
            logVar.data[k] = float(std::log1p(double(v) / (base * base)));
        }
    });
    vk::GpuImage varGpu(context, w, h, channels, "bayes.logvar");
    varGpu.Upload(logVar);
    bool swt = kind == BayesTransform::Swt;
    WaveletTransform transform(context, w, h, channels);
    StagedRun run(context, false);
    if (!swt)
        transform.RecordSqAnalysis(run.Recorder(), basis, levels, varGpu, varGpu, 0.f, 0.f);
    // The stationary transform: full-size planes (shaders/wavelet/swt.h), in groups of as
    // many channels as one binding holds; only the bands' means come back.
    std::vector<double> swtMeans;
    if (swt) {
        int groupSize = std::min(channels, SwtChannelsPerBinding(context, w, h, levels));
        if (groupSize < 1) CheckSwtFits(context, w, h, 1, levels, "bayes --noise variance");
        if (swtGroupChannels > 0) groupSize = std::min(groupSize, swtGroupChannels);
        for (int first = 0; first < channels; first += groupSize) {
            int n = std::min(groupSize, channels - first);
            SwtTransform swtTransform(context, w, h, n, levels);
            vk::GpuImage part = swtTransform.MakeCoefficients("bayes.swt.var");
            swtTransform.RecordAnalysis(run.Recorder(), basis, varGpu, part, true, first);
            run.Submit();
            std::vector<double> means = SwtBandMeans(part, w, h, n, levels);
            swtMeans.insert(swtMeans.end(), means.begin(), means.end());
        }
    }
    run.Submit();
    if (timings) timings->insert(timings->end(), run.Timings().begin(), run.Timings().end());
    Image coef = swt ? Image() : varGpu.Download();
    double toS = std::exp(0.5 * (std::lgamma(1.0 / pn) - std::lgamma(3.0 / pn)));
    std::vector<double> bandVar;
    if (!swt) bandVar = BandMeans(coef, levels);
    for (int c = 0; swt && c < channels; ++c)
        for (int level = 0; level < levels; ++level)
            for (int o = 0; o < 3; ++o)
                bandVar.push_back(swtMeans[size_t(c * shader::SwtPlaneCount(levels) +
                                                  shader::SwtDetailPlane(level, o))]);
    if (opponent) {
        size_t perChannel = size_t(levels) * 3;
        for (size_t k = 0; k < perChannel; ++k) {
            double mean = 0;
            for (int c = 0; c < channels; ++c) mean += bandVar[c * perChannel + k] / channels;
            for (int c = 0; c < channels; ++c) bandVar[c * perChannel + k] = mean;
        }
    }
    std::vector<float> s;
    for (double v : bandVar) s.push_back(float(std::sqrt(std::max(v, 0.0)) * toS));
    return s;
}

namespace {

// The variance the noise is taken from (--noise variance, or auto given one); none else.
const Image *NoiseVariance(const BayesParams &params, const Image *variance) {
    if (params.noise == BayesNoise::Variance && !variance)
        throw Error("bayes: --noise variance needs a variance layer; none was given",
                    ErrorKind::MissingLayer);
    bool reads = params.noise == BayesNoise::Variance || params.noise == BayesNoise::Auto;
    return reads ? variance : nullptr;
}

// Whether the finest bands' median absolute deviation sets s_n (--noise mad, or auto
// without the variance NoiseVariance gave).
bool MadNoise(const BayesParams &params, const Image *variance) {
    return !variance && (params.noise == BayesNoise::Mad || params.noise == BayesNoise::Auto);
}

void CheckBayesParams(const Image &color, const BayesParams &options) {
    if (color.Empty() || color.width < 1 || color.height < 1)
        throw Error("bayes: the image is empty", ErrorKind::InvalidArgument);
    if (!std::isfinite(options.sn) || options.sn < 0)
        throw Error(fmt::format("bayes: s_n must be a finite number >= 0, not {}", options.sn),
                    ErrorKind::InvalidArgument);
    if (!std::isfinite(options.pn) || options.pn < 0.1f || options.pn > 10.f)
        throw Error(fmt::format("bayes: p_n must be in [0.1, 10], not {}", options.pn),
                    ErrorKind::InvalidArgument);
    if (!std::isfinite(options.hpFactor) || options.hpFactor <= 0)
        throw Error(
            fmt::format("bayes: the high-pass factor must be > 0, not {}", options.hpFactor),
            ErrorKind::InvalidArgument);
    if (!std::isfinite(options.floorRel) || options.floorRel <= 0 || options.floorRel >= 1)
        throw Error(
            fmt::format("bayes: the log floor must be in (0, 1), not {}", options.floorRel),
            ErrorKind::InvalidArgument);
    if (options.levels < 0)
        throw Error("bayes: levels must be >= 0", ErrorKind::InvalidArgument);
    if (options.spins < 1 || options.spins > 8)
        throw Error(fmt::format("bayes: spins must be in [1, 8], not {}", options.spins),
                    ErrorKind::InvalidArgument);
    if (options.opponent && color.channels != 3)
        throw Error(
            fmt::format("bayes: luminance + chroma needs 3 channels, not {}", color.channels),
            ErrorKind::InvalidArgument);
}

// Channel groups of the transform: group g holds channels [g size, g size + Channels(g)).
struct ChannelGroups {
    int size = 0, count = 1, last = 0;
    int Channels(int g) const { return g == count - 1 ? last : size; }
};

// --bayes-transform swt: the stationary transform's coefficients, channels (3 levels + 1)
// full-size planes, in groups of as many channels as one binding holds (bands and fits are
// per channel, so the groups change nothing); refused up front when not even one
// channel's fit. The DWT has one group.
ChannelGroups BayesChannelGroups(vk::Context &context, const Image &color, int levels, bool swt,
                                 const RunSetup &setup) {
    int w = color.width, h = color.height, channels = color.channels;
    ChannelGroups groups;
    groups.size = channels;
    if (swt) {
        groups.size = std::min(channels, SwtChannelsPerBinding(context, w, h, levels));
        if (groups.size < 1)
            CheckSwtFits(context, w, h, 1, levels, "bayes --bayes-transform swt");
        if (setup.swtGroupChannels > 0)
            groups.size = std::min(groups.size, setup.swtGroupChannels);
    }
    groups.count = (channels + groups.size - 1) / groups.size;
    groups.last = channels - (groups.count - 1) * groups.size;
    if (groups.count > 1 && setup.keepStages)
        throw Error(
            fmt::format(
                "bayes: the SWT of this {}x{}x{} image runs in {} channel groups (one binding "
                "holds {} channels' coefficients); the stages need one: use --bayes-transform "
                "dwt or a smaller image",
                w, h, channels, groups.count, groups.size),
            ErrorKind::InvalidArgument);
    return groups;
}

// The GPU side of a run: the input, the work image (log, then coefficients for the DWT,
// then the synthesis), the output, the log floors, and the transforms.
struct BayesGpu {
    BayesGpu(vk::Context &context, const Image &image, const std::vector<float> &logFloors,
             int levels, bool swt, const ChannelGroups &groups, WaveletBasis basis)
        : color(context, image.width, image.height, image.channels, "bayes.color"),
          work(context, image.width, image.height, image.channels, "bayes.work"),
          out(context, image.width, image.height, image.channels, "bayes.out"),
          floors(context, image.channels * sizeof(float), "bayes.floors"),
          transform(context, image.width, image.height, image.channels),
          levels(levels),
          swt(swt),
          groups(groups),
          basis(basis) {
        color.Upload(image);
        floors.UploadFloats(logFloors);
        // A smaller last group has a transform of its own, sharing the coefficient buffer.
        if (swt) {
            swtTransform.emplace(context, image.width, image.height, groups.size, levels);
            if (groups.last != groups.size)
                swtLast.emplace(context, image.width, image.height, groups.last, levels);
            swtCoef = swtTransform->MakeCoefficients("bayes.swt");
        }
    }

    // The coefficients the moments and the shrinkage read: the SWT's, or the DWT's in place.
    vk::GpuImage &Coefficients() { return swt ? swtCoef : work; }

    // Analysis of group g's channels of `work` into Coefficients() (the DWT: g = 0).
    void RecordAnalysis(vk::Recorder &recorder, int g) {
        if (!swt) return transform.RecordAnalysis(recorder, basis, levels, work, work);
        SwtTransform &t = g == groups.count - 1 && swtLast ? *swtLast : *swtTransform;
        t.RecordAnalysis(recorder, basis, work, swtCoef, false, g * groups.size);
    }
    // Its synthesis back into those channels of `work`.
    void RecordSynthesis(vk::Recorder &recorder, int g) {
        if (!swt) return transform.RecordSynthesis(recorder, basis, levels, work, work);
        SwtTransform &t = g == groups.count - 1 && swtLast ? *swtLast : *swtTransform;
        t.RecordSynthesis(recorder, basis, swtCoef, work, g * groups.size);
    }

    vk::GpuImage color, work, out;
    vk::Buffer floors;
    WaveletTransform transform;
    std::optional<SwtTransform> swtTransform, swtLast;
    vk::GpuImage swtCoef;
    int levels;
    bool swt;
    ChannelGroups groups;
    WaveletBasis basis;
};

// Every band's noise s from one s_n: the finest level's hpFactor times it.
std::vector<float> FixedBandNoise(int bands, int levels, float sn, float hpFactor) {
    std::vector<float> bandSn(bands);
    for (int b = 0; b < bands; ++b)
        bandSn[b] = (b % (3 * levels)) / 3 == 0 ? sn * hpFactor : sn;
    return bandSn;
}

// The noise s of every band (band order of shaders/bayes/bayes.h) and the s_n reported
// (*sn): options.sn, or from `variance` (the layer --noise variance or auto reads), or
// --noise mad's estimate from the analysed coefficients (which submits, and leaves group
// 0's coefficients in place).
std::vector<float> BandNoise(StagedRun &run, BayesGpu &gpu, const Image &color,
                             const std::vector<float> &floors, const BayesParams &options,
                             const RunSetup &setup, const Image *variance, float *sn) {
    int levels = gpu.levels, channels = color.channels, groups = gpu.groups.count;
    int bands = BayesBandCount(channels, levels);
    *sn = options.sn;
    if (variance) {
        std::vector<float> bandSn = BayesVarianceNoise(
            run.Context(), color, *variance, floors, options.basis, levels, options.pn,
            options.opponent, &run.Timings(), options.transform, setup.swtGroupChannels);
        double mean = 0;
        for (float v : bandSn) mean += v / bands;
        *sn = float(mean);
        std::string perLevel;
        for (int level = 0; level < levels; ++level) {
            double m = 0;
            for (int c = 0; c < channels; ++c)
                for (int o = 0; o < 3; ++o)
                    m += bandSn[(c * levels + level) * 3 + o] / (3.0 * channels);
            perLevel += fmt::format("{}{:.4g}", level ? ", " : "", m);
        }
        run.Plan(fmt::format(
            "--noise variance: per band from the variance layer: log(1 + V / max(Y, "
            "floor)^2) per pixel (the delta method's V / Y^2, exact for log-normal), "
            "squared-filter {}, band mean -> s (p_n {}); mean s per level (finest "
            "first) {}",
            gpu.swt ? "SWT" : "DWT", options.pn, perLevel));
        return bandSn;
    }
    if (MadNoise(options, variance)) {
        run.Submit();
        double mad = 0;
        if (gpu.swt) {
            // Every group's finest HH planes, pooled; then group 0's coefficients again.
            std::vector<float> values;
            for (int g = 0; g < groups; ++g) {
                if (g > 0) {
                    gpu.RecordAnalysis(run.Recorder(), g);
                    run.Submit();
                }
                CollectFinestHH(gpu.swtCoef, gpu.groups.Channels(g), levels, &values);
            }
            if (groups > 1) gpu.RecordAnalysis(run.Recorder(), 0);
            mad = MedianOf(values);
        } else {
            mad = FinestMad(gpu.work.Download());
        }
        double finest = BayesScaleFromMad(mad, options.pn);
        *sn = float(finest / options.hpFactor);
        run.Plan(
            fmt::format("--noise auto: finest HH bands' median non-zero |y| {:.4g} -> "
                        "finest-level s {:.4g} (p_n {}) -> s_n {:.4g}",
                        mad, finest, options.pn, *sn));
    }
    return FixedBandNoise(bands, levels, *sn, options.hpFactor);
}

// Per group: its bands' noise, moments, (s_c, p_c) fits and posterior-mean tables.
struct BandBuffers {
    std::vector<vk::Buffer> noises, moments, params, tables;
};

// Per channel group (one unless the SWT is split): its bands' moments, fits, tables,
// shrinkage and synthesis (group 0 analysed already). The buffers live in `buffers` until
// the submission.
void RecordShrinkage(StagedRun &run, BayesGpu &gpu, const std::vector<float> &bandSn, float pn,
                     BandBuffers &buffers) {
    vk::Context &context = run.Context();
    vk::Recorder &recorder = run.Recorder();
    int levels = gpu.levels, groups = gpu.groups.count;
    int bands = BayesBandCount(gpu.work.channels, levels);
    for (auto *v : {&buffers.noises, &buffers.moments, &buffers.params, &buffers.tables})
        v->reserve(groups);
    for (int g = 0; g < groups; ++g) {
        int inGroup = gpu.groups.Channels(g);
        int groupBands = BayesBandCount(inGroup, levels);
        int firstBand = BayesBandCount(g * gpu.groups.size, levels);
        if (g > 0) gpu.RecordAnalysis(recorder, g);
        vk::Buffer &noise =
            buffers.noises.emplace_back(context, groupBands * sizeof(float), "bayes.noise");
        noise.UploadFloats(std::vector<float>(bandSn.begin() + firstBand,
                                              bandSn.begin() + firstBand + groupBands));
        vk::Buffer &moments = buffers.moments.emplace_back(
            context, groupBands * BAYES_MOMENT_STRIDE * sizeof(float), "bayes.moments");
        vk::Buffer &params = buffers.params.emplace_back(
            context, groupBands * BAYES_PARAM_STRIDE * sizeof(float), "bayes.params");
        vk::Buffer &table = buffers.tables.emplace_back(
            context, groupBands * BAYES_TABLE_SIZE * sizeof(float), "bayes.table");
        if (gpu.swt)
            RecordBayesSwtMoments(context, recorder, gpu.swtCoef, inGroup, levels, moments);
        else
            RecordBayesMoments(context, recorder, gpu.work, levels, moments);
        run.Stage("moments", [&] {
            std::vector<float> m = moments.DownloadFloats(size_t(bands) * BAYES_MOMENT_STRIDE);
            Image rows(BAYES_MOMENT_STRIDE, bands, 1);
            std::copy(m.begin(), m.end(), rows.data.begin());
            return rows;
        });
        RecordBayesSolve(context, recorder, moments, groupBands, levels, noise, pn, params);
        run.Stage("fits", [&] {
            std::vector<float> p = params.DownloadFloats(size_t(bands) * BAYES_PARAM_STRIDE);
            Image fits(3, bands, 1);
            for (int b = 0; b < bands; ++b)
                for (int i = 0; i < 3; ++i)
                    fits.At(0, b, i) = p[size_t(b) * BAYES_PARAM_STRIDE + 2 + i];
            return fits;
        });
        RecordBayesTable(context, recorder, params, groupBands, table);
        if (gpu.swt)
            RecordBayesSwtShrink(context, recorder, gpu.swtCoef, inGroup, levels, params,
                                 table);
        else
            RecordBayesShrink(context, recorder, gpu.work, levels, params, table);
        run.Stage("shrinkage", gpu.Coefficients());
        gpu.RecordSynthesis(recorder, g);
    }
}

// Every band's fit, from the groups' parameter buffers (after the submission).
std::vector<BayesBandFit> ReadFits(const BandBuffers &buffers, int bands, int levels) {
    std::vector<float> p;
    for (const vk::Buffer &params : buffers.params) {
        std::vector<float> q = params.DownloadFloats(params.Bytes() / sizeof(float));
        p.insert(p.end(), q.begin(), q.end());
    }
    std::vector<BayesBandFit> fits;
    for (int b = 0; b < bands; ++b) {
        BayesBandFit fit{b / (3 * levels), (b % (3 * levels)) / 3, b % 3, {}};
        std::copy_n(p.begin() + b * BAYES_PARAM_STRIDE, BAYES_PARAM_STRIDE, fit.params.begin());
        fits.push_back(fit);
    }
    return fits;
}

// The plan's lines on the transform, the noise and every band's fit.
void PlanBands(StagedRun &run, const BayesGpu &gpu, float sn,
               const std::vector<BayesBandFit> &fits, const BayesParams &options,
               bool noisePerBand) {
    std::string transformName = gpu.swt ? "stationary (undecimated) wavelet transform "
                                          "(--bayes-transform swt)"
                                        : "DWT (--bayes-transform dwt)";
    if (gpu.groups.count > 1)
        transformName += fmt::format(
            " in {} channel groups (one binding holds the coefficients of {} channel{})",
            gpu.groups.count, gpu.groups.size, gpu.groups.size == 1 ? "" : "s");
    if (noisePerBand)
        run.Plan(fmt::format("{}-level {} {}; noise per band (mean s {:.4g}), p_n {}",
                             gpu.levels, WaveletName(options.basis), transformName, sn,
                             options.pn));
    else
        run.Plan(fmt::format(
            "{}-level {} {}; noise (s_n {:.4g}, p_n {}), finest level s {:.4g} ({} x s_n)",
            gpu.levels, WaveletName(options.basis), transformName, sn, options.pn,
            sn * options.hpFactor, options.hpFactor));
    run.Plan(fmt::format(
        "per band: E[y^2], E[y^4] -> (s_c, p_c) by eqs. 17-18; posterior-mean table of "
        "{} entries (log-sum-exp quadrature), applied with interpolation",
        BAYES_TABLE_SIZE));
    static const char *kOrientation[3] = {"HL", "LH", "HH"};
    for (const BayesBandFit &f : fits) {
        int fit = int(f.params[4]);
        run.Plan(fmt::format("  band L{} {} ch{}: y_max {:.3g}, s_c {:.4g}, p_c {:.3g}: {}",
                             f.level, kOrientation[f.orientation], f.channel, f.params[5],
                             f.params[2], f.params[3], BayesFitName(fit)));
    }
    run.Plan("synthesis, exp");
}

// Log, transform, shrink, synthesise, exp into gpu.out, with levels > 0; with keepStages
// each stage is submitted and downloaded.
void RecordBayes(StagedRun &run, BayesGpu &gpu, const Image &color,
                 const std::vector<float> &floors, const BayesParams &options,
                 const RunSetup &setup, const Image *variance, BayesResult &result) {
    vk::Context &context = run.Context();
    vk::Recorder &recorder = run.Recorder();
    if (options.opponent) {
        RecordBayesMix(context, recorder, gpu.work, BayesOpponent());
        run.Plan("colour: log luminance + 2 log chroma (orthonormal opponent transform)");
        run.Stage("opponent", gpu.work);
    }
    gpu.RecordAnalysis(recorder, 0);
    run.Stage("analysis", gpu.Coefficients());
    float sn = 0;
    std::vector<float> bandSn =
        BandNoise(run, gpu, color, floors, options, setup, variance, &sn);
    result.sn = sn;
    BandBuffers buffers;
    RecordShrinkage(run, gpu, bandSn, options.pn, buffers);
    run.Stage("synthesis", gpu.work);
    if (options.opponent) {
        RecordBayesMix(context, recorder, gpu.work, BayesOpponentInverse());
        run.Stage("opponent inverse", gpu.work);
    }
    RecordBayesExp(context, recorder, gpu.work, gpu.color, gpu.out, options.restoreZeros);
    run.Submit();
    result.fits = ReadFits(buffers, BayesBandCount(color.channels, gpu.levels), gpu.levels);
    PlanBands(run, gpu, sn, result.fits, options, variance != nullptr);
}

BayesResult BayesDenoiseOnce(vk::Context &context, const Image &color,
                             const BayesParams &options, const RunSetup &setup,
                             const Image *variance) {
    CheckBayesParams(color, options);
    BayesResult result;
    StagedRun run(context, setup.keepStages);
    int levels = std::min(options.levels, MaxWaveletLevels(color.width, color.height));
    result.levels = levels;
    std::vector<float> floors = BayesFloors(color, options.floorRel);
    CountSpecials(color, floors, options.restoreZeros, run);
    run.Plan(fmt::format(
        "log domain (eqs. 4-5), per channel; floor {} x the channel's median positive value; "
        "{}",
        options.floorRel,
        options.restoreZeros
            ? "dark pixels lone among lit pixels (no two opposite 3x3 neighbour pixels dark: "
              "samples that missed the light) take their lit neighbours' mean log; zeros "
              "inside black or on a black line in their channel restored exactly after exp"
            : "zeros denoised like other pixels (--zeros denoise)"));
    if (levels < options.levels)
        run.Plan(fmt::format("{} levels requested; a {}x{} image allows {}", options.levels,
                             color.width, color.height, levels));

    bool swt = options.transform == BayesTransform::Swt && levels > 0;
    ChannelGroups groups = BayesChannelGroups(context, color, levels, swt, setup);
    BayesGpu gpu(context, color, floors, levels, swt, groups, options.basis);
    RecordBayesLog(context, run.Recorder(), gpu.color, gpu.floors, gpu.work,
                   options.restoreZeros);
    run.Stage("log", gpu.work);
    if (levels == 0) {
        run.Plan("left out: the shrinkage (a 1x1 image has no detail band)");
        RecordBayesExp(context, run.Recorder(), gpu.work, gpu.color, gpu.out,
                       options.restoreZeros);
        run.Submit();
    } else {
        RecordBayes(run, gpu, color, floors, options, setup, variance, result);
    }
    result.image = gpu.out.Download();
    run.AddStage("exp", result.image);
    run.Finish(result);
    RestoreMeans(color, options, setup.keepStages, variance, &result);
    return result;
}

}  // namespace

void CheckBayesZeros(const Image &color, const BayesParams &params, const std::string &layer) {
    if (!params.restoreZeros) return;
    // Bad parameters and an empty image are refused as such, not as "0 of 0" zeros.
    CheckBayesParams(color, params);
    CheckZerosRestorable(color, layer);
}

BayesResult BayesDenoise(vk::Context &context, const Image &color, const BayesParams &params,
                         const RunSetup &setup, const Image *variance) {
    CheckBayesParams(color, params);
    variance = NoiseVariance(params, variance);
    if (!setup.zerosDecided) CheckBayesZeros(color, params);
    if (params.spins == 1) {
        BayesResult result = BayesDenoiseOnce(context, color, params, setup, variance);
        CapLonePeaks(color, &result);
        return result;
    }
    // Cycle spinning: the first shift's result carries the plan, warnings and fits.
    BayesParams once = params;
    once.spins = 1;
    once.keepMean = false;  // applied once to the average below
    once.meanRadius = 0;
    BayesResult result;
    result.image =
        CycleSpin(color.width, color.height, color.channels, params.spins, [&](int dx, int dy) {
            Image padded = MirrorPad(color, dx, dy);
            // --noise variance: the variance layer shifted like the image,
            // estimated per shift.
            Image paddedVariance;
            if (variance) paddedVariance = MirrorPad(*variance, dx, dy);
            BayesResult one = BayesDenoiseOnce(context, padded, once, setup,
                                               variance ? &paddedVariance : nullptr);
            if (MadNoise(once, variance)) {
                // One noise estimate for every shift, the unshifted
                // image's: the shifts must differ only in where the
                // transform's grid falls.
                once.noise = BayesNoise::Fixed;
                once.sn = one.sn;
            }
            for (const vk::DispatchTiming &t : one.timings) result.timings.push_back(t);
            if (dx == 0 && dy == 0) {
                result.plan = std::move(one.plan);
                result.warnings = std::move(one.warnings);
                result.fits = std::move(one.fits);
                result.sn = one.sn;
                result.levels = one.levels;
                result.stages = std::move(one.stages);
            }
            return std::move(one.image);
        });
    result.plan.insert(result.plan.begin(),
                       fmt::format("cycle spinning: the average over {} x {} shifts (mirrored "
                                   "padding); the bands below (and --noise auto's estimate, "
                                   "used by every shift) are the unshifted run's",
                                   params.spins, params.spins));
    if (setup.keepStages) result.stages.push_back({"cycle spinning", result.image});
    RestoreMeans(color, params, setup.keepStages, variance, &result);
    CapLonePeaks(color, &result);
    return result;
}

Image SplitIndirect(const Image &direct, const Image &indirect, size_t *rounded) {
    Image out = indirect;
    *rounded = 0;
    for (size_t i = 0; i < out.Size(); ++i) {
        float v = out.data[i], d = direct.data[i];
        if (v < 0 && std::isfinite(d) &&
            -v <= kSplitRoundingEpsilons * std::numeric_limits<float>::epsilon() * std::fabs(d))
            out.data[i] = 0, ++*rounded;
    }
    return out;
}

BayesResult BayesDenoiseSplit(vk::Context &context, const Image &direct, const Image &indirect,
                              const BayesParams &params, const RunSetup &setup,
                              const Image *variance) {
    if (!direct.SameShape(indirect))
        throw Error(fmt::format("bayes: direct is {}x{}x{} but indirect is {}x{}x{}",
                                direct.width, direct.height, direct.channels, indirect.width,
                                indirect.height, indirect.channels),
                    ErrorKind::InvalidArgument);
    size_t rounded = 0;
    Image split = SplitIndirect(direct, indirect, &rounded);
    // A refusal of the indirect layer names it, as the warnings below do.
    RunSetup decided = setup;
    if (!setup.zerosDecided) CheckBayesZeros(split, params, " (indirect layer)");
    decided.zerosDecided = true;
    BayesResult result = BayesDenoise(context, split, params, decided, variance);
    // Its warnings are about the indirect layer, which the user may not know is what ran.
    for (std::string &warning : result.warnings)
        if (warning.rfind("bayes: ", 0) == 0) warning.insert(5, " (indirect layer)");
    if (rounded)
        result.plan.push_back(fmt::format(
            "{} value{} of the indirect layer below 0 by the split's rounding only (at most {} "
            "float epsilons times |direct|, 8 to 16 ulps of direct, where direct + indirect = "
            "color) taken as 0",
            rounded, rounded == 1 ? "" : "s", kSplitRoundingEpsilons));
    size_t nonFinite = 0;
    for (size_t i = 0; i < direct.Size(); ++i) {
        float d = direct.data[i];
        if (!Finite(d)) {
            ++nonFinite;
            d = 0;
        }
        result.image.data[i] += d;
    }
    if (nonFinite)
        result.warnings.push_back(
            fmt::format("bayes: {} NaN/Inf values in the direct layer, taken as 0", nonFinite));
    result.plan.insert(result.plan.begin(),
                       "split (section 4.1): only the indirect layer is denoised; the direct "
                       "layer is added back");
    return result;
}

}  // namespace mcd
