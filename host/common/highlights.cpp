#include "host/common/highlights.h"

#include <algorithm>
#include <cmath>

#include "host/common/parallel.h"
#include "host/error.h"

namespace mcd {
namespace {

// The median (the upper one of an even count) of `plane` over the window of radius r
// around (x, y), clipped to the image; `scratch` holds the window.
float WindowMedian(const float *plane, int w, int h, int x, int y, int r,
                   std::vector<float> &scratch) {
    scratch.clear();
    for (int v = std::max(0, y - r); v <= std::min(h - 1, y + r); ++v)
        for (int u = std::max(0, x - r); u <= std::min(w - 1, x + r); ++u)
            scratch.push_back(plane[size_t(v) * w + u]);
    auto mid = scratch.begin() + scratch.size() / 2;
    std::nth_element(scratch.begin(), mid, scratch.end());
    return *mid;
}

// Pixels over k times their window's median of the channel sums (and the floor).
std::vector<char> OverTheirWindows(const Image &sum, double k, int r) {
    const int w = sum.width, h = sum.height;
    double total = 0;
    for (float v : sum.data) total += v;
    const double floor = 1e-3 * total / double(sum.PixelCount());
    std::vector<char> over(sum.PixelCount(), 0);
    const size_t window = size_t(2 * r + 1) * (2 * r + 1);
    ParallelFor(h, sum.PixelCount() * window, [&](int yBegin, int yEnd) {
        std::vector<float> scratch;
        for (int y = yBegin; y < yEnd; ++y)
            for (int x = 0; x < w; ++x) {
                double s = sum.data[size_t(y) * w + x];
                // Cheap test first: the median is at least the floor.
                if (!(s > k * floor)) continue;
                double median = WindowMedian(sum.data.data(), w, h, x, y, r, scratch);
                over[size_t(y) * w + x] = s > k * std::max(median, floor);
            }
    });
    return over;
}

// With a variance, a highlight must stand kHighlightSigmas of its own standard deviation above
// its window's median (channels summed): a light's rim seen by many samples does, a firefly
// (one sample: a deviation about its mean) does not. One that stands kPairSigmas above needs
// one bright neighbour, not two: most of its samples saw the light (a two-pixel reflection
// of a small light in a mirror sphere).
constexpr double kHighlightSigmas = 2;
constexpr double kPairSigmas = 4;

// Marks that pass (1), and those that pass kPairSigmas (2).
void RequireConfidence(const Image &color, const Image &variance, int r,
                       std::vector<char> *over) {
    const int w = color.width, h = color.height;
    const size_t window = size_t(2 * r + 1) * (2 * r + 1);
    // Few pixels get this far: a row's cost is its marked pixels' windows.
    size_t marked = size_t(std::count(over->begin(), over->end(), char(1)));
    ParallelFor(h, marked * window * size_t(color.channels), [&](int yBegin, int yEnd) {
        std::vector<float> scratch;
        for (int y = yBegin; y < yEnd; ++y)
            for (int x = 0; x < w; ++x) {
                size_t p = size_t(y) * w + x;
                if (!(*over)[p]) continue;
                double excess = 0, v = 0;
                for (int c = 0; c < color.channels; ++c) {
                    excess += color.Plane(c)[p] -
                              WindowMedian(color.Plane(c), w, h, x, y, r, scratch);
                    v += variance.Plane(c)[p];
                }
                (*over)[p] = excess <= 0 ? 0
                             : excess * excess > kPairSigmas * kPairSigmas * v
                                 ? 2
                                 : excess * excess > kHighlightSigmas * kHighlightSigmas * v;
            }
    });
}

}  // namespace

int MarkedNeighbours(const std::vector<char> &marked, int w, int h, int x, int y) {
    int count = 0;
    for (int v = std::max(0, y - 1); v <= std::min(h - 1, y + 1); ++v)
        for (int u = std::max(0, x - 1); u <= std::min(w - 1, x + 1); ++u)
            count += (u != x || v != y) && marked[size_t(v) * w + u];
    return count;
}

HighlightSplit SplitHighlights(const Image &color, const Image *variance, double k, int r) {
    if (variance && !variance->SameShape(color))
        throw Error("SplitHighlights: the variance must have the color's shape",
                    ErrorKind::Internal);
    HighlightSplit split;
    split.base = color;
    if (variance) split.baseVariance = *variance;
    const int w = color.width, h = color.height;
    split.highlight.assign(color.PixelCount(), 0);
    for (float v : color.data)
        if (!std::isfinite(v)) return split;
    Image sum(w, h, 1);
    for (int c = 0; c < color.channels; ++c)
        for (size_t p = 0; p < color.PixelCount(); ++p) sum.data[p] += color.Plane(c)[p];
    std::vector<char> over = OverTheirWindows(sum, k, r);
    if (variance) RequireConfidence(color, *variance, r, &over);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            size_t p = size_t(y) * w + x;
            // Two marked neighbours, or one for a pixel kPairSigmas above.
            split.highlight[p] = over[p] && MarkedNeighbours(over, w, h, x, y) >= 3 - over[p];
        }
    std::vector<float> scratch;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            size_t p = size_t(y) * w + x;
            if (!split.highlight[p]) continue;
            ++split.count;
            for (int c = 0; c < color.channels; ++c) {
                split.base.Plane(c)[p] = WindowMedian(color.Plane(c), w, h, x, y, r, scratch);
                if (variance)
                    split.baseVariance.Plane(c)[p] =
                        WindowMedian(variance->Plane(c), w, h, x, y, r, scratch);
            }
        }
    return split;
}

void AddHighlights(const Image &color, const HighlightSplit &split, Image *output) {
    if (!color.SameShape(*output) || !color.SameShape(split.base))
        throw Error("AddHighlights: the images must have the color's shape",
                    ErrorKind::Internal);
    for (int c = 0; c < color.channels; ++c)
        for (size_t p = 0; p < color.PixelCount(); ++p)
            if (split.highlight[p])
                output->Plane(c)[p] += color.Plane(c)[p] - split.base.Plane(c)[p];
}

}  // namespace mcd
