#include "cpu_reference/nfor.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <vector>

#include "cpu_reference/local_mean.h"
#include "cpu_reference/nfor_alpha.h"
#include "cpu_reference/nfor_band.h"
#include "cpu_reference/nfor_coarse.h"
#include "cpu_reference/nfor_kept.h"
#include "cpu_reference/nfor_lights.h"
#include "cpu_reference/nfor_line.h"
#include "cpu_reference/nfor_rare.h"
#include "cpu_reference/nfor_specks.h"

namespace mcd::ref {
namespace {

bool Inside(const Image &image, int x, int y) {
    return x >= 0 && y >= 0 && x < image.width && y < image.height;
}

// The divisor of channel c at (x, y): the albedo's channel (its last one for fewer) where
// above the floor, else 0: the pixel is not divided.
double Divisor(const Image *divisor, int c, int x, int y) {
    if (!divisor) return 0;
    double a = divisor->At(std::min(c, divisor->channels - 1), y, x);
    return a > kNforNoiseAlbedoFloor ? a : 0;
}

// Whether two divisors divide alike: neither divides, or both within the ratio. The
// divisors are the albedo's floats and the products are rounded to float as the kernels
// round them, so a ratio at the bound (quantized albedos meet it exactly) is decided alike.
bool Alike(double a, double b) {
    if (a == 0 || b == 0) return a == b;
    const float fa = float(a), fb = float(b), ratio = float(kNforNoiseDivisorRatio);
    return fa <= fb * ratio && fb <= fa * ratio;
}

// z = value / divisor (the value where not divided).
double Demodulated(double value, double divisor) {
    return divisor > 0 ? value / divisor : value;
}

// The lower median (element (n - 1) / 2 of the sorted values).
double LowerMedian(std::vector<double> values) {
    std::sort(values.begin(), values.end());
    return values[(values.size() - 1) / 2];
}

// The k-th largest of the values (the smallest where there are fewer).
double KthLargest(std::vector<double> values, int k) {
    std::sort(values.begin(), values.end(), std::greater<double>());
    return values[std::min(size_t(k), values.size()) - 1];
}

}  // namespace

namespace {

// The noise estimate of channel c at (x, y) before calibration and scale: per direction the
// lower median of the half squared differences of the pairs that count (both divided alike
// to the pixel; relaxed: both divided where it is, both not where it is not, the pixel in
// neither) over the median
// of chi^2_1 (sparse: where that median is 0, their mean), the smallest over the directions
// with at least minPairs pairs; -1 for none.
double SmallestMedian(const Image &image, const Image *divisor, int radius, int c, int x, int y,
                      bool relaxed, size_t minPairs, bool sparse) {
    const int dirs[4][2] = {{1, 0}, {0, 1}, {1, 1}, {1, -1}};
    double a = Divisor(divisor, c, x, y), best = -1;
    for (const auto &d : dirs) {
        std::vector<double> halves;
        for (int v = y - radius; v <= y + radius; ++v)
            for (int u = x - radius; u <= x + radius; ++u) {
                int u1 = u + d[0], v1 = v + d[1];
                if (!Inside(image, u, v) || !Inside(image, u1, v1)) continue;
                double a0 = Divisor(divisor, c, u, v);
                double a1 = Divisor(divisor, c, u1, v1);
                bool centre = (u == x && v == y) || (u1 == x && v1 == y);
                bool counts = relaxed ? !centre && (a0 > 0) == (a > 0) && (a1 > 0) == (a > 0)
                                      : Alike(a, a0) && Alike(a, a1);
                if (!counts) continue;
                double diff =
                    Demodulated(image.At(c, v, u), a0) - Demodulated(image.At(c, v1, u1), a1);
                halves.push_back(0.5 * diff * diff);
            }
        if (halves.size() < minPairs || halves.empty()) continue;
        double estimate = LowerMedian(halves) / kNforChi2Median;
        if (estimate == 0 && sparse) {
            double sum = 0;
            for (double half : halves) sum += half;
            estimate = sum / double(halves.size());
        }
        if (best < 0 || estimate < best) best = estimate;
    }
    return best;
}

}  // namespace

Image NforNoise(const Image &image, const Image *divisor, int radius, double calibration,
                bool relaxed, bool sparse) {
    Image out(image.width, image.height, image.channels);
    for (int c = 0; c < image.channels; ++c)
        for (int y = 0; y < image.height; ++y)
            for (int x = 0; x < image.width; ++x) {
                double a = Divisor(divisor, c, x, y);
                double best = SmallestMedian(image, divisor, radius, c, x, y, false,
                                             kNforNoiseMinPairs, sparse);
                // An edge pixel unlike its neighbours: their pairs divided as it is.
                if (best < 0 && relaxed)
                    best = SmallestMedian(image, divisor, radius, c, x, y, true,
                                          kNforNoiseMinRelaxedPairs, sparse);
                double scale = a > 0 ? a * a : 1;
                out.At(c, y, x) = best < 0 ? 0.f : float(best * calibration * scale);
            }
    return out;
}

Image NforMask(const Image *albedo, int width, int height, double emitterAlbedo) {
    Image mask(width, height, 1, 1.f);
    if (!albedo) return mask;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            double most = 0;
            for (int c = 0; c < albedo->channels; ++c)
                most = std::max(most, double(albedo->At(c, y, x)));
            if (most > emitterAlbedo) mask.At(0, y, x) = 0;
        }
    return mask;
}

namespace {

// Channel c of (x, y) clamped on its own: its value, or its limit where it is above: the
// median (or k-th largest) of the neighbours' z divided alike + t sqrt(v) / a + rho |median|.
double ClampedValue(const Image &color, const Image &variance, const Image *divisor,
                    const Image &mask, double threshold, double relative, int rank,
                    double lightEdge, int c, int x, int y) {
    double a = Divisor(divisor, c, x, y), value = color.At(c, y, x);
    // The z of the neighbours divided alike; without any, their colours.
    std::vector<double> alike, all;
    bool emitterNear = false;
    for (int v = y - 1; v <= y + 1; ++v)
        for (int u = x - 1; u <= x + 1; ++u) {
            if ((u == x && v == y) || !Inside(color, u, v)) continue;
            emitterNear |= mask.At(0, v, u) == 0;
            double aq = Divisor(divisor, c, u, v);
            all.push_back(color.At(c, v, u));
            if (Alike(a, aq)) alike.push_back(Demodulated(color.At(c, v, u), aq));
        }
    // Unlike all around it next to a light: the light's edge, kept or clamped with its own
    // relative term.
    bool edge = alike.empty() && emitterNear;
    if (all.empty() || (edge && lightEdge < 0)) return value;
    double s = !alike.empty() && a > 0 ? a : 1;
    std::vector<double> &near = alike.empty() ? all : alike;
    double median = rank == 0 ? LowerMedian(near) : KthLargest(near, rank);
    double limit = median + threshold * std::sqrt(double(variance.At(c, y, x))) / s +
                   (edge ? lightEdge : relative) * std::fabs(median);
    return value / s > limit ? limit * s : value;
}

// Brightness of (x, y) for the line test: the sum of its channels' positive parts (a
// negative channel, say ringing, must not make a firefly beside it look dim), in float in
// channel order as the kernel adds them, so both draw the same lines; 0 outside the frame.
float LineBrightness(const Image &color, int x, int y) {
    if (!Inside(color, x, y)) return 0.f;
    float sum = 0.f;
    for (int c = 0; c < color.channels; ++c) sum += std::max(color.At(c, y, x), 0.f);
    return sum;
}

// The brightness of (x, y)'s line: over the 2 axes and the 2 diagonals, the largest of the
// dimmer side's brightest pixel 1 or 2 steps away (in float, as the kernel compares).
float LineSupport(const Image &color, int x, int y) {
    const int steps[4][2] = {{1, 0}, {0, 1}, {1, 1}, {-1, 1}};
    float support = 0.f;
    for (const auto &d : steps) {
        float ahead = 0.f, behind = 0.f;
        for (int s = 1; s <= 2; ++s) {
            ahead = std::max(ahead, LineBrightness(color, x + s * d[0], y + s * d[1]));
            behind = std::max(behind, LineBrightness(color, x - s * d[0], y - s * d[1]));
        }
        support = std::max(support, std::min(ahead, behind));
    }
    return support;
}

// Whether an albedo channel above kNforLineFloorLight (a bright emitter) lies within
// kNforLineFloorReach pixels of (x, y).
bool EmitterWithinReach(const Image *albedo, int x, int y) {
    if (!albedo) return false;
    const int r = kNforLineFloorReach;
    for (int v = y - r; v <= y + r; ++v)
        for (int u = x - r; u <= x + r; ++u)
            for (int c = 0; c < albedo->channels && Inside(*albedo, u, v); ++c)
                if (albedo->At(c, v, u) > float(kNforLineFloorLight)) return true;
    return false;
}

// Whether (x, y) is a light smaller than a pixel that its samples saw directly: an emitter
// (mask 0) with no emitter among its 8 neighbours, its largest albedo channel at least
// `least`, each colour channel within kNforLoneLightRatio of its albedo's both ways (the
// products rounded to float, as the kernel compares them).
bool LoneLight(const Image &color, const Image *albedo, const Image &mask, double least, int x,
               int y) {
    if (least <= 0 || !albedo || mask.At(0, y, x) != 0) return false;
    for (int v = y - 1; v <= y + 1; ++v)
        for (int u = x - 1; u <= x + 1; ++u)
            if ((u != x || v != y) && Inside(color, u, v) && mask.At(0, v, u) == 0)
                return false;
    const float ratio = float(kNforLoneLightRatio);
    float most = 0;
    for (int c = 0; c < color.channels; ++c) {
        const float a = albedo->At(std::min(c, albedo->channels - 1), y, x);
        const float value = color.At(c, y, x);
        if (!(a > 0 && value <= a * ratio && a <= value * ratio)) return false;
        most = std::max(most, a);
    }
    return most >= float(least);
}

}  // namespace

Image NforClamp(const Image &color, const Image &variance, const Image *divisor,
                const Image &mask, double threshold, double relative, int rank,
                double lightEdge, bool sumChannels, double line, double loneLight,
                double lineFloor) {
    Image out = color;
    if (threshold <= 0) return out;
    for (int y = 0; y < color.height; ++y)
        for (int x = 0; x < color.width; ++x) {
            // A line's pixel is kept; its peak keeps lineFloor x the line's brightness.
            const float brightness = LineBrightness(color, x, y);
            const float support = line > 0 || lineFloor > 0 ? LineSupport(color, x, y) : 0.f;
            if (line > 0 && support > float(line) * brightness) continue;
            const float floorShare =
                brightness > 0 ? std::min(float(lineFloor) * support / brightness, 1.f) : 0.f;
            if (LoneLight(color, divisor, mask, loneLight, x, y)) continue;
            const bool floored = lineFloor > 0 && EmitterWithinReach(divisor, x, y);
            double values = 0, kept = 0;
            std::vector<double> clamped(color.channels), ratios;
            for (int c = 0; c < color.channels; ++c) {
                double v = color.At(c, y, x);
                clamped[c] = ClampedValue(color, variance, divisor, mask, threshold, relative,
                                          rank, lightEdge, c, x, y);
                values += v;
                kept += clamped[c];
                ratios.push_back(v > 0 ? clamped[c] / v : 1);
            }
            // The second smallest share a channel keeps: 1 - it of the pixel scaled whole.
            std::sort(ratios.begin(), ratios.end());
            double t =
                sumChannels && ratios.size() > 1 ? std::clamp(1 - ratios[1], 0.0, 1.0) : 0;
            double scale = values > 0 ? std::min(kept / values, 1.0) : 1;
            for (int c = 0; c < color.channels; ++c) {
                const float v = color.At(c, y, x);
                out.At(c, y, x) =
                    float(t > 0 ? (1 - t) * clamped[c] + t * v * scale : clamped[c]);
                // The line's floor, after the channels' blend.
                if (floored && v > 0)
                    out.At(c, y, x) = std::max(out.At(c, y, x), floorShare * v);
            }
        }
    return out;
}

Image NforPrefilter(const Image &features, const Image &variance, int radius, int patch,
                    double bandwidth) {
    Image out = features;
    if (radius <= 0) return out;
    for (int j = 0; j < features.channels; ++j)
        for (int y = 0; y < features.height; ++y)
            for (int x = 0; x < features.width; ++x) {
                double sum = 0, weights = 0;
                for (int v = y - radius; v <= y + radius; ++v)
                    for (int u = x - radius; u <= x + radius; ++u) {
                        if (!Inside(features, u, v)) continue;
                        // NL-means distance of the patches around (x, y) and (u, v).
                        double distance = 0;
                        int count = 0;
                        for (int ty = -patch; ty <= patch; ++ty)
                            for (int tx = -patch; tx <= patch; ++tx) {
                                int px = x + tx, py = y + ty, qx = u + tx, qy = v + ty;
                                if (!Inside(features, px, py) || !Inside(features, qx, qy))
                                    continue;
                                double fp = features.At(j, py, px), fq = features.At(j, qy, qx);
                                double vp = variance.At(j, py, px), vq = variance.At(j, qy, qx);
                                double term =
                                    ((fp - fq) * (fp - fq) - (vp + vq)) /
                                    (vp + vq + kNforRelEps * (fp * fp + fq * fq) + kNforTiny);
                                distance += std::min(term, kNforTermMax);
                                ++count;
                            }
                        double e = std::max(0.0, distance / count) / (bandwidth * bandwidth);
                        double w = u == x && v == y ? 1 : (e > kNforExpCut ? 0 : std::exp(-e));
                        sum += w * features.At(j, v, u);
                        weights += w;
                    }
                out.At(j, y, x) = float(sum / weights);
            }
    return out;
}

int NforOffsetCount(int radius) {
    int side = 2 * radius + 1;
    return (side * side - 1) / 2;
}

void NforOffset(int radius, int j, int *ox, int *oy) {
    // Raster order over the window skips the centre and everything before it.
    int side = 2 * radius + 1;
    int index = (side * side + 1) / 2 + j;
    *ox = index % side - radius;
    *oy = index / side - radius;
}

Image NforAlbedoTrust(const Image &color, const Image &albedo, double noise) {
    const int w = color.width, h = color.height, channels = color.channels;
    // The albedo at least the floor, a NaN the floor (as the kernel's comparison).
    auto albedoAt = [&](int c, int x, int y) {
        double a = albedo.At(std::min(c, albedo.channels - 1), y, x);
        return a > kNforNoiseAlbedoFloor ? a : kNforNoiseAlbedoFloor;
    };
    Image trust(w, h, 1);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            // The window's pixels inside the frame.
            std::vector<std::pair<int, int>> window;
            for (int v = y - 1; v <= y + 1; ++v)
                for (int u = x - 1; u <= x + 1; ++u)
                    if (Inside(color, u, v)) window.emplace_back(u, v);
            const double n = double(window.size());
            // Per quantity (0 albedo, 1 colour, 2 colour / albedo): the channels' sum of the
            // window's variance and of its squared mean.
            double variances[3] = {0, 0, 0}, squaredMeans[3] = {0, 0, 0};
            for (int c = 0; c < channels; ++c)
                for (int kind = 0; kind < 3; ++kind) {
                    auto valueOf = [&](int u, int v) {
                        double a = albedoAt(c, u, v), value = color.At(c, v, u);
                        return kind == 0 ? a : kind == 1 ? value : value / a;
                    };
                    double mean = 0;
                    for (auto [u, v] : window) mean += valueOf(u, v);
                    mean /= n;
                    double deviation = 0;
                    for (auto [u, v] : window)
                        deviation += (valueOf(u, v) - mean) * (valueOf(u, v) - mean);
                    variances[kind] += deviation / n;
                    squaredMeans[kind] += mean * mean;
                }
            const bool rough = variances[0] > noise * squaredMeans[0];
            const bool roughens = variances[2] * squaredMeans[1] >
                                  (1 + kNforTrustTie) * variances[1] * squaredMeans[2];
            trust.At(0, y, x) = rough && roughens ? 0.f : 1.f;
        }
    return trust;
}

Image NforGlintRows(const Image &albedo, double gate, int reach) {
    const int w = albedo.width, h = albedo.height;
    Image rows(w, h, 1);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int u = std::max(0, x - reach); u <= std::min(w - 1, x + reach); ++u)
                for (int c = 0; c < albedo.channels; ++c)
                    if (double(albedo.At(c, y, u)) > gate) rows.At(0, y, x) = 1.f;
    return rows;
}

Image NforGlintNoise(const Image &color, const Image &albedo, const Image &trust, double gate,
                     int reach, double scale, Image *variance) {
    const int w = color.width, h = color.height;
    auto glint = [&](int x, int y) {
        for (int c = 0; c < albedo.channels; ++c)
            if (double(albedo.At(c, y, x)) > gate) return true;
        return false;
    };
    Image floored(w, h, 1);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            if (trust.At(0, y, x) != 0.f) continue;
            // Any glint in the square of half-side `reach` around the pixel.
            bool near = false;
            for (int v = y - reach; v <= y + reach && !near; ++v)
                for (int u = x - reach; u <= x + reach && !near; ++u)
                    near = Inside(color, u, v) && glint(u, v);
            if (!near) continue;
            int count = 0;
            for (int v = y - 1; v <= y + 1; ++v)
                for (int u = x - 1; u <= x + 1; ++u) count += Inside(color, u, v);
            const float inverse = shader::kNforGlintInverses[count];
            for (int c = 0; c < color.channels; ++c) {
                // The window's mean, then its squared deviations, in raster order.
                float mean = 0.f;
                for (int v = y - 1; v <= y + 1; ++v)
                    for (int u = x - 1; u <= x + 1; ++u)
                        if (Inside(color, u, v)) mean += color.At(c, v, u);
                mean *= inverse;
                float squares = 0.f;
                for (int v = y - 1; v <= y + 1; ++v)
                    for (int u = x - 1; u <= x + 1; ++u)
                        if (Inside(color, u, v)) {
                            const float d = color.At(c, v, u) - mean;
                            squares += d * d;
                        }
                const float bound = float(scale) * (squares * inverse);
                float &value = variance->At(c, y, x);
                if (bound > value) {
                    value = bound;
                    floored.At(0, y, x) = 1.f;
                }
            }
        }
    return floored;
}

namespace {

// Whether the pair (x, y), (x + ox, y + oy) compares colour / albedo: both trusted (no
// trust image: every pixel is).
bool PairTrusted(const Image *trust, int x, int y, int ox, int oy) {
    return !trust || (trust->At(0, y, x) != 0 && trust->At(0, y + oy, x + ox) != 0);
}

}  // namespace

Image NforDistance(const Image &color, const Image &variance, const Image *divisor, int radius,
                   int patch, double alpha, bool minVariance, const Image *trust) {
    // The values compared and their variances: the colour, or colour / albedo.
    Image z = color, vz = variance;
    for (int c = 0; c < color.channels; ++c)
        for (int y = 0; y < color.height; ++y)
            for (int x = 0; x < color.width; ++x) {
                double a = Divisor(divisor, c, x, y);
                if (a == 0) continue;
                z.At(c, y, x) = float(color.At(c, y, x) / a);
                vz.At(c, y, x) = float(variance.At(c, y, x) / (a * a));
            }
    int w = color.width, h = color.height;
    Image out(w, h, NforOffsetCount(radius));
    for (int j = 0; j < out.channels; ++j) {
        int ox, oy;
        NforOffset(radius, j, &ox, &oy);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                double sum = 0;
                int count = 0;
                for (int ty = -patch; ty <= patch; ++ty)
                    for (int tx = -patch; tx <= patch; ++tx) {
                        int ux = x + tx, uy = y + ty;
                        if (!Inside(color, ux, uy) || !Inside(color, ux + ox, uy + oy))
                            continue;
                        double term = 0;
                        // Colour / albedo where both albedos are trusted, else the colours.
                        const bool divided = PairTrusted(trust, ux, uy, ox, oy);
                        const Image &zs = divided ? z : color, &vs = divided ? vz : variance;
                        for (int c = 0; c < color.channels; ++c) {
                            double cp = zs.At(c, uy, ux), cq = zs.At(c, uy + oy, ux + ox);
                            double vp = vs.At(c, uy, ux), vq = vs.At(c, uy + oy, ux + ox);
                            double s = minVariance ? 2 * std::min(vp, vq) : vp + vq;
                            double t = ((cp - cq) * (cp - cq) - alpha * s) /
                                       (s + kNforRelEps * (cp * cp + cq * cq) + kNforTiny);
                            term += std::min(t, kNforTermMax);
                        }
                        sum += term / color.channels;
                        ++count;
                    }
                out.At(j, y, x) = count > 0 ? float(sum / count) : 0.f;
            }
    }
    return out;
}

Image NforTerms(const Image &color, const Image &variance, const Image *divisor, int radius,
                double alpha, bool minVariance, const Image *trust) {
    int w = color.width, h = color.height;
    Image out(w, h, NforOffsetCount(radius));
    for (int j = 0; j < out.channels; ++j) {
        int ox, oy;
        NforOffset(radius, j, &ox, &oy);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                if (!Inside(color, x + ox, y + oy)) continue;
                double term = 0;
                const bool divided = PairTrusted(trust, x, y, ox, oy);
                for (int c = 0; c < color.channels; ++c) {
                    // Colour and variance, divided by the albedo where it is above the floor
                    // and both ends' albedos are trusted.
                    double ap = divided ? Divisor(divisor, c, x, y) : 0,
                           aq = divided ? Divisor(divisor, c, x + ox, y + oy) : 0;
                    double sp = ap > 0 ? ap : 1, sq = aq > 0 ? aq : 1;
                    double cp = color.At(c, y, x) / sp, cq = color.At(c, y + oy, x + ox) / sq;
                    double vp = variance.At(c, y, x) / (sp * sp),
                           vq = variance.At(c, y + oy, x + ox) / (sq * sq);
                    double s = minVariance ? 2 * std::min(vp, vq) : vp + vq;
                    double t = ((cp - cq) * (cp - cq) - alpha * s) /
                               (s + kNforRelEps * (cp * cp + cq * cq) + kNforTiny);
                    term += std::min(t, kNforTermMax);
                }
                out.At(j, y, x) = float(term / color.channels);
            }
    }
    return out;
}

Image NforBoxPass(const Image &terms, int radius, int patch, bool vertical) {
    int w = terms.width, h = terms.height;
    Image out(w, h, terms.channels);
    for (int j = 0; j < terms.channels; ++j) {
        int ox, oy;
        NforOffset(radius, j, &ox, &oy);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                double sum = 0;
                for (int t = -patch; t <= patch; ++t) {
                    int u = vertical ? x : x + t, v = vertical ? y + t : y;
                    if (Inside(terms, u, v)) sum += terms.At(j, v, u);
                }
                if (!vertical) {
                    out.At(j, y, x) = float(sum);
                    continue;
                }
                // Patch positions (tx, ty) with both (x, y) + t and (x, y) + t + o inside.
                int count = 0;
                for (int ty = -patch; ty <= patch; ++ty)
                    for (int tx = -patch; tx <= patch; ++tx)
                        count += Inside(terms, x + tx, y + ty) &&
                                 Inside(terms, x + tx + ox, y + ty + oy);
                out.At(j, y, x) = count > 0 ? float(sum / count) : 0.f;
            }
    }
    return out;
}

namespace {

// D(p, q - p) from the stored half of the offsets.
double DistanceOf(const Image &distance, int radius, int px, int py, int qx, int qy) {
    int ox = qx - px, oy = qy - py;
    if (ox == 0 && oy == 0) return 0;
    int side = 2 * radius + 1, centre = (side * side - 1) / 2;
    int index = (oy + radius) * side + ox + radius;
    if (index > centre) return distance.At(index - centre - 1, py, px);
    // The mirrored offset is stored at q.
    int mirrored = (radius - oy) * side + radius - ox;
    return distance.At(mirrored - centre - 1, qy, qx);
}

// Weight of q in p's window (0 outside the frame or for an emitter).
double WeightOf(const Image &features, const Image &mask, const Image &distance,
                const NforCandidate &k, int px, int py, int qx, int qy) {
    if (!Inside(mask, qx, qy) || mask.At(0, qy, qx) == 0 || mask.At(0, py, px) == 0) return 0;
    if (qx == px && qy == py) return 1;
    double e = std::max(0.0, DistanceOf(distance, k.radius, px, py, qx, qy)) /
               (k.bandwidth * k.bandwidth);
    for (size_t j = 0; j < k.featureWeights->size(); ++j) {
        double d = (*k.featureWeights)[j] *
                   (double(features.At(int(j), qy, qx)) - features.At(int(j), py, px));
        e += d * d;
    }
    return e > kNforExpCut ? 0 : std::exp(-e);
}

// The regression's columns for q in p's window.
void Columns(const Image &features, int radius, int px, int py, int qx, int qy, double *x) {
    x[0] = 1;
    x[1] = double(qx - px) / radius;
    x[2] = double(qy - py) / radius;
    for (int j = 0; j < features.channels; ++j)
        x[3 + j] = double(features.At(j, qy, qx)) - features.At(j, py, px);
}

// Cholesky factor of the n x n row-major matrix in place (lower triangle); false when not
// positive definite.
bool Cholesky(std::vector<double> &a, int n) {
    for (int j = 0; j < n; ++j) {
        double s = a[j * n + j];
        for (int k = 0; k < j; ++k) s -= a[j * n + k] * a[j * n + k];
        if (!(s > 0)) return false;
        a[j * n + j] = std::sqrt(s);
        for (int i = j + 1; i < n; ++i) {
            double t = a[i * n + j];
            for (int k = 0; k < j; ++k) t -= a[i * n + k] * a[j * n + k];
            a[i * n + j] = t / a[j * n + j];
        }
    }
    return true;
}

void CholeskySolve(const std::vector<double> &l, int n, double *b) {
    for (int i = 0; i < n; ++i) {
        double t = b[i];
        for (int k = 0; k < i; ++k) t -= l[i * n + k] * b[k];
        b[i] = t / l[i * n + i];
    }
    for (int i = n - 1; i >= 0; --i) {
        double t = b[i];
        for (int k = i + 1; k < n; ++k) t -= l[k * n + i] * b[k];
        b[i] = t / l[i * n + i];
    }
}

}  // namespace

NforFit NforRegress(const Image &color, const Image &features, const Image &mask,
                    const Image &distance, const NforCandidate &k) {
    int w = color.width, h = color.height, ch = color.channels, n = features.channels + 3;
    NforFit fit{Image(w, h, n * ch), Image(w, h, 1)};
    std::vector<double> a(n * n), b(n * ch), x(n);
    for (int py = 0; py < h; ++py)
        for (int px = 0; px < w; ++px) {
            if (mask.At(0, py, px) == 0) {
                // An emitter: its own value, no slope; it is never gathered.
                for (int c = 0; c < ch; ++c) fit.beta.At(c, py, px) = color.At(c, py, px);
                fit.hat.At(0, py, px) = 1;
                continue;
            }
            std::fill(a.begin(), a.end(), 0.0);
            std::fill(b.begin(), b.end(), 0.0);
            double weights = 0;
            for (int qy = py - k.radius; qy <= py + k.radius; ++qy)
                for (int qx = px - k.radius; qx <= px + k.radius; ++qx) {
                    double wq = WeightOf(features, mask, distance, k, px, py, qx, qy);
                    if (wq == 0) continue;
                    Columns(features, k.radius, px, py, qx, qy, x.data());
                    for (int i = 0; i < n; ++i) {
                        for (int jj = 0; jj < n; ++jj) a[i * n + jj] += wq * x[i] * x[jj];
                        for (int c = 0; c < ch; ++c)
                            b[c * n + i] += wq * x[i] * color.At(c, qy, qx);
                    }
                    weights += wq;
                }
            for (int i = 1; i < n; ++i) a[i * n + i] += k.ridge * weights;
            if (!Cholesky(a, n)) {
                // Only without a ridge: the pixel keeps its value.
                for (int c = 0; c < ch; ++c) fit.beta.At(c, py, px) = color.At(c, py, px);
                fit.hat.At(0, py, px) = 1;
                continue;
            }
            for (int c = 0; c < ch; ++c) {
                CholeskySolve(a, n, &b[c * n]);
                for (int i = 0; i < n; ++i)
                    fit.beta.At(i * ch + c, py, px) = float(b[c * n + i]);
            }
            std::vector<double> e0(n, 0.0);
            e0[0] = 1;
            CholeskySolve(a, n, e0.data());
            fit.hat.At(0, py, px) = float(e0[0]);
        }
    return fit;
}

Image NforGather(const Image &input, const Image &features, const Image &mask,
                 const Image &distance, const NforFit &fit, const NforCandidate &k) {
    int w = input.width, h = input.height, ch = input.channels, n = features.channels + 3;
    Image out(w, h, ch);
    std::vector<double> x(n), sum(ch);
    for (int qy = 0; qy < h; ++qy)
        for (int qx = 0; qx < w; ++qx) {
            if (mask.At(0, qy, qx) == 0) {
                for (int c = 0; c < ch; ++c) out.At(c, qy, qx) = input.At(c, qy, qx);
                continue;
            }
            std::fill(sum.begin(), sum.end(), 0.0);
            double weights = 0;
            // The windows p holding q centred at most gatherRadius away, with q's weight.
            for (int py = qy - k.gatherRadius; py <= qy + k.gatherRadius; ++py)
                for (int px = qx - k.gatherRadius; px <= qx + k.gatherRadius; ++px) {
                    if (!Inside(input, px, py)) continue;
                    double wq = WeightOf(features, mask, distance, k, px, py, qx, qy);
                    if (wq == 0) continue;
                    Columns(features, k.radius, px, py, qx, qy, x.data());
                    for (int c = 0; c < ch; ++c) {
                        double value = 0;
                        for (int i = 0; i < n; ++i)
                            value += x[i] * fit.beta.At(i * ch + c, py, px);
                        sum[c] += wq * value;
                    }
                    weights += wq;
                }
            for (int c = 0; c < ch; ++c) out.At(c, qy, qx) = float(sum[c] / weights);
        }
    return out;
}

namespace {

// The window mean over (2 r + 1)^2 clipped to the frame of one plane.
double WindowMean(const Image &plane, int r, int x, int y) {
    double sum = 0;
    int count = 0;
    for (int v = y - r; v <= y + r; ++v)
        for (int u = x - r; u <= x + r; ++u)
            if (Inside(plane, u, v)) sum += plane.At(0, v, u), ++count;
    return sum / count;
}

// Per pixel SURE of each candidate: sum over channels of (y - C)^2 - v + 2 v h.
std::vector<Image> SurePlanes(const std::vector<Image> &outputs, const std::vector<Image> &hats,
                              const Image &color, const Image &variance) {
    std::vector<Image> sure;
    for (size_t k = 0; k < outputs.size(); ++k) {
        Image s(color.width, color.height, 1);
        for (int y = 0; y < color.height; ++y)
            for (int x = 0; x < color.width; ++x) {
                double e = 0;
                for (int c = 0; c < color.channels; ++c) {
                    double d = double(outputs[k].At(c, y, x)) - color.At(c, y, x);
                    double v = variance.At(c, y, x);
                    e += d * d - v + 2 * v * hats[k].At(0, y, x);
                }
                s.At(0, y, x) = float(e);
            }
        sure.push_back(std::move(s));
    }
    return sure;
}

// Per pixel each candidate's squared difference from candidate 0 over candidate 0's
// squared magnitude (channel means) + kNforAgreementFloor; candidate 0's plane is 0.
std::vector<Image> DisagreementPlanes(const std::vector<Image> &outputs) {
    const Image &first = outputs[0];
    std::vector<Image> planes;
    for (size_t k = 0; k < outputs.size(); ++k) {
        Image d(first.width, first.height, 1);
        for (int y = 0; y < first.height; ++y)
            for (int x = 0; x < first.width; ++x) {
                double sum = 0, mean = 0;
                for (int c = 0; c < first.channels; ++c) {
                    double e = double(outputs[k].At(c, y, x)) - first.At(c, y, x);
                    sum += e * e;
                    mean += first.At(c, y, x);
                }
                mean /= first.channels;
                d.At(0, y, x) =
                    float(sum / first.channels / (mean * mean + kNforAgreementFloor));
            }
        planes.push_back(std::move(d));
    }
    return planes;
}

}  // namespace

Image NforSelect(const std::vector<Image> &outputs, const std::vector<Image> &hats,
                 const Image &color, const Image &variance, int sureRadius, Image *choice,
                 double agreement) {
    int w = color.width, h = color.height, ch = color.channels;
    std::vector<Image> planes = agreement > 0 ? DisagreementPlanes(outputs)
                                              : SurePlanes(outputs, hats, color, variance);
    Image out(w, h, ch);
    *choice = Image(w, h, 1);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            size_t best = 0;
            double bestSure = 0;
            for (size_t k = 0; k < outputs.size(); ++k) {
                double mean = WindowMean(planes[k], sureRadius, x, y);
                if (agreement > 0) {
                    if (k > 0 && mean < agreement) best = k;
                } else if (k == 0 || mean < bestSure) {
                    best = k, bestSure = mean;
                }
            }
            for (int c = 0; c < ch; ++c) out.At(c, y, x) = outputs[best].At(c, y, x);
            choice->At(0, y, x) = float(best);
        }
    return out;
}

void GuardGlint(const Image &clamped, const Image &raised, Image *out) {
    const int w = clamped.width, h = clamped.height, r = kNforGlintGuardReach;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            bool near = false;
            for (int v = y - r; v <= y + r; ++v)
                for (int u = x - r; u <= x + r; ++u)
                    near = near || (Inside(clamped, u, v) && raised.At(0, v, u) > 0.f);
            if (!near) continue;
            for (int c = 0; c < clamped.channels; ++c) {
                double low = std::numeric_limits<double>::infinity();
                for (int v = y - 1; v <= y + 1; ++v)
                    for (int u = x - 1; u <= x + 1; ++u)
                        if (Inside(clamped, u, v)) low = std::fmin(low, clamped.At(c, v, u));
                if (std::isfinite(low) && low > out->At(c, y, x)) out->At(c, y, x) = float(low);
            }
        }
}

namespace {

// A pass's candidate: its bandwidth and window half-size, and the distances over it.
struct PassCandidate {
    double bandwidth;
    int radius;
    const Image *distance;
};

// One pass: each candidate's fits weighted by its distance and their collaborative average,
// then the per-pixel choice by SURE; stages named prefix + k<i>.beta, .hat, .output, choice.
template <typename Keep>
Image NforPass(const Image &clamped, const Image &variance, const Image &features,
               const Image &mask, const NforParams &p,
               const std::vector<PassCandidate> &candidates, const std::string &prefix,
               Keep &keep, double agreement = 0) {
    std::vector<Image> outputs, hats;
    for (size_t i = 0; i < candidates.size(); ++i) {
        const PassCandidate &c = candidates[i];
        NforCandidate k{c.bandwidth, &p.featureWeights, p.ridge, c.radius,
                        std::min(p.gatherRadius, c.radius)};
        NforFit fit = NforRegress(clamped, features, mask, *c.distance, k);
        Image out = NforGather(clamped, features, mask, *c.distance, fit, k);
        keep(fmt::format("{}k{}.beta", prefix, i), fit.beta);
        keep(fmt::format("{}k{}.hat", prefix, i), fit.hat);
        keep(fmt::format("{}k{}.output", prefix, i), out);
        outputs.push_back(std::move(out));
        hats.push_back(std::move(fit.hat));
    }
    if (outputs.size() == 1) return outputs[0];
    Image choice;
    Image out = NforSelect(outputs, hats, clamped, variance, p.sureRadius, &choice, agreement);
    keep(prefix + "choice", choice);
    return out;
}

}  // namespace

namespace {

// Whether the coarse pass runs: always with p.coarse, else where the frame's noise relative
// to relMSE's denominator, from its own estimate, reaches p.coarseGate.
bool NforCoarseGateOpen(const Image &color, const Image *albedo, const NforParams &p) {
    if (p.coarse) return true;
    if (p.coarseGate <= 0) return false;
    Image own =
        NforNoise(color, albedo, p.noiseRadius, p.noiseMinCalibration, false, p.sparseNoise);
    return NforRelativeNoise(color, own) >= p.coarseGate;
}

// 1 at each pixel within `reach` of an emitter (mask 0) or of a partly covered pixel.
std::vector<char> ClampLightNear(const Image &mask, const Image *alpha, int reach) {
    const int w = mask.width, h = mask.height;
    std::vector<char> flags(mask.PixelCount());
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            bool near = false;
            for (int v = std::max(0, y - reach); v <= std::min(h - 1, y + reach); ++v)
                for (int u = std::max(0, x - reach); u <= std::min(w - 1, x + reach); ++u)
                    near = near || mask.At(0, v, u) == 0 ||
                           (alpha && NforPartlyCovered(alpha->At(0, v, u)));
            flags[size_t(y) * w + x] = near;
        }
    return flags;
}

// The colour whose local means give the clamp's light back: the clamped colour within
// `reach` of an emitter (mask 0) or of a partly covered pixel, the colour elsewhere.
Image ClampLightSource(const Image &color, const Image &clamped,
                       const std::vector<char> &near) {
    Image source = clamped;
    for (int y = 0; y < color.height; ++y)
        for (int x = 0; x < color.width; ++x) {
            if (near[size_t(y) * color.width + x]) continue;
            for (int c = 0; c < color.channels; ++c) source.At(c, y, x) = color.At(c, y, x);
        }
    return source;
}

// After the local means, where the passes of a frame without a variance layer run (`plain`)
// and the coarse pass does not:
// the colour's own means (the light the clamp took) restored at p.clampLightRadius, then
// p.clampLightFine, from ClampLightSource's colour, guarded by in.alpha's partly covered
// pixels (none with p.premultiplied: the run is one without the alpha).
// `left`: the values the local means left as `clamped` has them (emitters, highlights); of
// those, the ones the source also takes from `clamped` or shares with it stay.
template <typename Keep>
void RestoreClampLight(const NforInputs &in, const NforParams &p, bool plain,
                       const Image &clamped, const Image &mask, const std::vector<bool> &left,
                       Keep &keep, Image *out) {
    if (p.clampLightRadius <= 0 || !plain || NforCoarseGateOpen(*in.color, in.albedo, p))
        return;
    const std::vector<char> near =
        ClampLightNear(mask, p.premultiplied ? nullptr : in.alpha, p.clampLightReach);
    Image source = ClampLightSource(*in.color, clamped, near);
    std::vector<bool> stay = left;
    for (size_t i = 0; i < stay.size(); ++i)
        if (source.data[i] != clamped.data[i]) stay[i] = false;
    RestoreLocalMeanAt(source, p.clampLightRadius, p.clampLightNoise, out, &stay);
    if (p.clampLightFine > 0)
        RestoreLocalMeanAt(source, p.clampLightFine, p.clampLightNoise, out, &stay);
    keep("clamp.light", *out);
    if (p.rareLightShare > 0) {
        NforSpreadRareLight(*in.color, clamped, near, p.rareLightShare, p.rareLightRatio,
                            p.rareLightSigma, p.rareLightRadius, p.rareLightPair,
                            p.rareLightOthers, out);
        keep("rare", *out);
    }
}

// Give `out` the low frequencies of the same method at half the resolution (without a coarse
// pass of its own) where the two differ by little.
void AddCoarse(const NforInputs &in, const NforParams &p,
               std::vector<std::pair<std::string, Image>> *stages, Image *out) {
    const Image &color = *in.color;
    // The same method at half the resolution, without a coarse pass of its own.
    Image halfColor = NforHalf(color), halfFeatures = NforHalf(*in.features), halfAlbedo,
          halfVariance;
    if (in.albedo) halfAlbedo = NforHalf(*in.albedo);
    if (in.variance) halfVariance = NforHalf(*in.variance, true);
    NforInputs half{&halfColor, in.albedo ? &halfAlbedo : nullptr, &halfFeatures,
                    in.variance ? &halfVariance : nullptr};
    Image halfPilot;
    if (in.pilot) {
        halfPilot = NforHalf(*in.pilot);
        half.pilot = &halfPilot;
    }
    NforParams coarseParams = p;
    coarseParams.coarse = false;
    coarseParams.coarseGate = 0;
    coarseParams.weakLightShare = coarseParams.lightShare = 0;
    coarseParams.clampLightRadius = 0;
    Image coarse = Nfor(half, coarseParams, nullptr);
    if (stages) stages->emplace_back("coarse", coarse);
    NforAddCoarse(color, coarse, in.albedo, p.emitterAlbedo, p.coarseRelative, p.coarseNoise,
                  out);
}

// The firefly clamp of in.color against `variance`, or beside a variance layer with
// p.clampEstimate against the frame's own estimate (*clampVariance), unless that took off
// more than p.clampLoss of the light (the light is in rare bright samples): then against the
// layer (*onLayer).
Image NforClampFrame(const NforInputs &in, const NforParams &p, const Image &variance,
                     const Image &mask, Image *clampVariance, bool *onLayer) {
    const Image &color = *in.color;
    const bool ownClamp = in.variance && p.clampEstimate;
    *onLayer = false;
    if (ownClamp)
        *clampVariance = NforNoise(color, in.albedo, p.noiseRadius, p.noiseMinCalibration,
                                   false, p.sparseNoise);
    auto clamp = [&](const Image &noise) {
        return NforClamp(color, noise, in.albedo, mask, p.fireflyThreshold, p.fireflyRelative,
                         p.fireflyRank, p.fireflyLightEdge, p.fireflySum, p.fireflyLine,
                         p.fireflyLoneLight, p.fireflyLineFloor);
    };
    // The layer as the clamp reads it: lone samples capped where p.loneReach > 0.
    auto layer = [&]() {
        if (p.loneReach <= 0) return variance;
        return NforCapLoneSamples(variance, color, p.loneHits, p.loneRatio, p.loneReach,
                                  nullptr);
    };
    if (!ownClamp) return clamp(in.variance ? layer() : variance);
    Image clamped = clamp(*clampVariance);
    // The light the clamp took off, over the colour's sum.
    double sum = 0, taken = 0, values = 0, changed = 0;
    for (int c = 0; c < color.channels; ++c)
        for (int y = 0; y < color.height; ++y)
            for (int x = 0; x < color.width; ++x) {
                sum += color.At(c, y, x);
                taken += double(color.At(c, y, x)) - double(clamped.At(c, y, x));
                values += 1;
                changed += clamped.At(c, y, x) != color.At(c, y, x) ? 1 : 0;
            }
    if (sum > 0 && changed >= kNforClampLossMinShare * values && taken / sum > p.clampLoss) {
        *onLayer = true;
        clamped = clamp(layer());
    }
    return clamped;
}

// Beside a variance layer with cap > 0 (p.layerNoiseCap, p.pilotNoiseCap): `variance` capped
// at cap times the clamped colour's own estimate, edge pixels relaxed, divided by
// `alpha` (nullptr: none) as without a layer.
void NforCapLayer(const NforInputs &in, const NforParams &p, const Image &clamped,
                  const Image *alpha, double cap, Image *variance) {
    if (!in.variance || cap <= 0) return;
    Image estimate = NforNoise(clamped, in.albedo, p.noiseRadius, p.noiseMinCalibration, true,
                               p.sparseNoise);
    if (alpha) estimate = NforStraight(estimate, *alpha, 1);
    for (size_t i = 0; i < variance->data.size(); ++i)
        variance->data[i] = std::min(variance->data[i], float(cap) * estimate.data[i]);
}

// What the fits leave by design: an emitter's colour (clamped), every channel.
std::vector<bool> LeftByTheFits(const Image &clamped, const Image &mask) {
    std::vector<bool> left(clamped.data.size(), false);
    for (int c = 0; c < clamped.channels; ++c)
        for (int y = 0; y < clamped.height; ++y)
            for (int x = 0; x < clamped.width; ++x)
                left[(size_t(c) * clamped.height + y) * clamped.width + x] =
                    mask.At(0, y, x) == 0;
    return left;
}

// The features as the passes read them: prefiltered where p.prefilterRadius > 0.
Image PrefilteredFeatures(const Image &features, const NforParams &p) {
    if (p.prefilterRadius <= 0) return features;
    Image featureVariance = NforNoise(features, nullptr, p.noiseRadius, p.noiseMinCalibration);
    return NforPrefilter(features, featureVariance, p.prefilterRadius, p.prefilterPatch,
                         p.prefilterBandwidth);
}

// Near a glint, where the albedo is noise: the weights' noise floored (a frame without a
// layer, with a trust). Returns the raised pixels' mask, empty where the floor does not run.
template <typename Keep>
Image FloorGlints(const NforInputs &in, const NforParams &p, const Image &clamped,
                  const Image *trust, Keep &keep, Image *variance) {
    const bool glints = trust && !in.variance && p.edgeNoise && p.glintNoise > 0 &&
                        std::any_of(in.albedo->data.begin(), in.albedo->data.end(),
                                    [](float a) { return double(a) > kNforGlintAlbedo; });
    if (!glints) return Image();
    Image glintMask = NforGlintNoise(clamped, *in.albedo, *trust, kNforGlintAlbedo,
                                     kNforGlintReach, p.glintNoise, variance);
    keep("glint", glintMask);
    keep("glint.variance", *variance);
    return glintMask;
}

// The first pass over the colour's distance (or the pilot given from outside in its place)
// and, with pilot bandwidths, the second pass over the pilot's distance.
template <typename Keep>
Image NforPasses(const NforInputs &in, const NforParams &p, const Image &clamped,
                 const Image &variance, const Image &features, const Image &mask,
                 const Image &distance, const Image *divisor, const Image *trust,
                 const Image *alpha, Keep &keep) {
    std::vector<PassCandidate> first;
    for (double k : p.bandwidths) first.push_back({k, p.radius, &distance});
    // A pilot from outside takes the first pass's place.
    const bool givenPilot = in.pilot && !p.pilotBandwidths.empty();
    Image out = givenPilot ? *in.pilot
                           : NforPass(clamped, variance, features, mask, p, first, "", keep);
    if (!p.pilotBandwidths.empty()) {
        keep("pilot", out);
        // The second pass's distances read the weights' noise capped beside a layer.
        Image pilotVariance = variance;
        if (in.variance && p.pilotNoiseCap > 0) {
            NforCapLayer(in, p, clamped, alpha, p.pilotNoiseCap, &pilotVariance);
            keep("pilot.variance", pilotVariance);
        }
        Image pilotDistance = NforDistance(out, pilotVariance, divisor, p.radius, p.patchRadius,
                                           p.pilotAlpha, p.pilotMinVariance, trust);
        keep("pilot.distance", pilotDistance);
        std::vector<PassCandidate> second;
        for (double k : p.pilotBandwidths) second.push_back({k, p.radius, &pilotDistance});
        Image wideDistance;
        if (p.pilotWideRadius > 0) {
            wideDistance = NforDistance(out, pilotVariance, divisor, p.pilotWideRadius,
                                        p.patchRadius, p.pilotAlpha, p.pilotMinVariance, trust);
            keep("pilot.wide.distance", wideDistance);
            for (double k : p.pilotBandwidths)
                second.push_back({k, p.pilotWideRadius, &wideDistance});
        }
        double agreement =
            p.pilotWideRadius > 0 && p.pilotBandwidths.size() == 1 ? p.wideAgreement : 0;
        out = NforPass(clamped, variance, features, mask, p, second, "pilot.", keep, agreement);
    }
    return out;
}

// The method on straight values (every stage but output), its result before any alpha;
// `alpha`: the coverage the partly covered pixels were divided by (nullptr: none); in.alpha:
// the frame's coverage as given, which guards the clamp's light (not with p.premultiplied).
// *plainOut: whether the passes of a frame without a variance layer ran; *clampedOut: the
// clamped colour.
Image NforStraightRun(const NforInputs &in, const NforParams &p,
                      std::vector<std::pair<std::string, Image>> *stages, const Image *alpha,
                      bool *plainOut, Image *clampedOut) {
    // A frame the coarse pass runs on is fitted over the noisy radius's windows.
    if (p.noisyRadius > p.radius && NforCoarseGateOpen(*in.color, in.albedo, p)) {
        NforParams noisy = p;
        noisy.radius = p.noisyRadius;
        noisy.gatherRadius = p.noisyGatherRadius;
        noisy.noisyRadius = 0;
        if (noisy.pilotWideRadius <= noisy.radius) noisy.pilotWideRadius = 0;
        return NforStraightRun(in, noisy, stages, alpha, plainOut, clampedOut);
    }
    auto keep = [&](const std::string &name, const Image &image) {
        if (stages) stages->emplace_back(name, image);
    };
    const Image &color = *in.color;
    Image variance = in.variance ? *in.variance
                                 : NforNoise(color, in.albedo, p.noiseRadius,
                                             p.noiseMinCalibration, false, p.sparseNoise);
    Image mask = NforMask(in.albedo, color.width, color.height, p.emitterAlbedo);
    keep("mask", mask);
    const bool ownClamp = in.variance && p.clampEstimate;
    bool clampOnLayer = false;
    Image clampVariance;
    Image clamped = NforClampFrame(in, p, variance, mask, &clampVariance, &clampOnLayer);
    keep("color", clamped);
    if (ownClamp) keep("clamp.variance", clampVariance);
    // The passes of a frame without a layer: without one, or beside one where the clamp
    // read the frame's own estimate.
    const bool plain = !in.variance || (p.layerPasses && ownClamp && !clampOnLayer);
    if (plainOut) *plainOut = plain;
    if (!in.variance && p.edgeNoise) {
        // The weights' noise estimated again on the clamped colour, edge pixels relaxed.
        keep("clamp.variance", variance);
        variance = NforNoise(clamped, in.albedo, p.noiseRadius, p.noiseMinCalibration, true,
                             p.sparseNoise);
        // A partly covered pixel holds a N of its N samples: 1 / a times the variance of the
        // covered pixels its estimate read.
        if (alpha) variance = NforStraight(variance, *alpha, 1);
    } else if (!in.variance && alpha) {
        // The one estimate (no edge noise), after the clamp read it: 1 / a for the weights.
        variance = NforStraight(variance, *alpha, 1);
    }
    NforCapLayer(in, p, clamped, alpha, p.layerNoiseCap, &variance);
    keep("variance", variance);
    const Image features = PrefilteredFeatures(*in.features, p);
    keep("features", features);
    // The distance's divisor, and where its albedo is noise (the pairs there compare colours).
    const Image *divisor = p.demodulateDistance ? in.albedo : nullptr;
    Image trustImage;
    const Image *trust = nullptr;
    if (divisor && p.albedoNoise > 0) {
        trustImage = NforAlbedoTrust(clamped, *in.albedo, p.albedoNoise);
        keep("trust", trustImage);
        trust = &trustImage;
    }
    const Image glintMask = FloorGlints(in, p, clamped, trust, keep, &variance);
    Image distance = NforDistance(clamped, variance, divisor, p.radius, p.patchRadius, p.alpha,
                                  p.minVariance, trust);
    keep("distance", distance);
    Image out = NforPasses(in, p, clamped, variance, features, mask, distance, divisor, trust,
                           alpha, keep);
    if (p.meanRadius > 0) {
        keep("fit", out);
        std::vector<char> exact;
        if (p.speckRelative >= 0 && plain) {
            NforClampSpecks(mask, p.speckRank, p.speckRelative, p.speckFloor, &out,
                            p.speckFlatShare, p.speckFlatRelative);
            // A pixel on an exact ground takes its clamped colour (its input) back.
            if (p.exactGround) exact = NforExactGround(color, clamped, mask);
            for (int y = 0; y < out.height && !exact.empty(); ++y)
                for (int x = 0; x < out.width; ++x)
                    if (exact[size_t(y) * out.width + x])
                        for (int c = 0; c < out.channels; ++c)
                            out.At(c, y, x) = clamped.At(c, y, x);
            keep("specks", out);
        }
        std::vector<bool> left = LeftByTheFits(clamped, mask);
        // A pixel on an exact ground keeps its input: no mean counts it.
        for (size_t i = 0; i < exact.size(); ++i)
            if (exact[i])
                for (int c = 0; c < out.channels; ++c) left[c * exact.size() + i] = true;
        RestoreLocalMeans(clamped, p.meanRadius, &out, nullptr, -1, false, &left);
        RestoreClampLight(in, p, plain, clamped, mask, left, keep, &out);
    }
    // Weak emitters alone are smoothed over radius 2 when keptRadius is 0.
    int keptPass = p.keptRadius > 0 ? p.keptRadius : p.weakEmitterAlbedo > 0 ? 2 : 0;
    if (keptPass > 0 && plain && (p.keptRadius > 0 || in.albedo)) {
        keep("unkept", out);
        NforSmoothKept(color, features, p.featureWeights, mask, keptPass, p.weakEmitterAlbedo,
                       in.albedo, in.albedo ? 3 : 0, &out, p.keptRadius > 0, p.weakEmitterLine,
                       p.weakEmitterRange);
    }
    if (NforCoarseGateOpen(color, in.albedo, p)) AddCoarse(in, p, stages, &out);
    if (glintMask.PixelCount() > 0) {
        GuardGlint(clamped, glintMask, &out);
        keep("glint.guard", out);
    }
    if (clampedOut) *clampedOut = clamped;
    return out;
}

}  // namespace

Image Nfor(const NforInputs &in, const NforParams &p,
           std::vector<std::pair<std::string, Image>> *stages) {
    bool partly = false;
    if (in.alpha && !p.premultiplied)
        for (float a : in.alpha->data) partly = partly || NforPartlyCovered(a);
    Image out, albedo, clamped;
    bool plain = true;
    if (!partly) {
        out = NforStraightRun(in, p, stages, nullptr, &plain, &clamped);
    } else {
        const Image &alpha = *in.alpha;
        Image color = NforStraight(*in.color, alpha, 1),
              features = NforStraight(*in.features, alpha, 1), variance;
        if (in.albedo) albedo = NforStraight(*in.albedo, alpha, 1);
        if (in.variance) variance = NforStraight(*in.variance, alpha, 2);
        Image pilot;
        if (in.pilot) pilot = NforStraight(*in.pilot, alpha, 1);
        NforInputs straight{&color,    in.albedo ? &albedo : nullptr,
                            &features, in.variance ? &variance : nullptr,
                            &alpha,    in.pilot ? &pilot : nullptr};
        out = NforStraightRun(straight, p, stages, &alpha, &plain, &clamped);
        clamped = NforPremultiply(clamped, alpha);
        if (stages) stages->emplace_back("straight", out);
        out = NforPremultiply(out, alpha);
    }
    // The lights' spread, on the output as written; emitters told by the straight albedo.
    if (plain && in.albedo && (p.weakLightShare > 0 || p.lightShare > 0)) {
        NforSpreadLights(partly ? albedo : *in.albedo, in.alpha, p.emitterAlbedo,
                         p.weakEmitterAlbedo, p.weakLightShare, p.lightShare, &out);
        if (stages) stages->emplace_back("lights", out);
    }
    // The line spread, last, on the output and the colours as written.
    if (p.lineSpread > 0 && in.albedo) {
        NforSpreadLine(*in.color, clamped, *in.albedo, in.alpha, p.lineSpread, 4, 3, 4, &out);
        if (stages) stages->emplace_back("line", out);
    }
    // The glint bands, last, near glints alone (kNforGlintReach of kNforGlintAlbedo).
    if (plain && p.glintBandRadius > 0 && in.albedo &&
        NforSmoothGlintBands(*in.albedo, in.alpha, p.glintBandRadius, p.glintBandSigma,
                             p.glintBandTensorSigma, p.glintBandBound, kNforGlintAlbedo,
                             kNforGlintReach, p.emitterAlbedo, &out) > 0 &&
        stages)
        stages->emplace_back("glint.band", out);
    // The rim hits, last, on the output and the colour as written; emitters told as above.
    if (plain && in.albedo && p.rimRatio > 0) {
        Image before = out;
        NforFoldRimHits(*in.color, partly ? albedo : *in.albedo, in.alpha, p.emitterAlbedo,
                        p.rimRatio, 2, &out);
        if (stages && out.data != before.data) stages->emplace_back("rim", out);
    }
    if (stages) stages->emplace_back("output", out);
    return out;
}

}  // namespace mcd::ref
