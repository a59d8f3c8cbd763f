#include "cpu_reference/highlights.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace mcd::ref {
namespace {

double UpperMedian(const Image &image, int c, int x, int y, int r) {
    std::vector<double> values;
    for (int v = y - r; v <= y + r; ++v)
        for (int u = x - r; u <= x + r; ++u)
            if (u >= 0 && v >= 0 && u < image.width && v < image.height)
                values.push_back(image.At(c, v, u));
    std::sort(values.begin(), values.end());
    return values[values.size() / 2];
}

}  // namespace

std::vector<char> SplitHighlights(const Image &color, const Image *variance, double k, int r,
                                  Image *base, Image *baseVariance) {
    const int w = color.width, h = color.height;
    *base = color;
    if (variance) *baseVariance = *variance;
    std::vector<char> highlight(size_t(w) * h, 0);
    for (float v : color.data)
        if (!std::isfinite(v)) return highlight;
    Image sum(w, h, 1);
    double total = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float s = 0;
            for (int c = 0; c < color.channels; ++c) s += color.At(c, y, x);
            sum.At(0, y, x) = s;
            total += s;
        }
    const double floor = 1e-3 * total / (double(w) * h), mean = total / (double(w) * h);
    // Over k times the window's median of the sums (and the floor).
    std::vector<char> bright(size_t(w) * h, 0);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            bright[size_t(y) * w + x] =
                sum.At(0, y, x) > k * std::max(UpperMedian(sum, 0, x, y, r), floor);
    // Per pixel 0: not a highlight; 1: one with 2 such neighbours; 2: one with 1 too (4 of its
    // own standard deviations above the window's median: most of its samples saw the light).
    std::vector<int> level(size_t(w) * h, 0);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            if (!bright[size_t(y) * w + x]) continue;
            if (!variance) {
                level[size_t(y) * w + x] = 1;
                continue;
            }
            double excess = 0, v = 0;
            for (int c = 0; c < color.channels; ++c) {
                excess += color.At(c, y, x) - UpperMedian(color, c, x, y, r);
                v += variance->At(c, y, x);
            }
            if (excess > 0)
                level[size_t(y) * w + x] =
                    excess * excess > 16 * v ? 2 : excess * excess > 4 * v;
        }
    // How many of (x, y)'s 8 neighbours inside the frame are marked.
    auto neighbours = [&](const auto &marked, int x, int y) {
        int count = 0;
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                int u = x + dx, v = y + dy;
                if ((dx || dy) && u >= 0 && v >= 0 && u < w && v < h &&
                    marked[size_t(v) * w + u])
                    ++count;
            }
        return count;
    };
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            int mark = level[size_t(y) * w + x];
            highlight[size_t(y) * w + x] = mark && neighbours(level, x, y) >= 3 - mark;
        }
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            if (!highlight[size_t(y) * w + x]) continue;
            for (int c = 0; c < color.channels; ++c) {
                base->At(c, y, x) = float(UpperMedian(color, c, x, y, r));
                if (variance)
                    baseVariance->At(c, y, x) = float(UpperMedian(*variance, c, x, y, r));
            }
        }
    // Growth: up to 4 rounds; in each, a pixel not marked takes the first marked neighbour (row
    // order) that it is over k times the background of (that neighbour's base, channels
    // summed; and the frame's mean) and, with a variance, 2 standard deviations above: its base
    // and base variance become that neighbour's. Marks of a round count from the next. A fifth
    // round only looks: a connected region (8 neighbours) with a pixel that would still grow
    // from it is a large light, and its grown pixels go back to the input.
    std::vector<char> grown(size_t(w) * h, 0);
    for (int round = 0; round < 5; ++round) {
        std::vector<char> before = highlight;
        Image baseBefore = *base;
        Image varianceBefore = variance ? *baseVariance : Image();
        bool any = false;
        std::vector<char> stillGrowing(size_t(w) * h, 0);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                if (before[size_t(y) * w + x]) continue;
                double s = 0, var = 0;
                for (int c = 0; c < color.channels; ++c) {
                    s += color.At(c, y, x);
                    if (variance) var += variance->At(c, y, x);
                }
                bool done = false;
                for (int dy = -1; dy <= 1 && !done; ++dy)
                    for (int dx = -1; dx <= 1 && !done; ++dx) {
                        int u = x + dx, v = y + dy;
                        if (u < 0 || v < 0 || u >= w || v >= h || !before[size_t(v) * w + u])
                            continue;
                        double background = 0;
                        for (int c = 0; c < color.channels; ++c)
                            background += baseBefore.At(c, v, u);
                        if (!(s > k * std::max(background, mean))) continue;
                        if (variance && !((s - background) * (s - background) > 4 * var))
                            continue;
                        done = any = true;
                        if (round == 4) {
                            stillGrowing[size_t(v) * w + u] = 1;
                            continue;
                        }
                        highlight[size_t(y) * w + x] = 1;
                        grown[size_t(y) * w + x] = 1;
                        for (int c = 0; c < color.channels; ++c) {
                            base->At(c, y, x) = baseBefore.At(c, v, u);
                            if (variance)
                                baseVariance->At(c, y, x) = varianceBefore.At(c, v, u);
                        }
                    }
            }
        if (!any) break;
        if (round < 4) continue;
        // Spread the look's verdict over each region, one ring a pass, until it stops.
        for (bool changed = true; changed;) {
            changed = false;
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) {
                    if (!highlight[size_t(y) * w + x] || stillGrowing[size_t(y) * w + x])
                        continue;
                    for (int dy = -1; dy <= 1; ++dy)
                        for (int dx = -1; dx <= 1; ++dx) {
                            int u = x + dx, v = y + dy;
                            if (u >= 0 && v >= 0 && u < w && v < h &&
                                stillGrowing[size_t(v) * w + u] &&
                                !stillGrowing[size_t(y) * w + x])
                                stillGrowing[size_t(y) * w + x] = changed = true;
                        }
                }
        }
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                if (!stillGrowing[size_t(y) * w + x] || !grown[size_t(y) * w + x]) continue;
                highlight[size_t(y) * w + x] = 0;
                for (int c = 0; c < color.channels; ++c) {
                    base->At(c, y, x) = color.At(c, y, x);
                    if (variance) baseVariance->At(c, y, x) = variance->At(c, y, x);
                }
            }
    }
    return highlight;
}

void LowerToInputMaximumNearHighlights(const Image &color, const std::vector<char> &highlight,
                                       int reach, int r, Image *output) {
    const int w = color.width, h = color.height;
    auto marked = [&](int x, int y) { return highlight[size_t(y) * w + x] != 0; };
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            if (marked(x, y)) continue;
            bool near = false;
            for (int v = y - reach; v <= y + reach; ++v)
                for (int u = x - reach; u <= x + reach; ++u)
                    if (u >= 0 && v >= 0 && u < w && v < h && marked(u, v)) near = true;
            if (!near) continue;
            for (int c = 0; c < color.channels; ++c) {
                double high = -std::numeric_limits<double>::infinity();
                for (int v = y - r; v <= y + r; ++v)
                    for (int u = x - r; u <= x + r; ++u)
                        if (u >= 0 && v >= 0 && u < w && v < h && !marked(u, v))
                            high = std::max(high, double(color.At(c, v, u)));
                double out = output->At(c, y, x);
                if (std::isfinite(high) && std::isfinite(out) && out > high)
                    output->At(c, y, x) = float(high);
            }
        }
}

void AddHighlights(const Image &color, const Image &base, const std::vector<char> &highlight,
                   Image *output) {
    for (int c = 0; c < color.channels; ++c)
        for (int y = 0; y < color.height; ++y)
            for (int x = 0; x < color.width; ++x)
                if (highlight[size_t(y) * color.width + x])
                    output->At(c, y, x) += color.At(c, y, x) - base.At(c, y, x);
}

}  // namespace mcd::ref
