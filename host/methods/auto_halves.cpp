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

}  // namespace

AutoHalvesResult AutoAdjustHalvesEstimates(Image &smooth, const Image &noise,
                                           const AutoHalvesSettings &settings) {
    const size_t n = smooth.PixelCount();
    const int count = smooth.channels;
    if (noise.channels != 1 || noise.PixelCount() != n || noise.width != smooth.width)
        throw Error("auto: the halves' noise must be one plane of the estimates' size",
                    ErrorKind::Internal);
    AutoHalvesResult result;
    result.dropped.assign(count, false);
    for (int k = 0; k < count; ++k)
        result.frameEstimates.push_back(FiniteMean(smooth.Plane(k), n));
    result.median = Median(result.frameEstimates);
    result.frameNoise = FiniteMean(noise.data.data(), n);
    if (settings.drop > 0 && result.median > kDropFloor)
        for (int k = 0; k < count; ++k)
            result.dropped[k] = result.frameEstimates[k] > settings.drop * result.median;
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
            if (!result.dropped[k]) e = std::max(e, least);
        }
    }
    for (int k = 0; k < count; ++k)
        if (result.dropped[k])
            std::fill_n(smooth.Plane(k), n, std::numeric_limits<float>::infinity());
    return result;
}

}  // namespace mcd
