#include "host/common/highlights.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

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

// The mean of a sum plane.
double PlaneMean(const Image &sum) {
    double total = 0;
    for (float v : sum.data) total += v;
    return total / double(sum.PixelCount());
}

// The channels of `color` summed per pixel.
Image ChannelSum(const Image &color) {
    Image sum(color.width, color.height, 1);
    for (int c = 0; c < color.channels; ++c)
        for (size_t p = 0; p < color.PixelCount(); ++p) sum.data[p] += color.Plane(c)[p];
    return sum;
}

// Pixels over k times their window's median of the channel sums (and the floor, a fraction of
// `mean`).
std::vector<char> OverTheirWindows(const Image &sum, double k, int r, double mean) {
    const int w = sum.width, h = sum.height;
    const double floor = 1e-3 * mean;
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

// A light wider than half the window is its own window's median inside: only its rim is over
// k times it. Highlights grow, kHighlightGrowRounds rings at most, into neighbours over k times
// the background they carry (the medians their seed read, channels summed) and k times the
// frame's mean (a light is; a cluster of noise in dim indirect light at low spp is not) and,
// given a variance, 2 standard deviations above the background or the sure rim of the
// neighbour (SureRimOf); a grown pixel takes the first such neighbour's background (neighbours
// in row order). Each round reads only the marks of the rounds before it. A region that would
// still grow after the last round is a light larger than a bulb (a ceiling panel, whose rim the
// filter keeps anyway): its growth is undone, its seeds kept.

// A rim pixel that one sample of a light hit has a standard deviation as large as its mean,
// so it never stands 2 above its background: a firefly's statistics. Beside a highlight most
// of whose samples saw the light (kPairSigmas of its own standard deviation above its
// background) and no dimmer than it, it is that light's rim. Whether the pixel whose channels
// sum to `s` is so beside highlight q; a glint's fireflies, brighter than the glint or beside
// a noisier one, are not.
bool SureRimOf(const Image &color, const Image &variance, double background, double s,
               size_t q) {
    double sq = 0, vq = 0;
    for (int c = 0; c < color.channels; ++c) {
        sq += color.Plane(c)[q];
        vq += variance.Plane(c)[q];
    }
    const double excess = sq - background;
    return s <= sq && excess > 0 && excess * excess > kPairSigmas * kPairSigmas * vq;
}

// The first highlight neighbour of `p` (row order) that p is over k times the background of
// (and of the frame's mean) and, given a variance, 2 standard deviations above or the sure rim
// of (SureRimOf), or SIZE_MAX.
size_t FirstPassingNeighbour(const Image &color, const Image *variance, double k, double mean,
                             const HighlightSplit &split, size_t p) {
    const int w = color.width, h = color.height;
    auto sumOf = [&](const Image &image, size_t q) {
        double s = 0;
        for (int c = 0; c < image.channels; ++c) s += image.Plane(c)[q];
        return s;
    };
    const int px = int(p % w), py = int(p / w);
    const double s = sumOf(color, p);
    const double var = variance ? sumOf(*variance, p) : 0;
    for (int v = std::max(0, py - 1); v <= std::min(h - 1, py + 1); ++v)
        for (int u = std::max(0, px - 1); u <= std::min(w - 1, px + 1); ++u) {
            size_t q = size_t(v) * w + u;
            if (!split.highlight[q]) continue;
            const double background = sumOf(split.base, q);
            const double excess = s - background;
            if (!(s > k * std::max(background, mean))) continue;
            if (variance && !(excess * excess > kHighlightSigmas * kHighlightSigmas * var) &&
                !SureRimOf(color, *variance, background, s, q))
                continue;
            return q;
        }
    return SIZE_MAX;
}

// Undoes the growth of the 8-connected highlight regions holding `seeds`: grown pixels (round
// above 0) go back to the input.
void UndoGrowth(const Image &color, const Image *variance, const std::vector<int> &grownIn,
                const std::vector<size_t> &seeds, HighlightSplit *split) {
    const int w = color.width, h = color.height;
    std::vector<char> visited(split->highlight.size(), 0);
    std::vector<size_t> stack;
    for (size_t s : seeds)
        if (!visited[s]) {
            visited[s] = 1;
            stack.push_back(s);
        }
    std::vector<size_t> region;
    while (!stack.empty()) {
        size_t q = stack.back();
        stack.pop_back();
        region.push_back(q);
        const int qx = int(q % w), qy = int(q / w);
        for (int v = std::max(0, qy - 1); v <= std::min(h - 1, qy + 1); ++v)
            for (int u = std::max(0, qx - 1); u <= std::min(w - 1, qx + 1); ++u) {
                size_t p = size_t(v) * w + u;
                if (!split->highlight[p] || visited[p]) continue;
                visited[p] = 1;
                stack.push_back(p);
            }
    }
    for (size_t p : region) {
        if (grownIn[p] == 0) continue;
        split->highlight[p] = 0;
        --split->count;
        --split->grown;
        for (int c = 0; c < color.channels; ++c) {
            split->base.Plane(c)[p] = color.Plane(c)[p];
            if (variance) split->baseVariance.Plane(c)[p] = variance->Plane(c)[p];
        }
    }
}

void GrowHighlights(const Image &color, const Image *variance, double k, double mean,
                    HighlightSplit *split) {
    const int w = color.width, h = color.height;
    std::vector<int> grownIn(split->highlight.size(), 0);
    std::vector<size_t> front;
    for (size_t p = 0; p < split->highlight.size(); ++p)
        if (split->highlight[p]) front.push_back(p);
    // The round after the last only asks which regions would still grow.
    for (int round = 1; round <= kHighlightGrowRounds + 1 && !front.empty(); ++round) {
        std::vector<size_t> candidates;
        std::vector<char> seen(split->highlight.size(), 0);
        for (size_t q : front) {
            const int qx = int(q % w), qy = int(q / w);
            for (int v = std::max(0, qy - 1); v <= std::min(h - 1, qy + 1); ++v)
                for (int u = std::max(0, qx - 1); u <= std::min(w - 1, qx + 1); ++u) {
                    size_t p = size_t(v) * w + u;
                    if (split->highlight[p] || seen[p]) continue;
                    seen[p] = 1;
                    candidates.push_back(p);
                }
        }
        std::sort(candidates.begin(), candidates.end());
        std::vector<size_t> next, source;
        for (size_t p : candidates) {
            size_t q = FirstPassingNeighbour(color, variance, k, mean, *split, p);
            if (q == SIZE_MAX) continue;
            next.push_back(p);
            source.push_back(q);
        }
        if (round > kHighlightGrowRounds) {
            UndoGrowth(color, variance, grownIn, source, split);
            break;
        }
        for (size_t i = 0; i < next.size(); ++i) {
            split->highlight[next[i]] = 1;
            grownIn[next[i]] = round;
            for (int c = 0; c < color.channels; ++c) {
                split->base.Plane(c)[next[i]] = split->base.Plane(c)[source[i]];
                if (variance)
                    split->baseVariance.Plane(c)[next[i]] =
                        split->baseVariance.Plane(c)[source[i]];
            }
        }
        split->count += next.size();
        split->grown += next.size();
        front = std::move(next);
    }
}

// The channels of `image` at pixel p summed, in channel order.
float SumAt(const Image &image, size_t p) {
    float s = 0;
    for (int c = 0; c < image.channels; ++c) s += image.Plane(c)[p];
    return s;
}

// A two-pixel reflection of a light few samples saw: its brighter pixel is a sparse light, and
// the other, which fewer samples saw, is under k times the frame's mean; the filter spread it
// into the dark pixels beside it. A sparse light in `sparse` (pixels in row order) whose one
// neighbour over its window has no other such neighbour, is not a highlight and has a largest
// sample at most kPartnerSampleRatio times the light's takes that neighbour in. The partners,
// found in the order of their lights, join `sparse`, sorted again. A sparse light or partner
// with more such neighbours is on a streak, a line or a light's rim, whose dim pixels are
// noise. (A partner brighter than its light would be over k times the mean and, not a sparse
// light itself, have a largest sample over kSparseLightSampleRatio times the highlights': the
// sample test refuses it.)
void AddReflectionPartners(const Image &color, const Image &maxSample,
                           const HighlightSplit &split, std::vector<size_t> *sparse) {
    const int w = color.width, h = color.height;
    std::vector<char> taken(color.PixelCount(), 0);
    for (size_t q : *sparse) taken[q] = 1;
    std::vector<size_t> partners;
    for (size_t q : *sparse) {
        const int qx = int(q % w), qy = int(q / w);
        if (MarkedNeighbours(split.overWindow, w, h, qx, qy) != 1) continue;
        for (int v = std::max(0, qy - 1); v <= std::min(h - 1, qy + 1); ++v)
            for (int u = std::max(0, qx - 1); u <= std::min(w - 1, qx + 1); ++u) {
                const size_t p = size_t(v) * w + u;
                if (p == q || !split.overWindow[p] || split.highlight[p] || taken[p] ||
                    MarkedNeighbours(split.overWindow, w, h, u, v) != 1)
                    continue;
                if (!(SumAt(maxSample, p) <= kPartnerSampleRatio * SumAt(maxSample, q)))
                    continue;
                taken[p] = 1;
                partners.push_back(p);
            }
    }
    sparse->insert(sparse->end(), partners.begin(), partners.end());
    std::sort(sparse->begin(), sparse->end());
}

// Each pixel of `marked` and those within `rings` steps of one (8-neighbours).
std::vector<char> GrownBy(const std::vector<char> &marked, int w, int h, int rings) {
    std::vector<char> near = marked;
    for (int ring = 0; ring < rings; ++ring) {
        std::vector<char> grown = near;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                grown[size_t(y) * w + x] |= MarkedNeighbours(near, w, h, x, y) > 0;
        near = std::move(grown);
    }
    return near;
}

// The largest channel sum of `color` over the marked pixels of (x, y)'s 3x3 window, itself
// included; 0 where none is marked.
double BrightestMarkedAround(const Image &color, const std::vector<char> &marked, int x,
                             int y) {
    const int w = color.width, h = color.height;
    double brightest = 0;
    for (int v = std::max(0, y - 1); v <= std::min(h - 1, y + 1); ++v)
        for (int u = std::max(0, x - 1); u <= std::min(w - 1, x + 1); ++u)
            if (marked[size_t(v) * w + u])
                brightest = std::max(brightest, double(SumAt(color, size_t(v) * w + u)));
    return brightest;
}

// Lowers each channel of the output at (x, y) to the input's largest value over the unmarked
// pixels of its (2r+1)^2 window (its own input included); a non-finite maximum lowers nothing
// where `finiteOnly`. Returns the values lowered.
size_t LowerToWindowMaximum(const Image &color, const std::vector<char> &marked, int x, int y,
                            int r, bool finiteOnly, Image *output) {
    const int w = color.width, h = color.height;
    const size_t p = size_t(y) * w + x;
    size_t moved = 0;
    for (int c = 0; c < color.channels; ++c) {
        float high = color.Plane(c)[p];
        for (int v = std::max(0, y - r); v <= std::min(h - 1, y + r); ++v)
            for (int u = std::max(0, x - r); u <= std::min(w - 1, x + r); ++u)
                if (!marked[size_t(v) * w + u])
                    high = std::max(high, color.Plane(c)[size_t(v) * w + u]);
        float &out = output->Plane(c)[p];
        if ((!finiteOnly || std::isfinite(high)) && std::isfinite(out) && out > high) {
            out = high;
            ++moved;
        }
    }
    return moved;
}

// Holds each channel of the output at (x, y) between the lower of its input and the input's
// mean over the unmarked pixels of its (2r+1)^2 window ((x, y) unmarked itself, so at least
// one) minus kRimCutSigmas of that mean's standard deviations, and the higher of its input and
// that mean plus as many. Returns the values moved.
size_t HoldToWindowMeanBounds(const Image &color, const Image &variance,
                              const std::vector<char> &marked, int x, int y, int r,
                              Image *output) {
    const int w = color.width, h = color.height;
    const size_t p = size_t(y) * w + x;
    size_t moved = 0;
    for (int c = 0; c < color.channels; ++c) {
        double total = 0, spread = 0;
        int count = 0;
        for (int v = std::max(0, y - r); v <= std::min(h - 1, y + r); ++v)
            for (int u = std::max(0, x - r); u <= std::min(w - 1, x + r); ++u)
                if (!marked[size_t(v) * w + u]) {
                    total += color.Plane(c)[size_t(v) * w + u];
                    spread += variance.Plane(c)[size_t(v) * w + u];
                    ++count;
                }
        // The mean's variance is the sum of the pixels' over count^2.
        const double mean = total / count, margin = kRimCutSigmas * std::sqrt(spread) / count;
        const float own = color.Plane(c)[p];
        const float high = std::max(own, float(mean + margin));
        const float low = std::min(own, float(mean - margin));
        float &out = output->Plane(c)[p];
        if (!std::isfinite(out)) continue;
        if (out > high || out < low) {
            out = out > high ? high : low;
            ++moved;
        }
    }
    return moved;
}

}  // namespace

int MarkedNeighbours(const std::vector<char> &marked, int w, int h, int x, int y) {
    int count = 0;
    for (int v = std::max(0, y - 1); v <= std::min(h - 1, y + 1); ++v)
        for (int u = std::max(0, x - 1); u <= std::min(w - 1, x + 1); ++u)
            count += (u != x || v != y) && marked[size_t(v) * w + u];
    return count;
}

double HighlightFrameMean(const Image &color) {
    return PlaneMean(ChannelSum(color));
}

HighlightSplit SplitHighlights(const Image &color, const Image *variance, double k, int r,
                               double frameMean) {
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
    Image sum = ChannelSum(color);
    const double mean = frameMean >= 0 ? frameMean : PlaneMean(sum);
    std::vector<char> over = OverTheirWindows(sum, k, r, mean);
    split.overWindow = over;
    split.mean = mean;
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
    GrowHighlights(color, variance, k, mean, &split);
    return split;
}

size_t LowerToInputMaximumNearHighlights(const Image &color, const std::vector<char> &highlight,
                                         int reach, int r, Image *output) {
    if (!color.SameShape(*output) || highlight.size() != color.PixelCount() || reach < 0 ||
        r < 0)
        throw Error(
            "LowerToInputMaximumNearHighlights: the output and mask must have the "
            "color's shape, reach and r >= 0",
            ErrorKind::Internal);
    const int w = color.width, h = color.height;
    // Within reach of the nearest highlight.
    const std::vector<char> near = GrownBy(highlight, w, h, reach);
    size_t moved = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const size_t p = size_t(y) * w + x;
            if (!near[p] || highlight[p]) continue;
            moved += LowerToWindowMaximum(color, highlight, x, y, r, true, output);
        }
    return moved;
}

LightRims FindLightRims(const Image &color, const Image &variance, const Image *maxSample,
                        double k, double frameMean) {
    LightRims found;
    const size_t n = color.PixelCount();
    if (!variance.SameShape(color) || (maxSample && !maxSample->SameShape(color))) return found;
    for (size_t i = 0; i < color.data.size(); ++i)
        if (!std::isfinite(color.data[i]) ||
            !(std::isfinite(variance.data[i]) && variance.data[i] >= 0))
            return found;
    if (maxSample)
        for (float v : maxSample->data)
            if (!std::isfinite(v)) return found;
    const int w = color.width, h = color.height;
    found.light.assign(n, 0);
    found.rim.assign(n, 0);
    found.full.assign(n, 0);
    for (size_t p = 0; p < n; ++p) {
        const double s = SumAt(color, p), v = SumAt(variance, p);
        found.light[p] =
            s > k * frameMean && s > 0 && s * s >= kLightRimSigmas * kLightRimSigmas * v;
        found.lights += found.light[p];
    }
    // A full light: sure to be no dimmer than kFullLightShare x the brightest light beside it
    // (a light pixel the edge crosses is dimmer than the interior beside it, its noise aside).
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const size_t p = size_t(y) * w + x;
            if (!found.light[p]) continue;
            const double brightest = BrightestMarkedAround(color, found.light, x, y);
            const double low =
                SumAt(color, p) - kFullLightSigmas * std::sqrt(double(SumAt(variance, p)));
            found.full[p] = low >= kFullLightShare * brightest;
        }
    if (!maxSample || !found.lights) return found;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const size_t p = size_t(y) * w + x;
            if (found.light[p]) continue;
            const double brightest = BrightestMarkedAround(color, found.light, x, y);
            found.rim[p] =
                brightest > 0 && SumAt(*maxSample, p) >= kLightRimSampleShare * brightest;
            found.rims += found.rim[p];
        }
    return found;
}

size_t ClampBeyondLightRims(const Image &color, const Image &variance, const LightRims &rims,
                            int reach, int r, Image *output) {
    if (!color.SameShape(*output) || !color.SameShape(variance) || reach < 0 || r < 0)
        throw Error(
            "ClampBeyondLightRims: the output and variance must have the color's shape, reach "
            "and r >= 0",
            ErrorKind::Internal);
    const size_t n = color.PixelCount();
    if (rims.light.size() != n || rims.rim.size() != n || rims.full.size() != n) return 0;
    const int w = color.width, h = color.height;
    std::vector<char> marked(n);
    for (size_t p = 0; p < n; ++p) marked[p] = rims.light[p] || rims.rim[p];
    const std::vector<char> &full = rims.full;
    const std::vector<char> near = GrownBy(marked, w, h, reach);
    // Past a sharp light's edge: nothing of its light, so the spread is held both ways.
    const std::vector<char> nearFull = GrownBy(full, w, h, kFullLightReach);
    size_t moved = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const size_t p = size_t(y) * w + x;
            // A full light's neighbour is its rim, lit or not: the spread may be its light.
            if (marked[p] || MarkedNeighbours(full, w, h, x, y) > 0) continue;
            if (nearFull[p])
                moved += HoldToWindowMeanBounds(color, variance, marked, x, y, kRimMeanRadius,
                                                output);
            else if (near[p])
                moved += LowerToWindowMaximum(color, marked, x, y, r, false, output);
        }
    return moved;
}

double HighlightSampleMedian(const Image &maxSample, const std::vector<char> &highlight) {
    if (highlight.size() != maxSample.PixelCount())
        throw Error("HighlightSampleMedian: the mask must have the max layer's size",
                    ErrorKind::Internal);
    for (float v : maxSample.data)
        if (!std::isfinite(v)) return 0;
    std::vector<double> sums;
    for (size_t p = 0; p < highlight.size(); ++p) {
        if (!highlight[p]) continue;
        double s = 0;
        for (int c = 0; c < maxSample.channels; ++c) s += maxSample.Plane(c)[p];
        sums.push_back(s);
    }
    if (sums.empty()) return 0;
    auto mid = sums.begin() + sums.size() / 2;
    std::nth_element(sums.begin(), mid, sums.end());
    return std::max(*mid, 0.0);
}

size_t AddSparseLights(const Image &color, const Image *variance, const Image &maxSample,
                       double k, int r, double lightSample, HighlightSplit *split) {
    if (!maxSample.SameShape(color) || split->highlight.size() != color.PixelCount() ||
        (!split->overWindow.empty() && split->overWindow.size() != color.PixelCount()) ||
        (variance && !variance->SameShape(color)))
        throw Error("AddSparseLights: the layers must have the color's shape",
                    ErrorKind::Internal);
    if (lightSample < 0) lightSample = HighlightSampleMedian(maxSample, split->highlight);
    // A frame with NaN/Inf has no window test, nor sparse lights.
    if (!(lightSample > 0) || split->overWindow.empty()) return 0;
    const int w = color.width, h = color.height;
    const double mean = split->mean;
    std::vector<float> scratch;
    std::vector<size_t> sparse;
    size_t added = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const size_t p = size_t(y) * w + x;
            if (!split->overWindow[p] || split->highlight[p]) continue;
            // The channel sum as SplitHighlights made it (ChannelSum's order).
            float s = 0;
            for (int c = 0; c < color.channels; ++c) s += color.Plane(c)[p];
            double sample = 0;
            for (int c = 0; c < color.channels; ++c) sample += maxSample.Plane(c)[p];
            if (!(sample <= kSparseLightSampleRatio * lightSample)) continue;
            // Under k times the mean only a glint's streak, dimmer than the frame's lights.
            const bool streak =
                s > kStreakMeanShare * k * mean &&
                MarkedNeighbours(split->overWindow, w, h, x, y) >= kStreakNeighbours &&
                sample <= kStreakSampleRatio * lightSample;
            if (!(s > k * mean) && !streak) continue;
            sparse.push_back(p);
        }
    AddReflectionPartners(color, maxSample, *split, &sparse);
    for (size_t p : sparse) {
        const int x = int(p % w), y = int(p / w);
        split->highlight[p] = 1;
        ++added;
        for (int c = 0; c < color.channels; ++c) {
            split->base.Plane(c)[p] = WindowMedian(color.Plane(c), w, h, x, y, r, scratch);
            if (variance)
                split->baseVariance.Plane(c)[p] =
                    WindowMedian(variance->Plane(c), w, h, x, y, r, scratch);
        }
    }
    split->count += added;
    split->sparse += added;
    return added;
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
