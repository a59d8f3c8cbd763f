#include "host/methods/auto_halves.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "host/error.h"

namespace mcd {

namespace {

// The mean of a plane's finite values (0 where it has none).
double FiniteMean(const float *plane, size_t count) {
    double sum = 0;
    size_t n = 0;
    for (size_t i = 0; i < count; ++i)
        if (std::isfinite(plane[i])) sum += plane[i], ++n;
    return n ? sum / double(n) : 0;
}

// The median of a few values (the mean of the middle two of an even count).
double Median(std::vector<double> values) {
    std::sort(values.begin(), values.end());
    size_t n = values.size();
    return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

// The smallest median a ratio is taken against; below it the estimates over the frame
// tell nothing (the halves' noise or shared bias outweighs them) and none is left out. The
// median, not the best: a candidate that keeps the bias the halves share has an estimate
// biased low, at times below zero, and against it every other would be left out.
constexpr double kDropFloor = 1e-4;

// The smallest share of half1's variance over the frame a candidate's estimate over the
// frame counts as in the rank, and that the candidates' median must pass for the drop: below
// it the frame's noise hides the differences (fence_grass in docs/methods/auto.md), and a
// candidate whose estimate is about zero or below would take every weight.
constexpr double kRankNoise = 0.01;

// Each candidate's factor on the floor: (its frame estimate / the smallest of those left
// in) ^ power, the estimates raised to kRankNoise x the frame's noise first; 1 without rank.
std::vector<float> RankFactors(const std::vector<double> &frame, double noise,
                               const std::vector<bool> &dropped, float power, float least) {
    std::vector<float> factors(frame.size(), 1.f);
    if (power <= 0) return factors;
    const double bottom = std::max(kRankNoise * noise, double(least));
    double smallest = std::numeric_limits<double>::infinity();
    for (size_t k = 0; k < frame.size(); ++k)
        if (!dropped[k]) smallest = std::min(smallest, std::max(frame[k], bottom));
    for (size_t k = 0; k < frame.size(); ++k)
        if (!dropped[k])
            factors[k] = float(std::pow(std::max(frame[k], bottom) / smallest, double(power)));
    return factors;
}

// After the floor, each variant's estimate times its factor: max(e, floorError), as the
// combination reads it, so that an estimate at or below floorError shares too. Left as they
// are where every estimate left in is under floorError: the combination weighs the
// candidates equally there (its median), with no weights to share. The product is capped at
// the largest float, so that a factor near it leaves the candidate in.
void ShareVariants(Image &smooth, const std::vector<bool> &dropped,
                   const std::vector<float> &factors, float floorError) {
    const size_t n = smooth.PixelCount();
    const int count = smooth.channels;
    if (std::all_of(factors.begin(), factors.end(), [](float f) { return f == 1.f; })) return;
    const double largest = std::numeric_limits<float>::max();
    for (size_t i = 0; i < n; ++i) {
        bool weighed = false;
        for (int k = 0; k < count; ++k)
            if (float e = smooth.data[size_t(k) * n + i]; !dropped[k] && std::isfinite(e))
                weighed = weighed || e >= floorError;
        if (!weighed) continue;
        for (int k = 0; k < count; ++k) {
            float &e = smooth.data[size_t(k) * n + i];
            if (!dropped[k] && factors[k] != 1.f && std::isfinite(e))
                e = float(std::min(double(std::max(e, floorError)) * factors[k], largest));
        }
    }
}

// Sums over tents of `radius` of `plane` (width x height) into `out`: weights (r + 1 - |dx|)
// (r + 1 - |dy|), or their squares with `squared`; pixels past the frame's edge weigh 0.
void TentSums(const float *plane, int width, int height, int radius, bool squared,
              std::vector<double> &rows, std::vector<double> &out) {
    std::vector<double> taps(2 * radius + 1);
    for (int d = -radius; d <= radius; ++d) {
        const double t = radius + 1 - std::abs(d);
        taps[d + radius] = squared ? t * t : t;
    }
    rows.assign(size_t(width) * height, 0.0);
    out.assign(size_t(width) * height, 0.0);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
            for (int d = std::max(-radius, -x); d <= std::min(radius, width - 1 - x); ++d)
                rows[size_t(y) * width + x] +=
                    taps[d + radius] * plane[size_t(y) * width + x + d];
    for (int y = 0; y < height; ++y)
        for (int d = std::max(-radius, -y); d <= std::min(radius, height - 1 - y); ++d)
            for (int x = 0; x < width; ++x)
                out[size_t(y) * width + x] +=
                    taps[d + radius] * rows[size_t(y + d) * width + x];
}

}  // namespace

void AutoHalvesSums::Add(const Image &smooth, const Image &noise) {
    const size_t n = smooth.PixelCount();
    const size_t begin = size_t(rowBegin) * smooth.width, end = size_t(rowEnd) * smooth.width;
    sum.resize(smooth.channels, 0.0);
    count.resize(smooth.channels, 0);
    // The order of FiniteMean over the whole frame: pixels in order, strips top to bottom.
    for (int k = 0; k < smooth.channels; ++k)
        for (size_t i = begin; i < end; ++i)
            if (float e = smooth.data[size_t(k) * n + i]; std::isfinite(e))
                sum[k] += e, ++count[k];
    for (size_t i = begin; i < end; ++i)
        if (std::isfinite(noise.data[i])) noiseSum += noise.data[i], ++noiseCount;
}

std::vector<double> AutoHalvesSums::Means() const {
    std::vector<double> means;
    for (size_t k = 0; k < sum.size(); ++k)
        means.push_back(count[k] ? sum[k] / double(count[k]) : 0);
    return means;
}

std::vector<bool> AutoHalvesDropped(const std::vector<double> &frameEstimates, float drop,
                                    double frameNoise, double *median) {
    *median = Median(frameEstimates);
    std::vector<bool> dropped(frameEstimates.size(), false);
    // A median within the share of half1's variance the rank reads as noise tells nothing
    // either: the candidates' estimates over the frame differ by less than half1's noise.
    if (drop > 0 && *median > std::max(kDropFloor, kRankNoise * frameNoise))
        for (size_t k = 0; k < frameEstimates.size(); ++k)
            dropped[k] = frameEstimates[k] > drop * *median;
    return dropped;
}

std::vector<float> AutoVariantFactors(const std::vector<int> &method,
                                      const std::vector<bool> &dropped, float power) {
    std::vector<float> factors(dropped.size(), 1.f);
    if (method.empty() || power <= 0) return factors;
    if (method.size() != dropped.size())
        throw Error("auto: the variants' methods must hold one per candidate",
                    ErrorKind::Internal);
    for (size_t k = 0; k < method.size(); ++k) {
        if (dropped[k]) continue;
        int siblings = 0;
        for (size_t j = 0; j < method.size(); ++j)
            siblings += !dropped[j] && method[j] == method[k];
        // In double and capped: below a power of about 0.01 the root of a few siblings
        // overflows a float.
        factors[k] = float(std::min(std::pow(double(siblings), 1.0 / double(power)),
                                    double(std::numeric_limits<float>::max())));
    }
    return factors;
}

AutoHalvesResult AutoAdjustHalvesEstimates(Image &smooth, const Image &noise,
                                           const AutoHalvesSettings &settings) {
    const size_t n = smooth.PixelCount();
    const int count = smooth.channels;
    if (noise.channels != 1 || noise.PixelCount() != n || noise.width != smooth.width)
        throw Error("auto: the halves' noise must be one plane of the estimates' size",
                    ErrorKind::Internal);
    AutoHalvesResult result;
    for (int k = 0; k < count; ++k)
        result.frameEstimates.push_back(FiniteMean(smooth.Plane(k), n));
    result.frameNoise = FiniteMean(noise.data.data(), n);
    result.dropped = AutoHalvesDropped(result.frameEstimates, settings.drop, result.frameNoise,
                                       &result.median);
    if (settings.dropped) {
        if (settings.dropped->size() != size_t(count))
            throw Error("auto: the halves' decided drop must hold one flag per candidate",
                        ErrorKind::Internal);
        result.dropped = *settings.dropped;
    }
    const bool whole = settings.frameEstimates != nullptr;
    if (whole && settings.frameEstimates->size() != size_t(count))
        throw Error("auto: the halves' frame estimates must hold one per candidate",
                    ErrorKind::Internal);
    const std::vector<float> factors =
        RankFactors(whole ? *settings.frameEstimates : result.frameEstimates,
                    whole ? settings.frameNoise : result.frameNoise, result.dropped,
                    settings.rank, settings.floorError);
    std::vector<float> kept;
    for (size_t i = 0; i < n && settings.floor > 0; ++i) {
        kept.clear();
        for (int k = 0; k < count; ++k) {
            float e = smooth.data[size_t(k) * n + i];
            if (!result.dropped[k] && std::isfinite(e))
                kept.push_back(std::max(e, settings.floorError));
        }
        if (kept.empty()) continue;
        auto middle = kept.begin() + kept.size() / 2;
        std::nth_element(kept.begin(), middle, kept.end());
        float median = *middle;
        if (kept.size() % 2 == 0)
            median = 0.5f * (median + *std::max_element(kept.begin(), middle));
        float least = std::min(std::max(noise.data[i], 0.f), settings.floor * median);
        for (int k = 0; k < count; ++k) {
            float &e = smooth.data[size_t(k) * n + i];
            if (!result.dropped[k]) e = std::max(e, least * factors[k]);
        }
    }
    result.variants = AutoVariantFactors(settings.method, result.dropped, settings.power);
    ShareVariants(smooth, result.dropped, result.variants, settings.floorError);
    for (int k = 0; k < count; ++k)
        if (result.dropped[k])
            std::fill_n(smooth.Plane(k), n, std::numeric_limits<float>::infinity());
    return result;
}

std::vector<double> AutoGuardLocalMeans(Image &smooth, const Image &color,
                                        const std::vector<const Image *> &outputs,
                                        const Image &variance, const AutoMeanGuard &guard) {
    const int w = color.width, h = color.height, channels = color.channels;
    const size_t n = color.PixelCount();
    if (smooth.channels != int(outputs.size()) || smooth.PixelCount() != n ||
        !variance.SameShape(color))
        throw Error(
            "auto: the guard reads one estimate plane per output and the colour's "
            "variance",
            ErrorKind::Internal);
    for (const Image *output : outputs)
        if (!output->SameShape(color))
            throw Error("auto: the guard's outputs must have the colour's shape",
                        ErrorKind::Internal);
    std::vector<double> raised(outputs.size(), 0.0);
    if (guard.z <= 0) return raised;
    // Each channel's tent weight over the frame, its colour's tent mean and that mean's
    // variance, shared by every candidate.
    std::vector<double> rows, ones, sums, mean(n * channels), meanVariance(n * channels);
    const std::vector<float> one(n, 1.f);
    TentSums(one.data(), w, h, guard.radius, false, rows, ones);
    for (int c = 0; c < channels; ++c) {
        TentSums(color.Plane(c), w, h, guard.radius, false, rows, sums);
        for (size_t i = 0; i < n; ++i) mean[c * n + i] = sums[i] / ones[i];
        TentSums(variance.Plane(c), w, h, guard.radius, true, rows, sums);
        for (size_t i = 0; i < n; ++i) {
            const double least = std::max(kAutoGuardRelative * std::abs(mean[c * n + i]),
                                          double(kAutoGuardLeastError));
            meanVariance[c * n + i] =
                std::max(sums[i], 0.0) / (ones[i] * ones[i]) + least * least;
        }
    }
    std::vector<double> t2(n);
    for (size_t k = 0; k < outputs.size(); ++k) {
        std::fill(t2.begin(), t2.end(), 0.0);
        for (int c = 0; c < channels; ++c) {
            TentSums(outputs[k]->Plane(c), w, h, guard.radius, false, rows, sums);
            for (size_t i = 0; i < n; ++i) {
                const double departure = sums[i] / ones[i] - mean[c * n + i];
                const double v = meanVariance[c * n + i];
                // A NaN variance is not noise, as in the combination: no guard there.
                if (std::isnan(v)) {
                    t2[i] = std::numeric_limits<double>::quiet_NaN();
                    continue;
                }
                if (departure != 0) t2[i] += departure * departure / v;
            }
        }
        float *plane = smooth.Plane(int(k));
        const double z2 = double(guard.z) * guard.z;
        for (size_t i = 0; i < n; ++i) {
            // The normal density's ratio at z over that at t.
            const double logRatio = std::min(0.5 * (t2[i] / channels - z2), kAutoGuardMostLog);
            if (!(logRatio > 0) || !std::isfinite(plane[i])) continue;
            plane[i] = float(double(std::max(plane[i], guard.floorError)) * std::exp(logRatio));
            raised[k] += 1.0 / double(n);
        }
    }
    return raised;
}

}  // namespace mcd
