#include "cpu_reference/nfor_specks.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

namespace mcd::ref {

namespace {

double Mean(const Image &image, int x, int y) {
    double sum = 0;
    for (int c = 0; c < image.channels; ++c) sum += image.At(c, y, x);
    return sum / image.channels;
}

}  // namespace

void NforClampSpecks(const Image &mask, int rank, double relative, double floor, Image *output,
                     double flatShare, double flatRelative) {
    const Image before = *output;
    for (int y = 0; y < before.height; ++y)
        for (int x = 0; x < before.width; ++x) {
            if (mask.At(0, y, x) != 1) continue;
            std::vector<double> neighbours;
            bool emitter = false, finite = true;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    int u = x + dx, v = y + dy;
                    if ((dx == 0 && dy == 0) || u < 0 || v < 0 || u >= before.width ||
                        v >= before.height)
                        continue;
                    if (mask.At(0, v, u) == 0) emitter = true;
                    double l = Mean(before, u, v);
                    if (!std::isfinite(l)) finite = false;
                    neighbours.push_back(l);
                }
            if (emitter || !finite || neighbours.size() < 8) continue;
            std::sort(neighbours.begin(), neighbours.end());
            double n = neighbours[neighbours.size() - size_t(rank)];
            // The 5th brightest of the 8: the neighbours' median, on a flat ground near n.
            bool flat = flatShare > 0 && neighbours[3] >= flatShare * n;
            double bound = (1 + (flat ? flatRelative : relative)) * n + floor,
                   l = Mean(before, x, y);
            if (!(l > bound)) continue;
            for (int c = 0; c < before.channels; ++c)
                output->At(c, y, x) = float(before.At(c, y, x) * (bound / l));
        }
}

namespace {

// The bits of channel c of pixel (x, y): equal bits, equal values (NaN and -0 alike).
uint32_t Bits(const Image &image, int c, int y, int x) {
    uint32_t bits;
    float value = image.At(c, y, x);
    std::memcpy(&bits, &value, sizeof bits);
    return bits;
}

bool SameColour(const Image &a, int ya, int xa, const Image &b, int yb, int xb) {
    for (int c = 0; c < a.channels; ++c)
        if (Bits(a, c, ya, xa) != Bits(b, c, yb, xb)) return false;
    return true;
}

}  // namespace

std::vector<char> NforExactGround(const Image &input, const Image &clamped, const Image &mask) {
    std::vector<char> flags(size_t(input.width) * input.height, 0);
    for (int y = 0; y < input.height; ++y)
        for (int x = 0; x < input.width; ++x) {
            bool border = x == 0 || y == 0 || x == input.width - 1 || y == input.height - 1;
            if (border || mask.At(0, y, x) != 1 || !SameColour(input, y, x, clamped, y, x))
                continue;
            int ground = 0;
            bool lit = false;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    int u = x + dx, v = y + dy;
                    if ((dx == 0 && dy == 0) || u < 0 || v < 0 || u >= input.width ||
                        v >= input.height || mask.At(0, v, u) != 1)
                        continue;
                    // Every neighbour equal to the one above and to the left.
                    if (!SameColour(input, v, u, input, y - 1, x - 1)) continue;
                    ++ground;
                    for (int c = 0; c < input.channels; ++c) lit = lit || input.At(c, v, u) > 0;
                }
            flags[size_t(y) * input.width + x] =
                ground == 8 && lit && !SameColour(input, y, x, input, y - 1, x - 1);
        }
    return flags;
}

namespace {

// The lower median of `values` (not empty): the ((n - 1) / 2)-th smallest.
double LowerMedianOf(std::vector<double> values) {
    std::sort(values.begin(), values.end());
    return values[(values.size() - 1) / 2];
}

bool IsLoneSample(const Image &variance, const Image &color, int y, int x, double hits,
                  double ratio) {
    double m = 0, s = 0;
    for (int c = 0; c < color.channels; ++c) {
        m += color.At(c, y, x);
        s += std::sqrt(std::max(double(variance.At(c, y, x)), 0.0));
    }
    m /= color.channels;
    s /= color.channels;
    if (!(m * m < hits * s * s)) return false;
    std::vector<double> means;
    int firstY = -1, firstX = -1;
    bool allSame = true;
    for (int v = y - 1; v <= y + 1; ++v)
        for (int u = x - 1; u <= x + 1; ++u) {
            if ((u == x && v == y) || u < 0 || v < 0 || u >= color.width || v >= color.height)
                continue;
            if (firstY < 0) firstY = v, firstX = u;
            allSame = allSame && SameColour(color, v, u, color, firstY, firstX);
            const double l = Mean(color, u, v);
            if (std::isfinite(l)) means.push_back(l);
        }
    if (means.empty() || allSame) return false;
    const double median = LowerMedianOf(means);
    return median > 0 && m > ratio * median;
}

}  // namespace

Image NforCapLoneSamples(const Image &variance, const Image &color, double hits, double ratio,
                         int reach, size_t *count) {
    const int w = color.width, h = color.height;
    std::vector<char> lone(size_t(w) * h, 0);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            lone[size_t(y) * w + x] = IsLoneSample(variance, color, y, x, hits, ratio);
    Image out = variance;
    size_t capped = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            if (!lone[size_t(y) * w + x]) continue;
            int others = 0;
            for (int v = std::max(0, y - reach); v <= std::min(h - 1, y + reach); ++v)
                for (int u = std::max(0, x - reach); u <= std::min(w - 1, x + reach); ++u)
                    others += (u != x || v != y) && lone[size_t(v) * w + u];
            if (others > 0) continue;
            for (int c = 0; c < variance.channels; ++c) {
                std::vector<double> around;
                for (int v = y - 1; v <= y + 1; ++v)
                    for (int u = x - 1; u <= x + 1; ++u) {
                        if ((u == x && v == y) || u < 0 || v < 0 || u >= w || v >= h) continue;
                        if (std::isfinite(variance.At(c, v, u)))
                            around.push_back(variance.At(c, v, u));
                    }
                if (!around.empty())
                    out.At(c, y, x) =
                        float(std::min(double(variance.At(c, y, x)), LowerMedianOf(around)));
            }
            ++capped;
        }
    if (count) *count = capped;
    return out;
}

}  // namespace mcd::ref
