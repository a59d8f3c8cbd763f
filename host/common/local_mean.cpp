#include "host/common/local_mean.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <mutex>
#include <vector>

#include <fmt/format.h>

#include "host/common/box_mean.h"
#include "host/common/highlights.h"
#include "host/common/parallel.h"
#include "host/common/squared_tent.h"
#include "host/error.h"

namespace mcd {
namespace {

// The images a restore's steps make anew at every scale and ring, kept for the next one:
// each step overwrites every value, and fresh pages cost more than the values' work.
struct RestoreScratch {
    Image moved, squared, means, squaredMeans;
    std::vector<float> plane;  // one plane of the tent means' passes
};

// `image` shaped as `like` (its values left as they are where it already is).
void ShapeAs(const Image &like, Image *image) {
    if (!image->SameShape(like)) *image = Image(like.width, like.height, like.channels);
}

// TentMean and TentSquaredMean into `out` through `plane` (local_mean.h).
void TentMeanInto(const Image &image, int r, std::vector<float> *plane, Image *out) {
    const int w = image.width, h = image.height;
    ShapeAs(image, out);
    plane->resize(size_t(w) * h);
    float *a = plane->data();
    for (int c = 0; c < image.channels; ++c) {
        // Each window's sum is the one of its values in order: a pixel's mean does not
        // depend on where the image starts (a tile gives the whole frame's values).
        BoxMeanRows(image.Plane(c), a, w, h, r);
        BoxMeanColumns(a, out->Plane(c), w, h, r);
        BoxMeanRows(out->Plane(c), a, w, h, r);
        BoxMeanColumns(a, out->Plane(c), w, h, r);
    }
}

void TentSquaredMeanInto(const Image &image, int r, std::vector<float> *plane, Image *out) {
    const int w = image.width, h = image.height;
    ShapeAs(image, out);
    plane->resize(size_t(w) * h);
    for (int c = 0; c < image.channels; ++c) {
        // Each value a function of its window alone (squared_tent.h): a tile gives the
        // whole frame's values.
        SquaredTentMeanRows(image.Plane(c), plane->data(), w, h, r);
        SquaredTentMeanColumns(plane->data(), out->Plane(c), w, h, r);
    }
}

// One scale of the restore (local_mean.h): `output` scaled by the shrunk ratio of the
// means over tents of radius 2s, the noise weighted by `noiseWeight`; `factors` (one per
// value) multiplied by the same. `inMeans`: the clean input's tent means at s, made here
// when empty (the coarse scale's serve its second pass).
void RestoreScale(const Image &clean, const std::vector<bool> &kept, int s, double noiseWeight,
                  bool pixelNoise, Image *output, std::vector<double> *factors, Image *inMeans,
                  RestoreScratch *scratch) {
    Image &moved = scratch->moved, &squared = scratch->squared;
    ShapeAs(*output, &moved);
    ShapeAs(*output, &squared);
    // The output without the kept values, copied in the same split loop as the squares.
    ParallelValues(moved.data.size(), 4, [&](size_t begin, size_t end) {
        for (size_t i = begin; i < end; ++i) {
            moved.data[i] = kept[i] ? 0.f : output->data[i];
            float e = clean.data[i] - moved.data[i];
            squared.data[i] = kept[i] ? 0.f : e * e;
        }
    });
    if (inMeans->Empty()) TentMeanInto(clean, s, &scratch->plane, inMeans);
    const Image &mIn = *inMeans, &mOut = scratch->means, &mSq = scratch->squaredMeans;
    TentMeanInto(moved, s, &scratch->plane, &scratch->means);
    if (pixelNoise)
        TentSquaredMeanInto(squared, s, &scratch->plane, &scratch->squaredMeans);
    else
        TentMeanInto(squared, s, &scratch->plane, &scratch->squaredMeans);
    const double weights = TentSquaredWeights(s) * noiseWeight;
    ParallelValues(mIn.data.size(), 16, [&](size_t begin, size_t end) {
        for (size_t i = begin; i < end; ++i) {
            if (kept[i]) continue;
            double a = mIn.data[i], b = mOut.data[i], q = mSq.data[i] * weights;
            if (!(a > 0 && b > 0 && std::isfinite(a) && std::isfinite(b) && std::isfinite(q)))
                continue;
            double d = a - b, d2 = d * d;
            double shrink = d2 > q ? 1 - q / d2 : 0;
            double factor = 1 + shrink * d / b;
            output->data[i] = float(output->data[i] * factor);
            (*factors)[i] *= factor;
        }
    });
}

// Highlights (local_mean.h): pixels whose input (the sum of its channels) is over
// kHighlight times the output there or the output's tent mean of radius 2r there, with at
// least kHighlightNeighbours of their 8 neighbours so too (a firefly stands alone). They
// take the input back and count as kept.
constexpr double kHighlight = 16;
constexpr int kHighlightNeighbours = 2;

// A variance of the pixel mean (`variance`, may be null) tells a light from a firefly
// instead of the neighbours: the input must then also be over kHighlightSigmas^2 times the
// pixel's variance away from the output.
constexpr double kHighlightSigmas = 4;

// Pixels every sample of which was the same, and not black: the variance of the pixel mean
// 0 in every channel, the input's channels summed above 0. Their paths are deterministic (a
// mirror's reflection of a lit wall); samples that all missed a light say less.
std::vector<char> ExactLitPixels(const Image &input, const Image &variance) {
    const size_t n = input.PixelCount();
    std::vector<char> exact(n, 0);
    ParallelValues(n, 4 * size_t(input.channels), [&](size_t begin, size_t end) {
        for (size_t p = begin; p < end; ++p) {
            double in = 0;
            bool zero = true;
            for (int c = 0; c < input.channels; ++c) {
                in += input.Plane(c)[p];
                zero = zero && variance.Plane(variance.channels == 1 ? 0 : c)[p] == 0;
            }
            exact[p] = zero && std::isfinite(in) && in > 0;
        }
    });
    return exact;
}

// Whether every neighbour of (x, y) inside the frame, kAmongExactLeast or more, is exact and
// lit: the pixel's own spread then comes from its footprint's coverage of something bright
// (a small light seen in a mirror), not from a rare path, and its light belongs where it is.
constexpr int kAmongExactLeast = 3;

bool AmongExactLit(const std::vector<char> &exact, int w, int h, int x, int y) {
    int count = 0;
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
            const int u = x + dx, v = y + dy;
            if (!(dx || dy) || u < 0 || u >= w || v < 0 || v >= h) continue;
            if (!exact[size_t(v) * w + u]) return false;
            ++count;
        }
    return count >= kAmongExactLeast;
}

// Which pixels are over (KeepHighlights): the input far above the output, or above the
// output's tent mean without the kept values, and with a variance so many deviations away
// or every neighbour exact and lit (`exact`, ExactLitPixels; empty without a variance).
std::vector<char> OverPixels(const Image &input, const Image *variance,
                             const std::vector<char> &exact, int r,
                             const std::vector<bool> &kept, const Image &output,
                             RestoreScratch *scratch) {
    const size_t n = input.PixelCount();
    Image &moved = scratch->moved, &level = scratch->means;
    ShapeAs(output, &moved);
    ParallelValues(moved.data.size(), 2, [&](size_t begin, size_t end) {
        for (size_t i = begin; i < end; ++i) moved.data[i] = kept[i] ? 0.f : output.data[i];
    });
    TentMeanInto(moved, r, &scratch->plane, &level);
    std::vector<char> over(n, 0);
    ParallelValues(n, 8 * size_t(input.channels), [&](size_t begin, size_t end) {
        for (size_t p = begin; p < end; ++p) {
            double in = 0, around = 0, out = 0;
            bool finite = true;
            for (int c = 0; c < input.channels; ++c) {
                float v = input.Plane(c)[p];
                finite = finite && std::isfinite(v);
                in += v;
                around += level.Plane(c)[p];
                out += moved.Plane(c)[p];
            }
            over[p] = finite && in > 0 && in > kHighlight * std::min(around, out);
            if (over[p] && variance) {
                double v = 0;
                for (int c = 0; c < input.channels; ++c)
                    v += variance->Plane(variance->channels == 1 ? 0 : c)[p];
                const int x = int(p % input.width), y = int(p / input.width);
                over[p] = std::isfinite(v) &&
                          ((in - out) * (in - out) > kHighlightSigmas * kHighlightSigmas * v ||
                           AmongExactLit(exact, input.width, input.height, x, y));
            }
        }
    });
    return over;
}

// Whether any of (x, y)'s 8 neighbours inside the frame is a kept highlight.
bool BesideHighlight(const std::vector<char> &taken, int w, int h, int x, int y) {
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
            const int u = x + dx, v = y + dy;
            if ((dx || dy) && u >= 0 && u < w && v >= 0 && v < h && taken[size_t(v) * w + u])
                return true;
        }
    return false;
}

// A light's rim is dimmer than its core, and the core's own output lifts the tent mean it is
// read against: the rim passes the test only once the core is kept. Rings grow, each read
// against the tent mean without the highlights kept so far, while pixels beside them pass.
constexpr int kHighlightRings = 4;

void KeepHighlights(const Image &input, const Image *variance, int r, std::vector<bool> *kept,
                    Image *output, RestoreScratch *scratch) {
    const int w = input.width, h = input.height;
    const size_t n = input.PixelCount();
    std::vector<char> taken(n, 0), exact;
    if (variance) exact = ExactLitPixels(input, *variance);
    for (int ring = 0; ring <= kHighlightRings; ++ring) {
        const std::vector<char> over =
            OverPixels(input, variance, exact, r, *kept, *output, scratch);
        std::vector<size_t> take;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                size_t p = size_t(y) * w + x;
                if (!over[p] || taken[p]) continue;
                if (!variance && MarkedNeighbours(over, w, h, x, y) < kHighlightNeighbours)
                    continue;
                if (ring > 0 && !BesideHighlight(taken, w, h, x, y)) continue;
                take.push_back(p);
            }
        if (take.empty()) break;
        for (size_t p : take) {
            taken[p] = 1;
            for (int c = 0; c < input.channels; ++c) {
                size_t i = c * n + p;
                // A value already kept stays as the method left it.
                if (!(*kept)[i]) output->data[i] = input.data[i];
                (*kept)[i] = true;
            }
        }
    }
}

// The smallest and largest factor of the values not kept (1 and 1 where all are). The
// factors are products of finite positive ones (RestoreScale), never NaN: their least and
// greatest do not depend on the order the parts are merged in.
LocalMeanFactors FactorRange(const std::vector<double> &factors,
                             const std::vector<bool> &kept) {
    LocalMeanFactors range;
    bool any = false;
    std::mutex lock;
    ParallelValues(factors.size(), 2, [&](size_t begin, size_t end) {
        LocalMeanFactors part;
        bool partAny = false;
        for (size_t i = begin; i < end; ++i) {
            if (kept[i]) continue;
            part.lo = partAny ? std::min(part.lo, factors[i]) : factors[i];
            part.hi = partAny ? std::max(part.hi, factors[i]) : factors[i];
            partAny = true;
        }
        if (!partAny) return;
        std::lock_guard<std::mutex> guard(lock);
        range.lo = any ? std::min(range.lo, part.lo) : part.lo;
        range.hi = any ? std::max(range.hi, part.hi) : part.hi;
        any = true;
    });
    return range;
}

}  // namespace

Image TentMean(const Image &image, int r) {
    Image out;
    std::vector<float> plane;
    TentMeanInto(image, r, &plane, &out);
    return out;
}

Image TentSquaredMean(const Image &image, int r) {
    Image out;
    std::vector<float> plane;
    TentSquaredMeanInto(image, r, &plane, &out);
    return out;
}

double TentSquaredWeights(int r) {
    // The 1D tent is the box of 2r + 1 taps convolved with itself: (2r + 1 - |j|) / n^2.
    double n = 2.0 * r + 1, sum = 0;
    for (int j = -2 * r; j <= 2 * r; ++j) {
        double t = (n - std::abs(j)) / (n * n);
        sum += t * t;
    }
    return sum * sum;
}

LocalMeanFactors RestoreLocalMeans(const Image &input, int r, Image *output,
                                   const Image *variance, double rebalance, bool pixelNoise,
                                   std::vector<bool> *left) {
    if (!input.SameShape(*output) || r <= 0 || std::isnan(rebalance) ||
        (left && left->size() != input.data.size()))
        throw Error(
            "RestoreLocalMeans: the output must have the input's shape, r > 0, the "
            "rebalance's weight a number, a kept mask one flag per value",
            ErrorKind::Internal);
    // The values the method left as they were (an emitter without a pivot, an exact zero
    // restored) are left out of the means and kept: mass balances without them. A method
    // that says which it left is taken at its word.
    // ParallelValues's blocks are whole words of the vector<bool>: no two parts share one.
    std::vector<bool> kept(input.data.size());
    ParallelValues(kept.size(), 2, [&](size_t begin, size_t end) {
        for (size_t i = begin; i < end; ++i)
            kept[i] = left ? bool((*left)[i]) : output->data[i] == input.data[i];
    });
    if (variance && (variance->width != input.width || variance->height != input.height ||
                     (variance->channels != 1 && variance->channels != input.channels)))
        variance = nullptr;
    RestoreScratch scratch;
    KeepHighlights(input, variance, r, &kept, output, &scratch);
    Image clean(input.width, input.height, input.channels);
    ParallelValues(clean.data.size(), 2, [&](size_t begin, size_t end) {
        for (size_t i = begin; i < end; ++i) {
            float v = input.data[i];
            clean.data[i] = !kept[i] && std::isfinite(v) && v > 0 ? v : 0.f;
        }
    });
    std::vector<double> factors(input.data.size(), 1.0);
    Image coarseIn, fineIn;
    RestoreScale(clean, kept, 4 * r, 1, pixelNoise, output, &factors, &coarseIn, &scratch);
    RestoreScale(clean, kept, r, 1, pixelNoise, output, &factors, &fineIn, &scratch);
    // The fine scale takes the coarse gain back confidently where no rare bright sample
    // fell and gives it uncertainly where one did: the coarse scale again returns the
    // energy so lost.
    if (rebalance >= 0)
        RestoreScale(clean, kept, 4 * r, rebalance, pixelNoise, output, &factors, &coarseIn,
                     &scratch);
    LocalMeanFactors range = FactorRange(factors, kept);
    if (left) *left = std::move(kept);
    return range;
}

namespace {

// The weights of the clipped tent of radius 2s along an axis of n values: at each x, (2s + 1
// - |u - x|) for u in the axis within 2s, over their sum; with `squared`, their squares.
std::vector<double> ClippedTent(int n, int s, bool squared) {
    const int reach = 2 * s, span = 2 * reach + 1;
    std::vector<double> weights(size_t(n) * span, 0.0);
    for (int x = 0; x < n; ++x) {
        double sum = 0;
        for (int u = std::max(0, x - reach); u <= std::min(n - 1, x + reach); ++u)
            sum += reach + 1 - std::abs(u - x);
        for (int u = std::max(0, x - reach); u <= std::min(n - 1, x + reach); ++u) {
            double w = (reach + 1 - std::abs(u - x)) / sum;
            weights[size_t(x) * span + (u - x + reach)] = squared ? w * w : w;
        }
    }
    return weights;
}

// One row filtered by the row weights `wx` (ClippedTent's, 2 reach + 1 a value). Each output is
// its window's products summed in order, u rising; the values whose window lies inside the
// row share one set of weights (their clipped sums are the same), so they are summed side
// by side, each in that same order.
void FilterRow(const float *in, float *out, int w, int reach, const std::vector<double> &wx,
               std::vector<double> *acc) {
    const int span = 2 * reach + 1;
    auto edge = [&](int x) {
        double sum = 0;
        for (int u = std::max(0, x - reach); u <= std::min(w - 1, x + reach); ++u)
            sum += wx[size_t(x) * span + (u - x + reach)] * in[u];
        out[x] = float(sum);
    };
    const int lo = std::min(reach, w), hi = std::max(lo, w - reach);
    for (int x = 0; x < lo; ++x) edge(x);
    if (hi > lo) {
        const double *inner = wx.data() + size_t(lo) * span;
        const int n = hi - lo;
        double *sums = acc->data();
        std::fill(sums, sums + n, 0.0);
        for (int d = 0; d < span; ++d) {
            const double weight = inner[d];
            const float *from = in + (lo - reach + d);  // u = x - reach + d
            for (int i = 0; i < n; ++i) sums[i] += weight * from[i];
        }
        for (int i = 0; i < n; ++i) out[lo + i] = float(sums[i]);
    }
    for (int x = hi; x < w; ++x) edge(x);
}

}  // namespace

// Every output is its window's products summed in order (u, then v, rising); the rows and
// the columns' outputs are split among the cores, the columns' summed a row at a time.
Image ClippedTentFilter(const Image &image, int s, bool squared) {
    const int w = image.width, h = image.height, reach = 2 * s, span = 2 * reach + 1;
    const std::vector<double> wx = ClippedTent(w, s, squared), wy = ClippedTent(h, s, squared);
    Image rows(w, h, image.channels), out(w, h, image.channels);
    const int lines = image.channels * h;
    const size_t cost = size_t(lines) * w * span;
    ParallelFor(lines, cost, [&](int begin, int end) {
        std::vector<double> acc(static_cast<size_t>(w));
        for (int line = begin; line < end; ++line)
            FilterRow(image.data.data() + size_t(line) * w, rows.data.data() + size_t(line) * w,
                      w, reach, wx, &acc);
    });
    ParallelFor(lines, cost, [&](int begin, int end) {
        std::vector<double> acc(static_cast<size_t>(w));
        for (int line = begin; line < end; ++line) {
            const int c = line / h, y = line % h;
            std::fill(acc.begin(), acc.end(), 0.0);
            for (int v = std::max(0, y - reach); v <= std::min(h - 1, y + reach); ++v) {
                const double weight = wy[size_t(y) * span + (v - y + reach)];
                const float *from = rows.Plane(c) + size_t(v) * w;
                for (int x = 0; x < w; ++x) acc[x] += weight * from[x];
            }
            float *to = out.Plane(c) + size_t(y) * w;
            for (int x = 0; x < w; ++x) to[x] = float(acc[x]);
        }
    });
    return out;
}

LocalMeanFactors RestoreLocalMeanAt(const Image &input, int s, double noiseWeight,
                                    Image *output, const std::vector<bool> *left) {
    if (!input.SameShape(*output) || s <= 0 || !(noiseWeight >= 0) ||
        (left && left->size() != input.data.size()))
        throw Error(
            "RestoreLocalMeanAt: the output must have the input's shape, s > 0, the noise's "
            "weight >= 0, a kept mask one flag per value",
            ErrorKind::Internal);
    // Kept values count in no mean: 0 in both and in the squares.
    Image clean(input.width, input.height, input.channels),
        moved = *output, squared(input.width, input.height, input.channels);
    std::vector<bool> kept(input.data.size());
    for (size_t i = 0; i < kept.size(); ++i) {
        kept[i] = left ? bool((*left)[i]) : output->data[i] == input.data[i];
        float v = input.data[i];
        clean.data[i] = !kept[i] && std::isfinite(v) && v > 0 ? v : 0.f;
        if (kept[i]) moved.data[i] = 0;
        float e = clean.data[i] - moved.data[i];
        squared.data[i] = e * e;
    }
    const Image mIn = ClippedTentFilter(clean, s, false),
                mOut = ClippedTentFilter(moved, s, false),
                q = ClippedTentFilter(squared, s, true);
    // Each value's shrunk gain (its first planes) and whether it has one (the last): a bright
    // value puts its light and its noise in every window that holds it, so the gain would step
    // at the edge of the tent's square support around it. Its mean over the same tent, among
    // the values that have one, ramps over the tent's width instead.
    const int channels = input.channels;
    Image gate(input.width, input.height, 2 * channels);
    const size_t n = input.data.size();
    for (size_t i = 0; i < n; ++i) {
        double a = mIn.data[i], b = mOut.data[i], noise = q.data[i] * noiseWeight;
        if (kept[i] ||
            !(a > 0 && b > 0 && std::isfinite(a) && std::isfinite(b) && std::isfinite(noise)))
            continue;
        double d = a - b, d2 = d * d;
        gate.data[i] = float((d2 > noise ? 1 - noise / d2 : 0) * d / b);
        gate.data[n + i] = 1;
    }
    const Image smooth = ClippedTentFilter(gate, s, false);
    LocalMeanFactors range;
    for (size_t i = 0; i < n; ++i) {
        if (gate.data[n + i] == 0) continue;
        double factor = 1 + double(smooth.data[i]) / smooth.data[n + i];
        output->data[i] = float(output->data[i] * factor);
        range.lo = std::min(range.lo, factor);
        range.hi = std::max(range.hi, factor);
    }
    return range;
}

namespace {

// The normalised smallest squared second difference of z at each pixel of channel c
// (FrameNoise), NaN where there is none.
std::vector<float> SecondDifferences(const Image &color, const Image *albedo, int c) {
    const int w = color.width, h = color.height;
    const float *y = color.Plane(c);
    const float *a = albedo ? albedo->Plane(albedo->channels == 1 ? 0 : c) : nullptr;
    std::vector<float> z(color.PixelCount()), e(color.PixelCount());
    for (size_t p = 0; p < z.size(); ++p) z[p] = a && a[p] > 0.02f ? y[p] / a[p] : y[p];
    const int directions[4][2] = {{0, 1}, {1, 0}, {1, 1}, {1, -1}};
    for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i) {
            double best = INFINITY;
            int count = 0;
            bool finite = true;
            for (const auto &d : directions) {
                const int ya = j - d[0], yb = j + d[0], xa = i - d[1], xb = i + d[1];
                if (ya < 0 || yb >= h || std::min(xa, xb) < 0 || std::max(xa, xb) >= w)
                    continue;
                const double r =
                    double(z[size_t(j) * w + i]) -
                    0.5 * (double(z[size_t(ya) * w + xa]) + z[size_t(yb) * w + xb]);
                finite = finite && std::isfinite(r * r);
                best = std::min(best, r * r / 1.5);
                ++count;
            }
            const double median = count == 4 ? kFrameNoiseMedianOf4 : kFrameNoiseMedianOf1;
            e[size_t(j) * w + i] = count > 0 && finite ? float(best / median) : NAN;
        }
    return e;
}

}  // namespace

Image FrameNoise(const Image &color, const Image *albedo) {
    const int w = color.width, h = color.height;
    if (albedo && (albedo->width != w || albedo->height != h ||
                   (albedo->channels != 1 && albedo->channels < color.channels)))
        throw Error("FrameNoise: the albedo must have the colour's size, 1 or its channels",
                    ErrorKind::Internal);
    Image out(w, h, color.channels);
    for (int c = 0; c < color.channels; ++c) {
        const std::vector<float> e = SecondDifferences(color, albedo, c);
        const float *a = albedo ? albedo->Plane(albedo->channels == 1 ? 0 : c) : nullptr;
        float *dst = out.Plane(c);
        ParallelFor(h, size_t(w) * h * 25, [&](int begin, int end) {
            float window[25];
            for (int y = begin; y < end; ++y)
                for (int x = 0; x < w; ++x) {
                    int count = 0;
                    for (int j = std::max(0, y - 2); j <= std::min(h - 1, y + 2); ++j)
                        for (int i = std::max(0, x - 2); i <= std::min(w - 1, x + 2); ++i)
                            if (float v = e[size_t(j) * w + i]; std::isfinite(v))
                                window[count++] = v;
                    const size_t p = size_t(y) * w + x;
                    if (count == 0) {
                        dst[p] = 0;
                        continue;
                    }
                    std::nth_element(window, window + (count - 1) / 2, window + count);
                    const double albedoAt = a && a[p] > 0.02f ? a[p] : 1.0;
                    dst[p] = float(window[(count - 1) / 2] / kFrameNoiseWindowBias * albedoAt *
                                   albedoAt);
                }
        });
    }
    return out;
}

namespace {

// The median of the values at (x, y)'s neighbours within the frame (the lower middle; with
// `positive`, of those not <= 0); NaN where one is not finite or there is none.
double NeighbourMedian(const float *plane, int w, int h, int x, int y, bool positive = false) {
    float values[8];
    int count = 0;
    for (int v = std::max(0, y - 1); v <= std::min(h - 1, y + 1); ++v)
        for (int u = std::max(0, x - 1); u <= std::min(w - 1, x + 1); ++u)
            if ((u != x || v != y) && (!positive || !(plane[size_t(v) * w + u] <= 0)))
                values[count++] = plane[size_t(v) * w + u];
    if (count == 0 ||
        !std::all_of(values, values + count, [](float v) { return std::isfinite(v); }))
        return NAN;
    std::nth_element(values, values + (count - 1) / 2, values + count);
    return values[(count - 1) / 2];
}

// Whether the channels' sum at (x, y) is over kSpike times its neighbours' median `*median`
// (set): finite, above 0, beside finite neighbours.
bool OverSpike(const Image &sums, int x, int y, double *median) {
    const float own = sums.data[size_t(y) * sums.width + x];
    *median = NeighbourMedian(sums.data.data(), sums.width, sums.height, x, y);
    return std::isfinite(own) && own > 0 && std::isfinite(*median) && own > kSpike * *median;
}

// Whether (x, y)'s value is above each of its neighbours' within the frame that is not over
// (a pair of fireflies is cut whole): a light's rim beside its core is not a spike, however
// far over its other neighbours it is.
bool AboveNeighbours(const float *plane, const std::vector<char> &over, int w, int h, int x,
                     int y) {
    const float v = plane[size_t(y) * w + x];
    for (int j = std::max(0, y - 1); j <= std::min(h - 1, y + 1); ++j)
        for (int i = std::max(0, x - 1); i <= std::min(w - 1, x + 1); ++i) {
            const size_t q = size_t(j) * w + i;
            if ((i != x || j != y) && !over[q] && !(plane[q] < v)) return false;
        }
    return true;
}

}  // namespace

// Whether pixel p is a light: its sum finite and > 0, its channels' variances summed at
// most (kLightNoise x its sum)^2.
bool Light(const Image &variance, const Image &sums, size_t p) {
    const double s = sums.data[p];
    if (!(s > 0) || !std::isfinite(s)) return false;
    double v = 0;
    for (int c = 0; c < variance.channels; ++c)
        v += variance.data[c * variance.PixelCount() + p];
    return v <= kLightNoise * kLightNoise * s * s;
}

// Each pixel's channels summed (in double), NaN where the sum is not finite.
Image ChannelSums(const Image &color) {
    Image sums(color.width, color.height, 1);
    for (size_t p = 0; p < color.PixelCount(); ++p) {
        double sum = 0;
        for (int c = 0; c < color.channels; ++c) sum += color.Plane(c)[p];
        sums.data[p] = std::isfinite(sum) ? float(sum) : NAN;
    }
    return sums;
}

namespace {

// Whether (x, y) is a small light's rim (CutLightRims): no light itself, over kSpike times
// its neighbours' median, a brighter light within kRimReach, a neighbour that is none, with at
// most kSmallLight lights in its 9x9 window.
bool RimAt(const Image &sums, const std::vector<char> &light, int w, int h, int x, int y) {
    const size_t p = size_t(y) * w + x;
    const float own = sums.data[p];
    double m;
    if (light[p] || !OverSpike(sums, x, y, &m)) return false;
    bool beside = false, others = false;
    for (int j = std::max(0, y - 1); j <= std::min(h - 1, y + 1); ++j)
        for (int i = std::max(0, x - 1); i <= std::min(w - 1, x + 1); ++i) {
            const size_t q = size_t(j) * w + i;
            if (q == p) continue;
            if (!light[q]) others = true;
        }
    for (int j = std::max(0, y - kRimReach); j <= std::min(h - 1, y + kRimReach); ++j)
        for (int i = std::max(0, x - kRimReach); i <= std::min(w - 1, x + kRimReach); ++i) {
            const size_t q = size_t(j) * w + i;
            if (light[q] && sums.data[q] > own) beside = true;
        }
    if (!beside || !others) return false;
    // A small light's: a light's long edge spread along itself is its coverage.
    int lights = 0;
    for (int j = std::max(0, y - kRimWindow); j <= std::min(h - 1, y + kRimWindow); ++j)
        for (int i = std::max(0, x - kRimWindow); i <= std::min(w - 1, x + kRimWindow); ++i)
            lights += light[size_t(j) * w + i];
    return lights <= kSmallLight;
}

}  // namespace

size_t CutSpikes(Image *color, const Image *variance, std::vector<size_t> *pixels) {
    const int w = color->width, h = color->height;
    const size_t n = color->PixelCount();
    const Image sums = ChannelSums(*color);
    // Pixels beside a light, where a spike over kSpikeMost stays.
    const bool usable = variance && variance->width == w && variance->height == h &&
                        (variance->channels == 1 || variance->channels == color->channels);
    std::vector<char> lit(n, !usable);
    if (usable)
        ParallelFor(h, n * 32, [&](int begin, int end) {
            for (int y = begin; y < end; ++y)
                for (int x = 0; x < w; ++x)
                    for (int j = std::max(0, y - 1); j <= std::min(h - 1, y + 1); ++j)
                        for (int i = std::max(0, x - 1); i <= std::min(w - 1, x + 1); ++i)
                            if ((i != x || j != y) && Light(*variance, sums, size_t(j) * w + i))
                                lit[size_t(y) * w + x] = 1;
        });
    std::vector<char> over(n, 0), within(n, 0);
    ParallelFor(h, n * 16, [&](int begin, int end) {
        for (int y = begin; y < end; ++y)
            for (int x = 0; x < w; ++x) {
                const size_t p = size_t(y) * w + x;
                double m;
                over[p] = OverSpike(sums, x, y, &m);
                // Over black the ratio says nothing: there the neighbours above 0 tell.
                const double level =
                    m == 0 ? NeighbourMedian(sums.data.data(), w, h, x, y, true) : m;
                within[p] = over[p] && sums.data[p] > kSpike * level &&
                            (sums.data[p] <= kSpikeMost * level || (!lit[p] && level > 0));
            }
    });
    std::vector<size_t> cut;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            if (within[size_t(y) * w + x] && MarkedNeighbours(over, w, h, x, y) < 2 &&
                AboveNeighbours(sums.data.data(), over, w, h, x, y))
                cut.push_back(size_t(y) * w + x);
    // Every median from the frame as it came: one cut does not move another's.
    std::vector<float> medians(cut.size() * color->channels);
    for (size_t k = 0; k < cut.size(); ++k)
        for (int c = 0; c < color->channels; ++c)
            medians[k * color->channels + c] =
                float(NeighbourMedian(color->Plane(c), w, h, int(cut[k] % w), int(cut[k] / w)));
    for (size_t k = 0; k < cut.size(); ++k)
        for (int c = 0; c < color->channels; ++c)
            color->Plane(c)[cut[k]] = medians[k * color->channels + c];
    if (pixels) *pixels = cut;
    return cut.size();
}

void TakeNeighbourMedians(const Image &given, const std::vector<size_t> &pixels,
                          const std::vector<char> &skipped, Image *cut) {
    const int w = given.width, h = given.height;
    for (size_t p : pixels) {
        const int x = int(p % w), y = int(p / w);
        for (int c = 0; c < given.channels; ++c) {
            float values[8];
            int count = 0;
            for (int j = std::max(0, y - 1); j <= std::min(h - 1, y + 1); ++j)
                for (int i = std::max(0, x - 1); i <= std::min(w - 1, x + 1); ++i) {
                    const size_t q = size_t(j) * w + i;
                    if (q != p && !skipped[q]) values[count++] = given.Plane(c)[q];
                }
            if (count == 0 ||
                !std::all_of(values, values + count, [](float v) { return std::isfinite(v); }))
                continue;
            std::nth_element(values, values + (count - 1) / 2, values + count);
            cut->Plane(c)[p] = values[(count - 1) / 2];
        }
    }
}

std::vector<size_t> CutLightRims(Image *color, const Image &variance) {
    const int w = color->width, h = color->height;
    const size_t n = color->PixelCount();
    std::vector<size_t> rims;
    if (variance.width != w || variance.height != h ||
        (variance.channels != 1 && variance.channels != color->channels))
        return rims;
    const Image sums = ChannelSums(*color);
    std::vector<char> light(n);
    for (size_t p = 0; p < n; ++p) light[p] = Light(variance, sums, p);
    // Each row's rims found on the cores, then gathered in order.
    std::vector<std::vector<size_t>> rowRims(static_cast<size_t>(h));
    ParallelFor(h, n * 16, [&](int begin, int end) {
        for (int y = begin; y < end; ++y)
            for (int x = 0; x < w; ++x)
                if (RimAt(sums, light, w, h, x, y))
                    rowRims[size_t(y)].push_back(size_t(y) * w + x);
    });
    for (const std::vector<size_t> &row : rowRims)
        rims.insert(rims.end(), row.begin(), row.end());
    // Every median from the frame as it came, over the neighbours that are no lights.
    std::vector<float> medians(rims.size() * color->channels);
    for (size_t k = 0; k < rims.size(); ++k) {
        const int x = int(rims[k] % w), y = int(rims[k] / w);
        for (int c = 0; c < color->channels; ++c) {
            float values[8];
            int count = 0;
            for (int j = std::max(0, y - 1); j <= std::min(h - 1, y + 1); ++j)
                for (int i = std::max(0, x - 1); i <= std::min(w - 1, x + 1); ++i) {
                    const size_t q = size_t(j) * w + i;
                    if (q != rims[k] && !light[q]) values[count++] = color->Plane(c)[q];
                }
            if (count == 0) continue;  // RimAt asks for a neighbour that is no light
            std::nth_element(values, values + (count - 1) / 2, values + count);
            medians[k * color->channels + c] = values[(count - 1) / 2];
        }
    }
    for (size_t k = 0; k < rims.size(); ++k)
        for (int c = 0; c < color->channels; ++c)
            color->Plane(c)[rims[k]] = medians[k * color->channels + c];
    return rims;
}

namespace {

// The most samples above the histograms' range over a pixel's colours (the last two bins of
// each); -1 where the pixel has no samples.
double BrightSamples(const Image &histograms, size_t p) {
    const int n3 = histograms.channels - 1, perColour = n3 / 3;
    const size_t n = histograms.PixelCount();
    if (!(histograms.data[n3 * n + p] > 0)) return -1;
    double most = 0;
    for (int c = 0; c < 3; ++c)
        most = std::max(most, double(histograms.data[(c * perColour + perColour - 2) * n + p]) +
                                  histograms.data[(c * perColour + perColour - 1) * n + p]);
    return most;
}

// P(X >= k) for X ~ Binomial(t, pi), 0 <= k <= t, summed term by term: a cluster's t is at
// most 2k (the rest of its window holds no more): k + 1 terms at most, none left out.
double BinomialTail(int64_t k, int64_t t, double pi) {
    double tail = 0;
    for (int64_t i = k; i <= t; ++i)
        tail += std::exp(std::lgamma(double(t) + 1) - std::lgamma(double(i) + 1) -
                         std::lgamma(double(t - i) + 1) + double(i) * std::log(pi) +
                         double(t - i) * std::log1p(-pi));
    return tail;
}

// The 8-connected cluster of `over` pixels holding p (pixels marked in `seen`), ascending.
std::vector<size_t> ClusterAt(const std::vector<char> &over, int w, int h, size_t p,
                              std::vector<char> *seen) {
    std::vector<size_t> cluster, stack{p};
    (*seen)[p] = 1;
    while (!stack.empty()) {
        const size_t q = stack.back();
        stack.pop_back();
        cluster.push_back(q);
        const int x = int(q % w), y = int(q / w);
        for (int j = std::max(0, y - 1); j <= std::min(h - 1, y + 1); ++j)
            for (int i = std::max(0, x - 1); i <= std::min(w - 1, x + 1); ++i) {
                const size_t r = size_t(j) * w + i;
                if (over[r] && !(*seen)[r]) {
                    (*seen)[r] = 1;
                    stack.push_back(r);
                }
            }
    }
    std::sort(cluster.begin(), cluster.end());
    return cluster;
}

// `over` with the bridges added: a pixel that is not over but holds a bright sample (its count
// rounds to 1 or more: the histograms' rescale leaves it a little under 1), beside
// kBridgedGroups or more groups of `over` (8-connected) of at least kBridgedSize pixels each
// holding one, spanning less than kClusterSpan (CutBrightClusters). The span bounds how far
// a join reads: a longer group's bridge would depend on the whole of it.
std::vector<char> JoinBridged(const Image &histograms, const std::vector<char> &over, int w,
                              int h) {
    const size_t n = over.size();
    // Each group's label, and whether it may be bridged.
    std::vector<int> label(n, -1);
    std::vector<char> bridgeable;
    std::vector<char> seen(n, 0);
    for (size_t p = 0; p < n; ++p) {
        if (!over[p] || seen[p]) continue;
        const std::vector<size_t> group = ClusterAt(over, w, h, p, &seen);
        bool bright = group.size() >= size_t(kBridgedSize);
        int x0 = w, x1 = -1, y0 = h, y1 = -1;
        for (size_t q : group) {
            label[q] = int(bridgeable.size());
            bright = bright && BrightSamples(histograms, q) >= 0.5;
            const int x = int(q % w), y = int(q / w);
            x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y),
            y1 = std::max(y1, y);
        }
        bridgeable.push_back(bright && x1 - x0 + 1 < kClusterSpan &&
                             y1 - y0 + 1 < kClusterSpan);
    }
    std::vector<char> joined = over;
    ParallelFor(h, n * 16, [&](int begin, int end) {
        for (int y = begin; y < end; ++y)
            for (int x = 0; x < w; ++x) {
                const size_t p = size_t(y) * w + x;
                if (over[p] || !(BrightSamples(histograms, p) >= 0.5)) continue;
                int groups[8], count = 0;
                for (int j = std::max(0, y - 1); j <= std::min(h - 1, y + 1); ++j)
                    for (int i = std::max(0, x - 1); i <= std::min(w - 1, x + 1); ++i) {
                        const int g = label[size_t(j) * w + i];
                        if (g >= 0 && bridgeable[g] &&
                            std::find(groups, groups + count, g) == groups + count)
                            groups[count++] = g;
                    }
                joined[p] = count >= kBridgedGroups;
            }
    });
    return joined;
}

// Whether the cluster's bright samples are too many for its share of its search window's
// (CutBrightClusters).
bool ClusterStandsOut(const Image &histograms, int w, int h, const std::vector<size_t> &cluster,
                      int searchHalf) {
    if (cluster.size() < size_t(kClusterLeast)) return false;
    const size_t n = histograms.PixelCount();
    int x0 = w, x1 = -1, y0 = h, y1 = -1;
    double own = 0;
    for (size_t p : cluster) {
        // A pixel with more is kept apart by the bright veto.
        const double b = BrightSamples(histograms, p),
                     count = histograms.data[(histograms.channels - 1) * n + p];
        if (b < 0 || b > kClusterShare * count) return false;
        own += b;
        x0 = std::min(x0, int(p % w)), x1 = std::max(x1, int(p % w));
        y0 = std::min(y0, int(p / w)), y1 = std::max(y1, int(p / w));
    }
    // Longer: a highlight's line, whose run the filter follows.
    if (x1 - x0 >= kClusterSpan || y1 - y0 >= kClusterSpan) return false;
    double around = 0;
    int pixels = 0;
    for (int y = std::max(0, y0 - searchHalf); y <= std::min(h - 1, y1 + searchHalf); ++y)
        for (int x = std::max(0, x0 - searchHalf); x <= std::min(w - 1, x1 + searchHalf); ++x) {
            if (x >= x0 - 1 && x <= x1 + 1 && y >= y0 - 1 && y <= y1 + 1) continue;
            around += std::max(0.0, BrightSamples(histograms, size_t(y) * w + x));
            ++pixels;
        }
    const int64_t k = std::lround(own), t = std::lround(own + around);
    if (k < 2 || pixels == 0 || around > own) return false;
    const double share = double(cluster.size()) / double(cluster.size() + pixels);
    return BinomialTail(k, std::max(t, k), share) < kClusterLevel;
}

}  // namespace

std::vector<size_t> CutBrightClusters(const Image &input, const Image &histograms,
                                      int searchHalf, Image *color,
                                      std::vector<size_t> *bridged) {
    const int w = input.width, h = input.height;
    const size_t n = input.PixelCount();
    std::vector<size_t> cut, joinedCut;
    if (bridged) bridged->clear();
    if (histograms.width != w || histograms.height != h || histograms.channels < 4) return cut;
    const Image sums = ChannelSums(input);
    std::vector<char> over(n, 0);
    ParallelFor(h, n * 16, [&](int begin, int end) {
        for (int y = begin; y < end; ++y)
            for (int x = 0; x < w; ++x) {
                double m;
                over[size_t(y) * w + x] = OverSpike(sums, x, y, &m);
            }
    });
    const std::vector<char> joined = JoinBridged(histograms, over, w, h);
    std::vector<char> seen(n, 0), inCluster(n, 0);
    for (size_t p = 0; p < n; ++p) {
        if (!joined[p] || seen[p]) continue;
        const std::vector<size_t> cluster = ClusterAt(joined, w, h, p, &seen);
        if (!ClusterStandsOut(histograms, w, h, cluster, searchHalf)) continue;
        for (size_t q : cluster) inCluster[q] = 1;
        const bool joins =
            std::any_of(cluster.begin(), cluster.end(), [&](size_t q) { return !over[q]; });
        std::vector<size_t> &to = joins ? joinedCut : cut;
        to.insert(to.end(), cluster.begin(), cluster.end());
    }
    std::sort(cut.begin(), cut.end());
    std::sort(joinedCut.begin(), joinedCut.end());
    // Each takes its neighbours' median outside the cluster, from the frame as given.
    TakeNeighbourMedians(input, cut, inCluster, color);
    TakeNeighbourMedians(input, joinedCut, inCluster, color);
    if (bridged) *bridged = std::move(joinedCut);
    return cut;
}

namespace {

// The bound's lowest value: k standard deviations below the input, and not below 0 where
// the input is not negative (noise does not make a non-negative truth negative).
double BoundLow(double in, double spread) {
    return in >= 0 ? std::max(0.0, in - spread) : in - spread;
}

// How far the output may move from the input toward o.
double BoundAllowed(double in, double o, double spread) {
    return o < in ? in - BoundLow(in, spread) : spread;
}

// One channel's limits under a bound that moves a pixel's channels by one share: the
// range [lo, hi] its value ends in, and the largest share of its move from the input that
// the range allows. Not bounded: the channel is left as it is. Floor only: its noise says
// nothing, so it is only kept from going below 0, alone (moving the pixel's other channels
// with it, to their input, brought back a dim frame's grain).
struct ChannelLimit {
    bool bounded = false, floorOnly = false;
    double lo = 0, hi = 0, share = 1;
};

// Each pixel's bounded channels moved to input + t (output - input), clamped to their
// ranges, with one t for the pixel: the least share any of its channels allows (a bound on
// one channel alone would tint the pixel); a channel bounded by its floor only is raised to
// 0 where it is below. `limit(c, x, y, in, out)` gives a channel's
// ChannelLimit; `cost`: about the operations per pixel and channel. Returns how many values
// moved.
template <typename Limit>
size_t MoveByOneShare(const Image &input, Image *output, size_t cost, Limit limit) {
    const int w = input.width, h = input.height, channels = input.channels;
    std::atomic<size_t> moved{0};
    ParallelFor(h, size_t(w) * h * cost * channels, [&](int yBegin, int yEnd) {
        size_t movedHere = 0;
        std::vector<ChannelLimit> limits(channels);
        for (int y = yBegin; y < yEnd; ++y)
            for (int x = 0; x < w; ++x) {
                const size_t p = size_t(y) * w + x;
                double t = 1;
                for (int c = 0; c < channels; ++c) {
                    limits[c] =
                        limit(c, x, y, double(input.Plane(c)[p]), double(output->Plane(c)[p]));
                    if (limits[c].floorOnly && output->Plane(c)[p] < 0)
                        output->Plane(c)[p] = 0, ++movedHere;
                    else if (limits[c].bounded && !limits[c].floorOnly)
                        t = std::min(t, limits[c].share);
                }
                if (t == 1) continue;
                for (int c = 0; c < channels; ++c) {
                    if (!limits[c].bounded || limits[c].floorOnly) continue;
                    float *out = &output->Plane(c)[p];
                    const double in = input.Plane(c)[p];
                    const float value = float(
                        std::clamp(in + t * (double(*out) - in), limits[c].lo, limits[c].hi));
                    if (value != *out) *out = value, ++movedHere;
                }
            }
        moved += movedHere;
    });
    return moved.load();
}

}  // namespace

double NoiseSpread(const Image &variance, int c, int x, int y) {
    const int w = variance.width, h = variance.height;
    const float *v = variance.Plane(variance.channels == 1 ? 0 : c);
    if (!(v[size_t(y) * w + x] > 0)) return -1;
    double sum = 0, largest = 0;
    int count = 0;
    for (int j = std::max(0, y - 1); j <= std::min(h - 1, y + 1); ++j)
        for (int i = std::max(0, x - 1); i <= std::min(w - 1, x + 1); ++i) {
            const float vi = v[size_t(j) * w + i];
            if (!std::isfinite(vi) || vi < 0) return -1;
            sum += vi;
            largest = std::max(largest, double(vi));
            ++count;
        }
    const double rest = count > 1 ? (sum - largest) / (count - 1) : 0;
    return std::sqrt(std::max(double(v[size_t(y) * w + x]), rest));
}

size_t BoundToNoise(const Image &input, const Image &variance, double k, Image *output) {
    if (!input.SameShape(*output) || variance.width != input.width ||
        variance.height != input.height ||
        (variance.channels != 1 && variance.channels != input.channels) || !(k > 0))
        throw Error(
            "BoundToNoise: the output must have the input's shape, the variance its "
            "size, k > 0",
            ErrorKind::Internal);
    return MoveByOneShare(input, output, 24, [&](int c, int x, int y, double in, double o) {
        ChannelLimit limit;
        if (!std::isfinite(in) || !std::isfinite(o)) return limit;
        const double s = NoiseSpread(variance, c, x, y);
        if (s < 0) {
            // Its noise says nothing, but a truth that is not negative is not made so.
            limit.floorOnly = limit.bounded = in >= 0;
            return limit;
        }
        const double spread = k * s;
        const double allowed = BoundAllowed(in, o, spread);
        limit = {true, false, BoundLow(in, spread), in + spread, 1};
        if (std::fabs(o - in) > allowed) limit.share = allowed / std::fabs(o - in);
        return limit;
    });
}

size_t BoundToInputRange(const Image &input, const Image &variance, int radius, double k,
                         Image *output) {
    if (!input.SameShape(*output) || radius < 0 || !(k >= 0) || variance.width != input.width ||
        variance.height != input.height ||
        (variance.channels != 1 && variance.channels != input.channels))
        throw Error(
            "BoundToInputRange: the output must have the input's shape, the variance its size, "
            "radius >= 0, k >= 0",
            ErrorKind::Internal);
    const int w = input.width, h = input.height, side = 2 * radius + 1;
    return MoveByOneShare(
        input, output, side * side + 9, [&](int c, int x, int y, double i, double o) {
            ChannelLimit limit;
            const double spread = NoiseSpread(variance, c, x, y);
            if (!std::isfinite(i) || !std::isfinite(o) || spread < 0) return limit;
            const float *in = input.Plane(c);
            float least = in[size_t(y) * w + x], most = least;
            for (int v = std::max(0, y - radius); v <= std::min(h - 1, y + radius); ++v)
                for (int u = std::max(0, x - radius); u <= std::min(w - 1, x + radius); ++u) {
                    const float q = in[size_t(v) * w + u];
                    if (!std::isfinite(q)) continue;
                    least = std::min(least, q);
                    most = std::max(most, q);
                }
            const double slack = kRangeSlack * std::max(std::fabs(least), std::fabs(most));
            limit = {true, false, double(least) - k * spread - slack,
                     double(most) + k * spread + slack, 1};
            if (o > limit.hi) limit.share = (limit.hi - i) / (o - i);
            if (o < limit.lo) limit.share = (i - limit.lo) / (i - o);
            return limit;
        });
}

std::string RestoreLocalMeansRebalanced(const Image &input, int r, Image *output,
                                        const Image *variance, double rebalance) {
    LocalMeanFactors f = RestoreLocalMeans(input, r, output, variance, rebalance, true);
    return fmt::format(
        "the input's means over tents of radius {}, then {}, then {} again restored (factors "
        "{:.3g} to {:.3g})",
        8 * r, 2 * r, 8 * r, f.lo, f.hi);
}

namespace {

// Per pixel w (a0 - h1)(a0 - b0) and w (a0 - b0)^2 summed over the channels (planes 0
// and 1), w = 1 / (a^2 + 0.01), a the channels' mean of `a`.
Image RestoreGain(const Image &a, const Image &a0, const Image &b0, const Image &h1) {
    const size_t n = a.PixelCount();
    Image terms(a.width, a.height, 2);
    for (size_t i = 0; i < n; ++i) {
        double mean = 0;
        for (int c = 0; c < a.channels; ++c) mean += a.data[c * n + i];
        mean /= a.channels;
        double w = 1 / (mean * mean + 0.01), gain = 0, squared = 0;
        if (!std::isfinite(w)) continue;
        for (int c = 0; c < a.channels; ++c) {
            double x = a0.data[c * n + i], y = b0.data[c * n + i], h = h1.data[c * n + i];
            if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(h)) continue;
            gain += w * (x - h) * (x - y);
            squared += w * (x - y) * (x - y);
        }
        terms.data[i] = float(gain);
        terms.data[n + i] = float(squared);
    }
    return terms;
}

// The highlights the restore took back among exact lit neighbours (AmongExactLit): every
// channel of `restored` the input's and some channel not `combined`'s. One sample of many
// saw such a light, so it lies in one half alone and the other cannot confirm it; the
// neighbours' samples, all equal, say it is coverage, not a rare path. Empty of marks
// without a variance of the input's size.
std::vector<char> CoverageHighlights(const Image &input, const Image *variance,
                                     const Image &combined, const Image &restored) {
    const size_t n = input.PixelCount();
    std::vector<char> marked(n, 0);
    if (!variance || variance->width != input.width || variance->height != input.height ||
        (variance->channels != 1 && variance->channels != input.channels))
        return marked;
    const std::vector<char> exact = ExactLitPixels(input, *variance);
    for (size_t i = 0; i < n; ++i) {
        bool taken = true, moved = false;
        for (int c = 0; c < input.channels; ++c) {
            taken = taken && restored.data[c * n + i] == input.data[c * n + i];
            moved = moved || restored.data[c * n + i] != combined.data[c * n + i];
        }
        marked[i] = taken && moved &&
                    AmongExactLit(exact, input.width, input.height, int(i % input.width),
                                  int(i / input.width));
    }
    return marked;
}

}  // namespace

RestoreCheck RestoreLocalMeansChecked(const Image &input, const Image &half0,
                                      const Image &half1, const Image &combined,
                                      const Image &combinedHalf, int r, const Image *variance,
                                      double rebalance, int s, double floorShare, Image *output,
                                      double maxGain) {
    if (!half0.SameShape(input) || !half1.SameShape(input) || !combined.SameShape(input) ||
        !combinedHalf.SameShape(input))
        throw Error(
            "RestoreLocalMeansChecked: the halves and combinations must have the "
            "input's shape",
            ErrorKind::InvalidArgument);
    RestoreCheck check;
    Image restored = combined, restoredHalf = combinedHalf;
    check.restore = RestoreLocalMeansRebalanced(input, r, &restored, variance, rebalance);
    RestoreLocalMeansRebalanced(half0, r, &restoredHalf, variance, rebalance);
    Image terms = TentMean(RestoreGain(combined, combinedHalf, restoredHalf, half1), s);
    const size_t n = input.PixelCount();
    std::vector<double> share(n, 1.0);
    const std::vector<char> coverage = CoverageHighlights(input, variance, combined, restored);
    // The means of the input, of the checked output and of what a full lift would add.
    double in = 0, checked = 0, rest = 0, total = 0;
    for (size_t i = 0; i < n; ++i) {
        if (terms.data[n + i] > 0 && !coverage[i])
            share[i] = std::clamp(double(terms.data[i]) / terms.data[n + i], 0.0, 1.0);
        total += share[i];
        for (int c = 0; c < input.channels; ++c) {
            double a = combined.data[c * n + i], b = restored.data[c * n + i];
            double x = input.data[c * n + i];
            if (std::isfinite(x)) in += x;
            if (!std::isfinite(a) || !std::isfinite(b)) continue;
            checked += a + share[i] * (b - a);
            rest += (1 - share[i]) * (b - a);
        }
    }
    check.meanShare = n ? total / double(n) : 1;
    // A gain of at most maxGain first, then as much more of the restore as the floor asks.
    const double target = floorShare * in;
    // A gain that reaches the target leaves no lift (not even one rounding step's).
    bool reached = false;
    if (checked < target && checked > 0 && rest > 0 && maxGain > 1) {
        const double cap = std::min(maxGain, (checked + rest) / checked);
        reached = target / checked <= cap;
        check.gain = std::min(target / checked, cap);
    }
    if (!reached && checked * check.gain < target && rest > 0)
        check.lift = std::min(1.0, (target / check.gain - checked) / rest);
    *output = combined;
    for (size_t i = 0; i < n; ++i) {
        double t = share[i] + check.lift * (1 - share[i]);
        for (int c = 0; c < input.channels; ++c) {
            double a = combined.data[c * n + i], b = restored.data[c * n + i];
            output->data[c * n + i] = float(check.gain * (a + t * (b - a)));
        }
    }
    return check;
}

}  // namespace mcd
