#include "host/common/pivot_spikes.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "host/common/parallel.h"
#include "host/error.h"

namespace mcd {
namespace {

// The lower middle of the values of `plane` at the 8 neighbours of (x, y) within the image.
double NeighbourMedian(const float *plane, int w, int h, int x, int y) {
    float values[8];
    int n = 0;
    for (int v = std::max(0, y - 1); v <= std::min(h - 1, y + 1); ++v)
        for (int u = std::max(0, x - 1); u <= std::min(w - 1, x + 1); ++u)
            if (u != x || v != y) values[n++] = plane[size_t(v) * w + u];
    std::nth_element(values, values + (n - 1) / 2, values + n);
    return values[(n - 1) / 2];
}

// Each pixel's channels summed (NaN where one is not finite).
std::vector<float> Sums(const Image &image) {
    std::vector<float> sums(image.PixelCount(), 0.0f);
    for (int c = 0; c < image.channels; ++c) {
        const float *plane = image.Plane(c);
        for (size_t p = 0; p < sums.size(); ++p)
            sums[p] = std::isfinite(plane[p]) ? sums[p] + plane[p] : NAN;
    }
    return sums;
}

// Where p's pivot sum is a spike over its neighbours' median, how many of them are so too;
// -1 where it is not. `median`, where given, takes that median.
int SpikeNeighbours(const std::vector<float> &sums, int w, int h, int x, int y,
                    double *median = nullptr) {
    const size_t p = size_t(y) * w + x;
    if (!std::isfinite(sums[p]) || w * h == 1) return -1;
    int over = 0;
    for (int v = std::max(0, y - 1); v <= std::min(h - 1, y + 1); ++v)
        for (int u = std::max(0, x - 1); u <= std::min(w - 1, x + 1); ++u)
            if (!std::isfinite(sums[size_t(v) * w + u])) return -1;
    // A median of 0 (background, black material) would take the tips of thin objects and
    // small lights to 0.
    const double level = NeighbourMedian(sums.data(), w, h, x, y);
    if (!(level > 0) || !(sums[p] > kPivotSpike * level)) return -1;
    for (int v = std::max(0, y - 1); v <= std::min(h - 1, y + 1); ++v)
        for (int u = std::max(0, x - 1); u <= std::min(w - 1, x + 1); ++u)
            if ((u != x || v != y) && sums[size_t(v) * w + u] > kPivotSpike * level) ++over;
    if (median) *median = level;
    return over;
}

// Whether every neighbour of p not over kPivotSpike times `median` (the dark ones the median
// is of) has p's ids (each id layer present; true without). A mirror's reflection has the
// mirror's ids as the dark mirror around it; a thin bright part (a wire) has its own.
bool DarkNeighboursShareIds(const std::vector<float> &sums, const Image *objectId,
                            const Image *partId, int w, int h, int x, int y, double median) {
    const size_t p = size_t(y) * w + x;
    for (int v = std::max(0, y - 1); v <= std::min(h - 1, y + 1); ++v)
        for (int u = std::max(0, x - 1); u <= std::min(w - 1, x + 1); ++u) {
            const size_t q = size_t(v) * w + u;
            if (q == p || sums[q] > kPivotSpike * median) continue;
            for (const Image *id : {objectId, partId})
                if (id && id->data[q] != id->data[p]) return false;
        }
    return true;
}

// Whether p's pivot sum is a lone spike over its neighbours' median.
bool LoneSpike(const std::vector<float> &sums, int w, int h, int x, int y) {
    const int over = SpikeNeighbours(sums, w, h, x, y);
    return over >= 0 && over < 2;
}

// Whether p's colour is noisy enough to be a few samples' firefly.
bool FewSamples(const Image &color, const Image &variance, size_t p) {
    double value = 0, var = 0;
    for (int c = 0; c < color.channels; ++c) {
        const float v = variance.Plane(variance.channels == 1 ? 0 : c)[p];
        if (!std::isfinite(v) || v < 0) return false;
        value += color.Plane(c)[p];
        var += v;
    }
    return value > 0 && std::sqrt(var) >= kPivotSpikeNoise * value;
}

// Whether `layer` has the colour's size and 1 or `channels` channels.
bool FitsColour(const Image &layer, const Image &color, int channels) {
    return layer.width == color.width && layer.height == color.height &&
           (layer.channels == 1 || layer.channels == channels);
}

}  // namespace

std::vector<size_t> ScalePivotSpikes(const Image &color, const Image &pivot,
                                     const Image &variance, Image *output) {
    if (!color.SameShape(*output) || !FitsColour(pivot, color, color.channels) ||
        !FitsColour(variance, color, color.channels))
        throw Error(
            "ScalePivotSpikes: the output must have the colour's shape, the pivot and the "
            "variance its size and 1 or its channels",
            ErrorKind::Internal);
    const int w = color.width, h = color.height;
    const std::vector<float> sums = Sums(pivot);
    std::vector<char> scaled(size_t(w) * h, 0);
    ParallelFor(h, size_t(w) * h * 40, [&](int yBegin, int yEnd) {
        for (int y = yBegin; y < yEnd; ++y)
            for (int x = 0; x < w; ++x) {
                const size_t p = size_t(y) * w + x;
                if (!LoneSpike(sums, w, h, x, y) || !FewSamples(color, variance, p)) continue;
                bool changed = false;
                for (int c = 0; c < color.channels; ++c) {
                    float *out = &output->Plane(c)[p];
                    const float *plane = pivot.Plane(pivot.channels == 1 ? 0 : c);
                    if (*out == color.Plane(c)[p] || !(plane[p] > 0)) continue;
                    const double median = NeighbourMedian(plane, w, h, x, y);
                    if (!(median > 0)) continue;
                    *out = float(double(*out) * (median / double(plane[p])));
                    changed = true;
                }
                scaled[p] = changed;
            }
    });
    std::vector<size_t> pixels;
    for (size_t p = 0; p < scaled.size(); ++p)
        if (scaled[p]) pixels.push_back(p);
    return pixels;
}

std::vector<size_t> KeepPivotSpikeClusters(const Image &color, const Image &pivot,
                                           const Image *objectId, const Image *partId,
                                           Image *output) {
    if (!color.SameShape(*output) || !FitsColour(pivot, color, color.channels) ||
        (objectId && !FitsColour(*objectId, color, 1)) ||
        (partId && !FitsColour(*partId, color, 1)))
        throw Error(
            "KeepPivotSpikeClusters: the output must have the colour's shape, the pivot its "
            "size and 1 or its channels, each id layer its size and 1 channel",
            ErrorKind::Internal);
    const int w = color.width, h = color.height;
    const std::vector<float> sums = Sums(pivot);
    std::vector<size_t> pixels;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            double median = 0;
            if (SpikeNeighbours(sums, w, h, x, y, &median) < 2 ||
                !DarkNeighboursShareIds(sums, objectId, partId, w, h, x, y, median))
                continue;
            const size_t p = size_t(y) * w + x;
            bool changed = false;
            for (int c = 0; c < color.channels; ++c) {
                const float in = color.Plane(c)[p];
                float *out = &output->Plane(c)[p];
                if (!std::isfinite(in) || *out == in) continue;
                *out = in;
                changed = true;
            }
            if (changed) pixels.push_back(p);
        }
    return pixels;
}

}  // namespace mcd
