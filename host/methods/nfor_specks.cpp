#include "host/methods/nfor_specks.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <vector>

#include "host/common/parallel.h"

namespace mcd {

namespace {

// Whether pixel p of `a` and pixel q of `b` hold the same bits in every channel.
bool SameBits(const Image &a, size_t p, const Image &b, size_t q) {
    for (int c = 0; c < a.channels; ++c)
        if (std::memcmp(&a.Plane(c)[p], &b.Plane(c)[q], sizeof(float)) != 0) return false;
    return true;
}

// The mean of the channels at pixel i, in double.
double ChannelMean(const Image &image, size_t i) {
    double sum = 0;
    for (int c = 0; c < image.channels; ++c) sum += image.Plane(c)[i];
    return sum / image.channels;
}

}  // namespace

size_t NforClampSpecks(const Image &mask, const NforSpeckSettings &s, Image *output) {
    const Image in = *output;
    const int w = in.width, h = in.height;
    std::vector<double> luminance(in.PixelCount());
    for (size_t i = 0; i < luminance.size(); ++i) luminance[i] = ChannelMean(in, i);
    size_t changed = 0;
    std::vector<double> around;
    // A border pixel has fewer neighbours to be bright with it: left.
    for (int y = 1; y + 1 < h; ++y)
        for (int x = 1; x + 1 < w; ++x) {
            const size_t p = size_t(y) * w + x;
            if (mask.data[p] != 1) continue;
            around.clear();
            bool nearEmitter = false, finite = true;
            for (int v = y - 1; v <= y + 1; ++v)
                for (int u = x - 1; u <= x + 1; ++u) {
                    if (u == x && v == y) continue;
                    const size_t q = size_t(v) * w + u;
                    nearEmitter = nearEmitter || mask.data[q] == 0;
                    finite = finite && std::isfinite(luminance[q]);
                    around.push_back(luminance[q]);
                }
            if (nearEmitter || !finite) continue;
            const int k = std::clamp(s.rank, 1, 8) - 1;
            std::nth_element(around.begin(), around.begin() + k, around.end(),
                             std::greater<double>());
            const double rankth = around[k], l = luminance[p];
            const double loose = (1.0 + s.relative) * rankth + double(s.floor);
            const double tight = (1.0 + s.flatRelative) * rankth + double(s.floor);
            // Only a pixel above a bound it may take needs the neighbours' median.
            if (!(l > loose) && !(s.flatShare > 0 && l > tight)) continue;
            // On a flat ground (the neighbours' median near the rank-th brightest) a speck
            // is held to the tighter bound.
            bool flat = false;
            if (s.flatShare > 0) {
                std::nth_element(around.begin(), around.begin() + 4, around.end(),
                                 std::greater<double>());
                flat = around[4] >= s.flatShare * rankth;
            }
            const double bound = flat ? tight : loose;
            if (!(l > bound)) continue;
            const double scale = bound / l;
            for (int c = 0; c < in.channels; ++c)
                output->Plane(c)[p] = float(double(in.Plane(c)[p]) * scale);
            ++changed;
        }
    return changed;
}

std::vector<char> NforExactGround(const Image &input, const Image &clamped, const Image &mask) {
    const int w = input.width, h = input.height, channels = input.channels;
    std::vector<char> exact(input.PixelCount(), 0);
    // Rows split among the cores: each pixel's flag reads the frame only.
    ParallelFor(std::max(h - 2, 0), size_t(w) * h * 8 * size_t(channels), [&](int y0, int y1) {
        for (int y = y0 + 1; y < y1 + 1; ++y)
            for (int x = 1; x + 1 < w; ++x) {
                const size_t p = size_t(y) * w + x, first = p - w - 1;
                if (mask.data[p] != 1 || !SameBits(input, p, clamped, p)) continue;
                bool ground = true, lit = false;
                for (int c = 0; c < channels; ++c) lit = lit || input.Plane(c)[first] > 0;
                for (int v = y - 1; v <= y + 1 && ground && lit; ++v)
                    for (int u = x - 1; u <= x + 1 && ground; ++u) {
                        const size_t q = size_t(v) * w + u;
                        if (q == p) continue;
                        ground = mask.data[q] == 1 && SameBits(input, q, input, first);
                    }
                exact[p] = ground && lit && !SameBits(input, p, input, first);
            }
    });
    return exact;
}

namespace {

// The in-frame neighbours of (x, y) in the 3x3 window, the pixel left out: calls
// visit(index) for each.
template <typename Visit>
void ForNeighbours(int w, int h, int x, int y, Visit visit) {
    for (int v = std::max(y - 1, 0); v <= std::min(y + 1, h - 1); ++v)
        for (int u = std::max(x - 1, 0); u <= std::min(x + 1, w - 1); ++u)
            if (u != x || v != y) visit(size_t(v) * w + u);
}

// The lower median of values[0, n) (n > 0), reordering them.
template <typename T>
T LowerMedian(T *values, int n) {
    std::nth_element(values, values + (n - 1) / 2, values + n);
    return values[(n - 1) / 2];
}

// Whether pixel (x, y) is a lone sample (NforCapLoneSamples): its layer says about one
// sample holds its mean, it is far above its neighbours, whose colours are lit and not
// all the same bits.
bool LoneSample(const Image &variance, const Image &color, int x, int y) {
    const int w = color.width, h = color.height;
    const size_t p = size_t(y) * w + x;
    double mean = 0, sigma = 0;
    for (int c = 0; c < color.channels; ++c) {
        mean += color.Plane(c)[p];
        sigma += std::sqrt(std::max(double(variance.Plane(c)[p]), 0.0));
    }
    mean /= color.channels;
    sigma /= color.channels;
    if (!(mean * mean < kNforLoneHits * sigma * sigma)) return false;
    double around[8];
    int n = 0, seen = 0;
    bool exact = true;
    size_t first = 0;  // the first neighbour visited: the others' colour compared with it
    ForNeighbours(w, h, x, y, [&](size_t q) {
        if (seen++ == 0) first = q;
        exact = exact && SameBits(color, q, color, first);
        const double l = ChannelMean(color, q);
        if (std::isfinite(l)) around[n++] = l;
    });
    if (n == 0 || exact) return false;
    const double median = LowerMedian(around, n);
    return median > 0 && mean > kNforLoneRatio * median;
}

}  // namespace

size_t NforCapLoneSamples(const Image &variance, const Image &color, Image *capped) {
    const int w = color.width, h = color.height;
    // Lone-sample flags, and their counts summed over the rectangle above and left of each
    // place (a summed-area table, (w + 1) x (h + 1)).
    std::vector<char> lone(color.PixelCount(), 0);
    ParallelFor(h, size_t(w) * h * 16, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y)
            for (int x = 0; x < w; ++x)
                lone[size_t(y) * w + x] = LoneSample(variance, color, x, y);
    });
    if (std::find(lone.begin(), lone.end(), 1) == lone.end()) return 0;
    std::vector<int> table(size_t(w + 1) * (h + 1), 0);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            table[size_t(y + 1) * (w + 1) + x + 1] =
                lone[size_t(y) * w + x] + table[size_t(y) * (w + 1) + x + 1] +
                table[size_t(y + 1) * (w + 1) + x] - table[size_t(y) * (w + 1) + x];
    auto within = [&](int x, int y) {
        const int x0 = std::max(x - kNforLoneReach, 0),
                  x1 = std::min(x + kNforLoneReach + 1, w);
        const int y0 = std::max(y - kNforLoneReach, 0),
                  y1 = std::min(y + kNforLoneReach + 1, h);
        return table[size_t(y1) * (w + 1) + x1] - table[size_t(y0) * (w + 1) + x1] -
               table[size_t(y1) * (w + 1) + x0] + table[size_t(y0) * (w + 1) + x0];
    };
    size_t changed = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const size_t p = size_t(y) * w + x;
            if (!lone[p] || within(x, y) != 1) continue;
            if (changed++ == 0) *capped = variance;
            for (int c = 0; c < variance.channels; ++c) {
                float around[8];
                int n = 0;
                ForNeighbours(w, h, x, y, [&](size_t q) {
                    const float value = variance.Plane(c)[q];
                    if (std::isfinite(value)) around[n++] = value;
                });
                if (n > 0)
                    capped->Plane(c)[p] = std::min(capped->Plane(c)[p], LowerMedian(around, n));
            }
        }
    return changed;
}

}  // namespace mcd
