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

// How many of (x, y)'s 8 neighbours inside the w x h frame are marked.
template <typename Marks>
int CountNeighbours(const Marks &marked, int w, int h, int x, int y) {
    int count = 0;
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
            int u = x + dx, v = y + dy;
            if ((dx || dy) && u >= 0 && v >= 0 && u < w && v < h && marked[size_t(v) * w + u])
                ++count;
        }
    return count;
}

// Each pixel's channels summed.
Image ChannelSums(const Image &color) {
    Image sum(color.width, color.height, 1);
    for (int y = 0; y < color.height; ++y)
        for (int x = 0; x < color.width; ++x) {
            float s = 0;
            for (int c = 0; c < color.channels; ++c) s += color.At(c, y, x);
            sum.At(0, y, x) = s;
        }
    return sum;
}

// Per pixel 0: not a highlight candidate; 1: over k times its window's median of the sums
// (and the floor) and, with a variance, 2 standard deviations above its channels' medians;
// 2: 4 standard deviations above (most of its samples saw the light).
std::vector<int> CandidateLevels(const Image &color, const Image *variance, const Image &sum,
                                 double k, int r, double floor) {
    const int w = color.width, h = color.height;
    std::vector<int> level(size_t(w) * h, 0);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            if (!(sum.At(0, y, x) > k * std::max(UpperMedian(sum, 0, x, y, r), floor)))
                continue;
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
    return level;
}

// Candidates with 2 marked neighbours, or 1 at level 2; their bases become the windows'
// medians.
std::vector<char> MarkSeeds(const Image &color, const Image *variance,
                            const std::vector<int> &level, int r, Image *base,
                            Image *baseVariance) {
    const int w = color.width, h = color.height;
    std::vector<char> highlight(size_t(w) * h, 0);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            int mark = level[size_t(y) * w + x];
            if (!mark || CountNeighbours(level, w, h, x, y) < 3 - mark) continue;
            highlight[size_t(y) * w + x] = 1;
            for (int c = 0; c < color.channels; ++c) {
                base->At(c, y, x) = float(UpperMedian(color, c, x, y, r));
                if (variance)
                    baseVariance->At(c, y, x) = float(UpperMedian(*variance, c, x, y, r));
            }
        }
    return highlight;
}

// Whether a pixel summing to s is the sure rim of the highlight at (u, v), whose background
// (base summed) is b: the highlight's input summed, sq, is >= s and sq - b > 0 with
// (sq - b)^2 > 16 x the sum of its variances.
bool SureRim(const Image &color, const Image &variance, double b, double s, int u, int v) {
    double sq = 0, vq = 0;
    for (int c = 0; c < color.channels; ++c) {
        sq += color.At(c, v, u);
        vq += variance.At(c, v, u);
    }
    return s <= sq && sq - b > 0 && (sq - b) * (sq - b) > 16 * vq;
}

// The first neighbour (row order) marked in `before` that the pixel at (x, y) is over k times
// the background of (its base's channels summed; and the frame's mean) and, with a variance,
// 2 standard deviations above or the sure rim of; false when none.
bool GrowSource(const Image &color, const Image *variance, const std::vector<char> &before,
                const Image &baseBefore, double k, double mean, int x, int y, int *sx,
                int *sy) {
    const int w = color.width, h = color.height;
    double s = 0, var = 0;
    for (int c = 0; c < color.channels; ++c) {
        s += color.At(c, y, x);
        if (variance) var += variance->At(c, y, x);
    }
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
            int u = x + dx, v = y + dy;
            if (u < 0 || v < 0 || u >= w || v >= h || !before[size_t(v) * w + u]) continue;
            double background = 0;
            for (int c = 0; c < color.channels; ++c) background += baseBefore.At(c, v, u);
            if (!(s > k * std::max(background, mean))) continue;
            if (variance && !((s - background) * (s - background) > 4 * var) &&
                !SureRim(color, *variance, background, s, u, v))
                continue;
            *sx = u;
            *sy = v;
            return true;
        }
    return false;
}

// One round of growth from the marks before it: each pixel not marked with a source takes the
// source's base (and base variance). In the check round nothing grows; the sources are marked
// in `stillGrowing` instead. Returns whether any pixel had a source.
bool GrowRound(const Image &color, const Image *variance, double k, double mean, bool check,
               std::vector<char> *highlight, std::vector<char> *grown, Image *base,
               Image *baseVariance, std::vector<char> *stillGrowing) {
    const int w = color.width, h = color.height;
    const std::vector<char> before = *highlight;
    const Image baseBefore = *base;
    const Image varianceBefore = variance ? *baseVariance : Image();
    bool any = false;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            int u, v;
            if (before[size_t(y) * w + x] ||
                !GrowSource(color, variance, before, baseBefore, k, mean, x, y, &u, &v))
                continue;
            any = true;
            if (check) {
                (*stillGrowing)[size_t(v) * w + u] = 1;
                continue;
            }
            (*highlight)[size_t(y) * w + x] = (*grown)[size_t(y) * w + x] = 1;
            for (int c = 0; c < color.channels; ++c) {
                base->At(c, y, x) = baseBefore.At(c, v, u);
                if (variance) baseVariance->At(c, y, x) = varianceBefore.At(c, v, u);
            }
        }
    return any;
}

// Spreads the check round's verdict over each connected region (8 neighbours) of highlights,
// one ring a pass, until it stops; grown pixels of those regions get their input back.
void UndoStillGrowing(const Image &color, const Image *variance, const std::vector<char> &grown,
                      std::vector<char> stillGrowing, std::vector<char> *highlight, Image *base,
                      Image *baseVariance) {
    const int w = color.width, h = color.height;
    for (bool changed = true; changed;) {
        changed = false;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                if ((*highlight)[size_t(y) * w + x] && !stillGrowing[size_t(y) * w + x] &&
                    CountNeighbours(stillGrowing, w, h, x, y) > 0)
                    stillGrowing[size_t(y) * w + x] = changed = true;
    }
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            if (!stillGrowing[size_t(y) * w + x] || !grown[size_t(y) * w + x]) continue;
            (*highlight)[size_t(y) * w + x] = 0;
            for (int c = 0; c < color.channels; ++c) {
                base->At(c, y, x) = color.At(c, y, x);
                if (variance) baseVariance->At(c, y, x) = variance->At(c, y, x);
            }
        }
}

}  // namespace

std::vector<char> SplitHighlights(const Image &color, const Image *variance, double k, int r,
                                  Image *base, Image *baseVariance) {
    const int w = color.width, h = color.height;
    *base = color;
    if (variance) *baseVariance = *variance;
    for (float v : color.data)
        if (!std::isfinite(v)) return std::vector<char>(size_t(w) * h, 0);
    const Image sum = ChannelSums(color);
    double total = 0;
    for (float s : sum.data) total += s;
    const double mean = total / (double(w) * h);
    std::vector<int> level = CandidateLevels(color, variance, sum, k, r, 1e-3 * mean);
    std::vector<char> highlight = MarkSeeds(color, variance, level, r, base, baseVariance);
    // Growth: up to 4 rounds, each reading the marks of the rounds before it; a fifth only
    // looks, and a region with a pixel that would still grow is a large light: undone.
    std::vector<char> grown(size_t(w) * h, 0), stillGrowing(size_t(w) * h, 0);
    for (int round = 0; round < 5; ++round) {
        bool check = round == 4;
        if (!GrowRound(color, variance, k, mean, check, &highlight, &grown, base, baseVariance,
                       &stillGrowing))
            break;
        if (check)
            UndoStillGrowing(color, variance, grown, stillGrowing, &highlight, base,
                             baseVariance);
    }
    return highlight;
}

namespace {

// The upper median over the highlights of maxSample's channel sums; 0 without highlights or
// with NaN/Inf in maxSample.
double SparseLightSample(const Image &maxSample, const std::vector<char> &highlight) {
    for (float v : maxSample.data)
        if (!std::isfinite(v)) return 0;
    std::vector<double> lightSamples;
    for (int y = 0; y < maxSample.height; ++y)
        for (int x = 0; x < maxSample.width; ++x) {
            if (!highlight[size_t(y) * maxSample.width + x]) continue;
            double s = 0;
            for (int c = 0; c < maxSample.channels; ++c) s += maxSample.At(c, y, x);
            lightSamples.push_back(s);
        }
    if (lightSamples.empty()) return 0;
    std::sort(lightSamples.begin(), lightSamples.end());
    return lightSamples[lightSamples.size() / 2];
}

}  // namespace

void AddSparseLights(const Image &color, const Image *variance, const Image &maxSample,
                     double k, int r, double lightSample, std::vector<char> *highlight,
                     Image *base, Image *baseVariance) {
    const int w = color.width, h = color.height;
    // A frame with NaN/Inf has no highlights, nor sparse lights (as SplitHighlights).
    for (float v : color.data)
        if (!std::isfinite(v)) return;
    const double m = lightSample >= 0 ? lightSample : SparseLightSample(maxSample, *highlight);
    if (!(m > 0)) return;
    const Image sum = ChannelSums(color);
    double total = 0;
    for (float s : sum.data) total += s;
    const double mean = total / (double(w) * h);
    auto overWindow = [&](int x, int y) {
        return sum.At(0, y, x) > k * std::max(UpperMedian(sum, 0, x, y, r), 1e-3 * mean);
    };
    std::vector<char> sparse(size_t(w) * h, 0);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const double s = sum.At(0, y, x);
            if ((*highlight)[size_t(y) * w + x] || !overWindow(x, y)) continue;
            double sample = 0;
            for (int c = 0; c < maxSample.channels; ++c) sample += maxSample.At(c, y, x);
            if (!(sample <= 2 * m)) continue;
            if (s > k * mean) {
                sparse[size_t(y) * w + x] = 1;
                continue;
            }
            // A streak's pixel: over k / 2 x the mean, at least 2 neighbours over their
            // windows, its largest sample at most m / 2.
            int neighbours = 0;
            for (int v = std::max(0, y - 1); v <= std::min(h - 1, y + 1); ++v)
                for (int u = std::max(0, x - 1); u <= std::min(w - 1, x + 1); ++u)
                    neighbours += (u != x || v != y) && overWindow(u, v);
            if (s > 0.5 * k * mean && neighbours >= 2 && sample <= 0.5 * m)
                sparse[size_t(y) * w + x] = 1;
        }
    // A two-pixel reflection's dimmer pixel: the only neighbour over its window of a sparse
    // light, with no other neighbour so itself, not a highlight, with a largest sample at most
    // a quarter of the light's.
    auto sampleSum = [&](int x, int y) {
        float s = 0;
        for (int c = 0; c < maxSample.channels; ++c) s += maxSample.At(c, y, x);
        return s;
    };
    // How many of (x, y)'s 8 neighbours pass the window test; the last one in (*px, *py).
    auto overNeighbours = [&](int x, int y, int *px, int *py) {
        int over = 0;
        for (int v = std::max(0, y - 1); v <= std::min(h - 1, y + 1); ++v)
            for (int u = std::max(0, x - 1); u <= std::min(w - 1, x + 1); ++u)
                if ((u != x || v != y) && overWindow(u, v)) {
                    ++over;
                    *px = u;
                    *py = v;
                }
        return over;
    };
    std::vector<char> partner(size_t(w) * h, 0);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            if (!sparse[size_t(y) * w + x]) continue;
            int px = -1, py = -1, ux, uy;
            if (overNeighbours(x, y, &px, &py) != 1 || (*highlight)[size_t(py) * w + px] ||
                sparse[size_t(py) * w + px] || overNeighbours(px, py, &ux, &uy) != 1)
                continue;
            if (sampleSum(px, py) <= 0.25 * sampleSum(x, y)) partner[size_t(py) * w + px] = 1;
        }
    for (size_t p = 0; p < partner.size(); ++p) sparse[p] |= partner[p];
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            if (!sparse[size_t(y) * w + x]) continue;
            (*highlight)[size_t(y) * w + x] = 1;
            for (int c = 0; c < color.channels; ++c) {
                base->At(c, y, x) = float(UpperMedian(color, c, x, y, r));
                if (variance)
                    baseVariance->At(c, y, x) = float(UpperMedian(*variance, c, x, y, r));
            }
        }
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

void ClampBeyondLightRims(const Image &color, const Image &variance, const Image *maxSample,
                          double k, double frameMean, int reach, int r, Image *output) {
    for (size_t i = 0; i < color.data.size(); ++i)
        if (!std::isfinite(color.data[i]) || !std::isfinite(variance.data[i]) ||
            variance.data[i] < 0)
            return;
    if (maxSample)
        for (float v : maxSample->data)
            if (!std::isfinite(v)) return;
    const int w = color.width, h = color.height;
    auto inside = [&](int x, int y) { return x >= 0 && y >= 0 && x < w && y < h; };
    // Channel sums in float, in channel order (as ChannelSums).
    auto sum = [](const Image &image, int x, int y) {
        float s = 0;
        for (int c = 0; c < image.channels; ++c) s += image.At(c, y, x);
        return s;
    };
    // The frame's own mean of the sums unless given (a tile reads the whole frame's).
    double mean = frameMean;
    if (mean < 0) {
        double total = 0;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) total += sum(color, x, y);
        mean = total / (double(w) * h);
    }
    auto light = [&](int x, int y) {
        const double s = sum(color, x, y);
        return s > k * mean && s > 0 && s * s >= 16.0 * sum(variance, x, y);
    };
    auto rim = [&](int x, int y) {
        if (!maxSample || light(x, y)) return false;
        double brightest = 0;
        for (int v = y - 1; v <= y + 1; ++v)
            for (int u = x - 1; u <= x + 1; ++u)
                if (inside(u, v) && light(u, v))
                    brightest = std::max(brightest, double(sum(color, u, v)));
        return brightest > 0 && sum(*maxSample, x, y) >= 0.5 * brightest;
    };
    // A full light is, 2 standard deviations below its value, no dimmer than 0.75 x the
    // brightest light beside it.
    auto full = [&](int x, int y) {
        if (!light(x, y)) return false;
        double brightest = 0;
        for (int v = y - 1; v <= y + 1; ++v)
            for (int u = x - 1; u <= x + 1; ++u)
                if (inside(u, v) && light(u, v))
                    brightest = std::max(brightest, double(sum(color, u, v)));
        const double low =
            double(sum(color, x, y)) - 2 * std::sqrt(double(sum(variance, x, y)));
        return low >= 0.75 * brightest;
    };
    std::vector<char> marked(color.PixelCount()), lit(color.PixelCount());
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            lit[size_t(y) * w + x] = full(x, y);
            marked[size_t(y) * w + x] = light(x, y) || rim(x, y);
        }
    auto any = [&](const std::vector<char> &mask, int x, int y, int radius) {
        for (int v = y - radius; v <= y + radius; ++v)
            for (int u = x - radius; u <= x + radius; ++u)
                if (inside(u, v) && mask[size_t(v) * w + u]) return true;
        return false;
    };
    Image in = *output;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            if (marked[size_t(y) * w + x] || any(lit, x, y, 1)) continue;
            // Within 4 of a full light: between the lower of its input and the 5x5 window's
            // mean minus 2 of that mean's standard deviations and the higher of its input and
            // the mean plus as many. Else, within reach of a light or rim: the window's
            // maximum.
            const bool nearFull = any(lit, x, y, 4);
            if (!nearFull && !any(marked, x, y, reach)) continue;
            const int radius = nearFull ? 2 : r;
            for (int c = 0; c < color.channels; ++c) {
                double high = color.At(c, y, x), total = 0, spread = 0;
                int count = 0;
                for (int v = y - radius; v <= y + radius; ++v)
                    for (int u = x - radius; u <= x + radius; ++u)
                        if (inside(u, v) && !marked[size_t(v) * w + u]) {
                            high = std::max(high, double(color.At(c, v, u)));
                            total += color.At(c, v, u);
                            spread += variance.At(c, v, u);
                            ++count;
                        }
                const float out = in.At(c, y, x);
                if (!std::isfinite(out)) continue;
                if (nearFull) {
                    const double mean = total / count, margin = 2 * std::sqrt(spread) / count;
                    const float upper = std::max(color.At(c, y, x), float(mean + margin));
                    const float lower = std::min(color.At(c, y, x), float(mean - margin));
                    output->At(c, y, x) = std::clamp(out, lower, upper);
                } else if (out > high) {
                    output->At(c, y, x) = float(high);
                }
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
