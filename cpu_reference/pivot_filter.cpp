#include "cpu_reference/pivot_filter.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "cpu_reference/kept_edges.h"

namespace mcd::ref {
namespace {

constexpr double kTiny = 1e-30;
constexpr double kZMax = 1e18;
// exp(-e) for e above this is 0 (no denormals).
constexpr double kExpCut = 30;
// A pivot of the elimination below this fraction of its column's raw second moment means
// the window's pixels do not span that direction: the fit drops to a lower order.
constexpr double kRankEps = 1e-4;
// A pixel beside other ids mixes in a side far from its own (PivotRatioOf) when the sides'
// medians of z within kSideRadius lie over kSideGap of their spreads (kMadSigma x their
// median distances to their medians) apart and its z over kSideToward of its deviation
// toward the other side: kept.
constexpr double kSideGap = 2;
constexpr double kSideToward = 0.5;
constexpr double kMadSigma = 1.4826;
constexpr int kSideRadius = 2;

// One pixel of a window: offset from the centre, weight, value, variance of the value.
struct Sample {
    double dx, dy, w, z, s;
};

struct Plane {
    bool valid = false;
    double a = 0, b = 0, c = 0;
    double var0 = 0;    // predicted variance of the value at the centre
    double margin = 1;  // relative distance of the rank decisions to their threshold
};

// Weighted least squares Z = a dx + b dy + c over `samples`. The normal equations in the
// unknowns (c, a, b) are factorised as L D L^T, eliminating c, then a, then b; an unknown
// whose pivot is not above kRankEps x its raw second moment is dropped (set to 0): one
// column of pixels drops a, one row drops b, one pixel drops both.
Plane FitPlane(const std::vector<Sample> &samples) {
    double s0 = 0, sx = 0, sy = 0, sxx = 0, sxy = 0, syy = 0, sz = 0, sxz = 0, syz = 0, sws = 0;
    for (const Sample &p : samples) {
        s0 += p.w;
        sx += p.w * p.dx;
        sy += p.w * p.dy;
        sxx += p.w * p.dx * p.dx;
        sxy += p.w * p.dx * p.dy;
        syy += p.w * p.dy * p.dy;
        sz += p.w * p.z;
        sxz += p.w * p.dx * p.z;
        syz += p.w * p.dy * p.z;
        sws += p.w * p.w * p.s;
    }
    Plane plane;
    if (!(s0 > 0)) return plane;
    plane.valid = true;
    // Eliminate c.
    double l10 = sx / s0, l20 = sy / s0;
    double dxx = sxx - sx * l10, dxy = sxy - sy * l10, dyy = syy - sy * l20;
    double rx = sxz - sz * l10, ry = syz - sz * l20;
    auto marginOf = [](double pivot, double raw) {
        if (!(raw > 0)) return 1.0;
        return std::fabs(pivot / raw - kRankEps) / kRankEps;
    };
    bool hasA = sxx > 0 && dxx > kRankEps * sxx;
    plane.margin = std::min(plane.margin, marginOf(dxx, sxx));
    double l21 = hasA ? dxy / dxx : 0;
    double dyy2 = dyy - l21 * dxy, ry2 = ry - l21 * rx;
    bool hasB = syy > 0 && dyy2 > kRankEps * syy;
    plane.margin = std::min(plane.margin, marginOf(dyy2, syy));
    plane.b = hasB ? ry2 / dyy2 : 0;
    plane.a = hasA ? (rx - dxy * plane.b) / dxx : 0;
    plane.c = (sz - sx * plane.a - sy * plane.b) / s0;
    // q^T M^-1 q at the centre, q = (1, 0, 0): solve L u = q.
    double u1 = hasA ? -l10 : 0;
    double u2 = hasB ? -l20 - l21 * u1 : 0;
    double quad = 1 / s0 + (hasA ? u1 * u1 / dxx : 0) + (hasB ? u2 * u2 / dyy2 : 0);
    plane.var0 = sws / s0 * quad;
    return plane;
}

double Luma(const Image &pivot, int x, int y) {
    double sum = 0;
    for (int c = 0; c < pivot.channels; ++c) sum += pivot.At(c, y, x);
    return sum / pivot.channels;
}

int Quadrant(int dx, int dy) {
    return dx >= 0 ? (dy >= 0 ? 0 : 3) : (dy >= 0 ? 1 : 2);
}

bool InQuadrant(int m, int dx, int dy) {
    switch (m) {
        case 0:
            return dx >= 0 && dy >= 0;
        case 1:
            return dx <= 0 && dy >= 0;
        case 2:
            return dx <= 0 && dy <= 0;
        default:
            return dx >= 0 && dy <= 0;
    }
}

// Eq. 11 with eq. 12 written as t = 1 / w_m = (min(|Z|, |Zm|) / max(|Z|, |Zm|))^8, which
// cannot overflow: z = (t Z + Zm) / (t + 1). Opposite signs or one zero: t = 0 (Zm wins).
double Combine(double z, double zm) {
    double lo = std::min(std::fabs(z), std::fabs(zm)),
           hi = std::max(std::fabs(z), std::fabs(zm));
    double t;
    if (hi == 0)
        t = 1;
    else if (z == 0 || zm == 0 || (z > 0) != (zm > 0))
        t = 0;
    else
        t = std::pow(lo / hi, 8.0);
    return (t * z + zm) / (t + 1);
}

}  // namespace

// The gather's weight of the plain normal term beside the data term: a pixel that no centre
// takes as data (its normal shorter than theirs) still takes the fits of its surface.
constexpr double kGatherFallback = 1e-3;

double PivotNormalTerm(const Image *normal, int x, int y, int x0, int y0, bool data) {
    if (!normal) return 1;
    double n[3], n0[3], len = 0, len0 = 0;
    for (int c = 0; c < 3; ++c) {
        n[c] = normal->At(c, y, x);
        n0[c] = normal->At(c, y0, x0);
        len += n[c] * n[c];
        len0 += n0[c] * n0[c];
    }
    if (len == 0 && len0 == 0) return 1;
    if (len == 0 || len0 == 0) return 0;
    double d = (n[0] * n0[0] + n[1] * n0[1] + n[2] * n0[2]) / std::sqrt(len * len0);
    if (!(d > 0.5)) return 0;
    double term = d * d * d * d;
    // A fit's data pixel whose normal (a mean over its samples; one longer than 1 counts as
    // 1) is shorter than the centre's saw the centre's surface only in part: the term times
    // (1 - |n0|^8 (|n0| - |n|))^4, continuous in the lengths (they are sample counts'
    // fractions, and a threshold on them would tie).
    if (data) {
        double l = std::min(1.0, std::sqrt(len)), l0 = std::min(1.0, std::sqrt(len0));
        double coverage = 1 - std::pow(l0, 8) * std::max(0.0, l0 - l);
        term *= coverage * coverage * coverage * coverage;
    }
    return term;
}

double PivotIdTerm(const Image *ids, int x, int y, int x0, int y0) {
    if (!ids) return 1;
    for (int c = 0; c < ids->channels; ++c)
        if (ids->At(c, y, x) != ids->At(c, y0, x0)) return 0;
    return 1;
}

double PivotBoundaryTerm(const Image *ids, int x, int y) {
    if (!ids) return 1;
    int w = ids->width, h = ids->height;
    const int offsets[4][2] = {{-1, 0}, {1, 0}, {0, -1}, {0, 1}};
    for (const auto &o : offsets) {
        int u = x + o[0], v = y + o[1];
        if (u >= 0 && u < w && v >= 0 && v < h && PivotIdTerm(ids, u, v, x, y) == 0) return 0;
    }
    return 1;
}

PivotRatio PivotRatioOf(const Image &color, const Image &pivot, const Image *variance,
                        double floor, const Image *ids) {
    int w = color.width, h = color.height;
    PivotRatio r{Image(w, h, color.channels), Image(w, h, color.channels),
                 Image(w, h, color.channels, -1.f), Image(w, h, color.channels),
                 Image(w, h, color.channels)};
    for (int c = 0; c < color.channels; ++c) {
        double mean = 0;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) mean += std::max(0.0, double(pivot.At(c, y, x)));
        double threshold = floor * mean / (double(w) * h);
        auto zOf = [&](int x, int y) { return double(color.At(c, y, x)) / pivot.At(c, y, x); };
        // A pixel has z when its pivot is above the threshold and z stays in float's range
        // squared.
        auto valid = [&](int x, int y) {
            return double(pivot.At(c, y, x)) > threshold && std::fabs(zOf(x, y)) <= kZMax;
        };
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                if (!valid(x, y)) continue;
                // Mean, then sample variance, of z over the valid 3x3 neighbours.
                int y0 = std::max(0, y - 1), y1 = std::min(h - 1, y + 1);
                int x0 = std::max(0, x - 1), x1 = std::min(w - 1, x + 1);
                // The same values as floats, sorted after, give the edge test's level.
                double sum = 0, sumSq = 0;
                int n = 0;
                std::vector<float> values;
                for (int v = y0; v <= y1; ++v)
                    for (int u = x0; u <= x1; ++u)
                        if (valid(u, v)) {
                            sum += zOf(u, v), ++n;
                            values.push_back(float(zOf(u, v)));
                        }
                double zl = sum / n;
                for (int v = y0; v <= y1; ++v)
                    for (int u = x0; u <= x1; ++u)
                        if (valid(u, v)) sumSq += (zOf(u, v) - zl) * (zOf(u, v) - zl);
                // A pixel's variance of z from the variance input.
                auto varianceOf = [&](int u, int v) {
                    double la = pivot.At(c, v, u);
                    return std::min(double(variance->At(c, v, u)) / (la * la), kZMax * kZMax);
                };
                double s, noise = 0;
                if (variance) {
                    s = varianceOf(x, y);
                    // The edge test's noise: the mean of the valid neighbours' variances,
                    // which one pixel whose samples all missed (s = 0) does not take to 0.
                    for (int v = y0; v <= y1; ++v)
                        for (int u = x0; u <= x1; ++u)
                            if (valid(u, v)) noise += varianceOf(u, v);
                    noise /= n;
                } else {
                    s = std::min(n > 1 ? sumSq / (n - 1) : 0, kZMax * kZMax);
                    noise = s;
                }
                r.z.At(c, y, x) = float(zOf(x, y));
                r.s.At(c, y, x) = float(s);
                // The edge test's level: the median of those values (the upper one of an
                // even count).
                std::sort(values.begin(), values.end());
                r.level.At(c, y, x) = values[values.size() / 2];
                r.noise.At(c, y, x) = float(noise);
                r.nu.At(c, y, x) = float(s / std::max(zl * zl, kTiny));
                if (PivotBoundaryTerm(ids, x, y) == 0) {
                    // Beside other ids: data like any other pixel, unless it mixes in a side
                    // far from its own (a light's rim first seen as the wall, or a wall
                    // first seen as the light): then kept.
                    // Medians of z over its own ids' pixels within kSideRadius (itself
                    // among them) and over the other ids', and of the distances to its own.
                    auto medians = [&](bool own, size_t *count) {
                        std::vector<float> side, distances;
                        for (int v = std::max(0, y - kSideRadius);
                             v <= std::min(h - 1, y + kSideRadius); ++v)
                            for (int u = std::max(0, x - kSideRadius);
                                 u <= std::min(w - 1, x + kSideRadius); ++u)
                                if (valid(u, v) && (PivotIdTerm(ids, u, v, x, y) != 0) == own)
                                    side.push_back(float(zOf(u, v)));
                        *count = side.size();
                        if (side.empty()) return std::pair<double, double>{0, 0};
                        std::sort(side.begin(), side.end());
                        float median = side[side.size() / 2];
                        for (float v : side) distances.push_back(std::fabs(v - median));
                        std::sort(distances.begin(), distances.end());
                        return std::pair<double, double>{median, distances[side.size() / 2]};
                    };
                    size_t ownCount, nOther;
                    auto [median, distance] = medians(true, &ownCount);
                    auto [otherMedian, otherDistance] = medians(false, &nOther);
                    double spread = kMadSigma * std::max(distance, otherDistance);
                    double sigma2 = std::max(double(r.s.At(c, y, x)), spread * spread);
                    double gap = otherMedian - median, zHere = r.z.At(c, y, x);
                    double toward = gap > 0 ? zHere - median : median - zHere;
                    if (nOther > 0 && gap * gap > kSideGap * kSideGap * spread * spread &&
                        toward > 0 && toward * toward > kSideToward * kSideToward * sigma2) {
                        r.nu.At(c, y, x) = -1;
                        r.z.At(c, y, x) = r.s.At(c, y, x) = 0;
                    }
                }
            }
    }
    return r;
}

Image PivotFit(const PivotRatio &ratio, const PivotGuides &guides, const PivotParams &params,
               Image *margin) {
    const Image &z = ratio.z;
    int w = z.width, h = z.height, channels = z.channels;
    Image fits(w, h, kPivotPlanes * channels);
    if (margin) *margin = Image(w, h, channels, 1.f);
    // The parameters in double, as every sum below.
    const double k = params.k, sigmaWeight = params.sigmaWeight;
    const double disagreement = params.disagreement, targetNoise = params.targetNoise;
    const double good = double(params.goodNoise) * params.goodNoise;
    for (int c = 0; c < channels; ++c)
        for (int y0 = 0; y0 < h; ++y0)
            for (int x0 = 0; x0 < w; ++x0) {
                auto plane = [&](int p) -> float & {
                    return fits.At(p * channels + c, y0, x0);
                };
                double closest = 1;
                plane(15) = -1;
                // A pixel beside other ids is data to its side's fits but no centre: its
                // square, mostly of other ids, would grow far on few pixels of its own.
                if (ratio.nu.At(c, y0, x0) < 0 || PivotBoundaryTerm(guides.ids, x0, y0) == 0)
                    continue;
                // The centre's local mean of z: <z> during growth.
                double zc = 0;
                int n = 0;
                for (int v = std::max(0, y0 - 1); v <= std::min(h - 1, y0 + 1); ++v)
                    for (int u = std::max(0, x0 - 1); u <= std::min(w - 1, x0 + 1); ++u)
                        if (ratio.nu.At(c, v, u) >= 0) zc += z.At(c, v, u), ++n;
                zc /= n;
                const double centreLevel = ratio.level.At(c, y0, x0),
                             centreNoise = ratio.noise.At(c, y0, x0);
                // The pixels of the square of half-size r that may be fitted, with eq. 10's
                // weight for the given <z> and distance scale (0: no distance term).
                auto window = [&](int r, double mean, double radius) {
                    std::vector<Sample> samples;
                    for (int y = std::max(0, y0 - r); y <= std::min(h - 1, y0 + r); ++y)
                        for (int x = std::max(0, x0 - r); x <= std::min(w - 1, x0 + r); ++x) {
                            double nu = ratio.nu.At(c, y, x);
                            if (nu < 0 || nu > good) continue;
                            // The edge test in the final fit only: growth still stops
                            // where a quadrant disagrees.
                            if (radius > 0) {
                                double zq = ratio.level.At(c, y, x),
                                       sq = ratio.noise.At(c, y, x);
                                // A few float operations on stored floats, against the
                                // growth's long sums: the other terms' margin scale is far
                                // coarser than its round-off.
                                closest = std::min(
                                    closest, 100 * PivotEdgeMargin(zq, sq, centreLevel,
                                                                   centreNoise, params.edge));
                                if (PivotAcrossEdge(zq, sq, centreLevel, centreNoise,
                                                    params.edge))
                                    continue;
                            }
                            double geo = PivotNormalTerm(guides.normal, x, y, x0, y0, true) *
                                         PivotIdTerm(guides.ids, x, y, x0, y0);
                            if (geo == 0) continue;
                            double zq = z.At(c, y, x), dx = x - x0, dy = y - y0;
                            double e =
                                k * std::fabs(zq - mean) / std::max(std::fabs(mean), kTiny) +
                                sigmaWeight * nu;
                            if (radius > 0) e += (dx * dx + dy * dy) / (radius * radius);
                            if (e > kExpCut) continue;
                            samples.push_back(
                                {dx, dy, geo * std::exp(-e), zq, ratio.s.At(c, y, x)});
                        }
                    return samples;
                };
                auto fitAll = [&](const std::vector<Sample> &samples, Plane planes[5]) {
                    planes[0] = FitPlane(samples);
                    for (int m = 0; m < 4; ++m) {
                        std::vector<Sample> part;
                        for (const Sample &p : samples)
                            if (InQuadrant(m, int(p.dx), int(p.dy))) part.push_back(p);
                        planes[1 + m] = FitPlane(part);
                    }
                    for (int i = 0; i < 5; ++i) closest = std::min(closest, planes[i].margin);
                };
                // Section 4.3: grow from 5x5. A centre that would grow off its lattice (eq.
                // 13's quadrature) stops before and keeps that square's growth fits.
                int radius = 2;
                Plane planes[5];
                bool offLattice = false;
                for (int r = 2;; ++r) {
                    fitAll(window(r, zc, 0), planes);
                    bool disagree = false;
                    if (planes[0].valid) {
                        double zs = planes[0].c;
                        for (int m = 1; m < 5; ++m) {
                            if (!planes[m].valid) continue;
                            double allowed =
                                disagreement * std::fabs(zs) + 2 * std::sqrt(planes[m].var0);
                            double diff = std::fabs(zs - planes[m].c);
                            if (allowed > 0)
                                closest =
                                    std::min(closest, std::fabs(diff - allowed) / allowed);
                            disagree |= diff > allowed;
                        }
                    }
                    if (disagree) {
                        radius = std::max(2, r - 1);
                        break;
                    }
                    bool quiet = false;
                    if (planes[0].valid) {
                        double target = targetNoise * std::fabs(planes[0].c);
                        double noise = std::sqrt(planes[0].var0);
                        if (target > 0)
                            closest = std::min(closest, std::fabs(noise - target) / target);
                        quiet = noise <= target;
                    }
                    bool covers =
                        x0 - r <= 0 && y0 - r <= 0 && x0 + r >= w - 1 && y0 + r >= h - 1;
                    if (quiet || covers || r >= params.maxRadius) {
                        radius = r;
                        break;
                    }
                    // Growing to r + 1 would leave the lattice: stop at r, off it, with the
                    // radius r + 1 (how the gather tells it is off its lattice).
                    int step = PivotLatticeStep(r + 1);
                    if (x0 % step != 0 || y0 % step != 0) {
                        radius = r + 1;
                        offLattice = true;
                        break;
                    }
                }
                // The chosen square of a lattice centre, fitted with eq. 10 in full.
                if (!offLattice) {
                    double mean = 0;
                    int count = 0;
                    for (const Sample &p : window(radius, zc, 0)) mean += p.z, ++count;
                    mean /= std::max(count, 1);
                    fitAll(window(radius, mean, radius), planes);
                }
                if (margin) margin->At(c, y0, x0) = float(closest);
                if (!planes[0].valid) continue;
                for (int m = 0; m < 5; ++m) {
                    const Plane &p = planes[m].valid ? planes[m] : planes[0];
                    plane(3 * m) = float(p.a);
                    plane(3 * m + 1) = float(p.b);
                    plane(3 * m + 2) = float(p.c);
                }
                plane(15) = float(radius);
            }
    return fits;
}

int PivotLatticeStep(double radius) {
    int step = 1;
    while (step < 8 && 2 * step <= radius / 2) step *= 2;
    return step;
}

bool PivotAcrossEdge(double zq, double sq, double zc, double sc, double sigmas) {
    if (!(sigmas > 0)) return false;
    double gap = std::fabs(zq - zc);
    return gap > kPivotEdgeContrast * std::min(std::fabs(zq), std::fabs(zc)) &&
           3 * gap > sigmas * std::sqrt(sq + sc);
}

double PivotEdgeMargin(double zq, double sq, double zc, double sc, double sigmas) {
    if (!(sigmas > 0)) return 1;
    double gap = std::fabs(zq - zc), margin = 1;
    double contrast = kPivotEdgeContrast * std::min(std::fabs(zq), std::fabs(zc));
    double noise = sigmas * std::sqrt(sq + sc);
    if (contrast > 0) margin = std::min(margin, std::fabs(gap - contrast) / contrast);
    if (noise > 0) margin = std::min(margin, std::fabs(3 * gap - noise) / noise);
    return margin;
}

Image PivotGather(const Image &color, const Image &pivot, const PivotRatio &ratio,
                  const Image &fits, const PivotGuides &guides, double edge) {
    int w = color.width, h = color.height, channels = color.channels;
    Image out = color;
    int reach = 0;
    for (int c = 0; c < channels; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                reach = std::max(reach, int(fits.At(15 * channels + c, y, x)));
    for (int c = 0; c < channels; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                // Pixels without z keep their input.
                if (ratio.nu.At(c, y, x) < 0) continue;
                double sumW = 0, sumWz = 0;
                // Every centre whose square holds (x, y) (eq. 13) and that lies on its
                // lattice, standing for step^2 centres; none reaches further than the
                // largest radius.
                for (int y0 = std::max(0, y - reach); y0 <= std::min(h - 1, y + reach); ++y0)
                    for (int x0 = std::max(0, x - reach); x0 <= std::min(w - 1, x + reach);
                         ++x0) {
                        auto plane = [&](int p) -> double {
                            return fits.At(p * channels + c, y0, x0);
                        };
                        double radius = plane(15);
                        int dx = x - x0, dy = y - y0;
                        if (radius < 0 || std::abs(dx) > radius || std::abs(dy) > radius)
                            continue;
                        int step = PivotLatticeStep(radius);
                        if (x0 % step != 0 || y0 % step != 0) continue;
                        if (PivotAcrossEdge(ratio.level.At(c, y, x), ratio.noise.At(c, y, x),
                                            ratio.level.At(c, y0, x0),
                                            ratio.noise.At(c, y0, x0), edge))
                            continue;
                        double weight =
                            std::exp(-(double(dx) * dx + double(dy) * dy) / (radius * radius)) *
                            (PivotNormalTerm(guides.normal, x, y, x0, y0, true) +
                             (guides.normal ? kGatherFallback : 0) *
                                 PivotNormalTerm(guides.normal, x, y, x0, y0)) *
                            PivotIdTerm(guides.ids, x, y, x0, y0) * step * step;
                        if (weight == 0) continue;
                        int m = 1 + Quadrant(dx, dy);
                        double zs = plane(0) * dx + plane(1) * dy + plane(2);
                        double zm =
                            plane(3 * m) * dx + plane(3 * m + 1) * dy + plane(3 * m + 2);
                        sumW += weight;
                        sumWz += weight * Combine(zs, zm);
                    }
                // No lattice centre reaches the pixel (a thin part between other ids with a
                // centre of its own): its own fit at its own place, square and quadrant 0. A
                // part at most two pixels wide has no centre (each pixel is beside other
                // ids) and keeps its input.
                if (sumW == 0 && fits.At(15 * channels + c, y, x) >= 0) {
                    sumW = 1;
                    sumWz = Combine(fits.At(2 * channels + c, y, x),
                                    fits.At(5 * channels + c, y, x));
                }
                if (sumW > 0)
                    out.At(c, y, x) = FilteredValue(float(pivot.At(c, y, x) * (sumWz / sumW)),
                                                    color.At(c, y, x));
            }
    return out;
}

Image PivotBilateral(const Image &color, const Image &pivot, const PivotRatio &ratio,
                     const PivotGuides &guides, const PivotParams &params) {
    int w = color.width, h = color.height, r = params.bilateralRadius;
    const double sigmaS = std::max(0.5, r / 2.0), sigmaRange = params.sigmaRange;
    const double good = double(params.goodNoise) * params.goodNoise;
    Image out = color;
    for (int c = 0; c < color.channels; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                if (ratio.nu.At(c, y, x) < 0) continue;
                double g = Luma(pivot, x, y), sumW = 0, sumWz = 0;
                for (int v = std::max(0, y - r); v <= std::min(h - 1, y + r); ++v)
                    for (int u = std::max(0, x - r); u <= std::min(w - 1, x + r); ++u) {
                        double nu = ratio.nu.At(c, v, u);
                        if (nu < 0 || nu > good) continue;
                        double gq = Luma(pivot, u, v);
                        double rel = (gq - g) / std::max({std::fabs(g), std::fabs(gq), kTiny});
                        double d2 = double(u - x) * (u - x) + double(v - y) * (v - y);
                        double e = d2 / (2 * sigmaS * sigmaS) +
                                   rel * rel / (2 * sigmaRange * sigmaRange);
                        if (e > kExpCut) continue;
                        double weight = std::exp(-e) *
                                        PivotNormalTerm(guides.normal, u, v, x, y) *
                                        PivotIdTerm(guides.ids, u, v, x, y);
                        sumW += weight;
                        sumWz += weight * ratio.z.At(c, v, u);
                    }
                if (sumW > 0)
                    out.At(c, y, x) = FilteredValue(float(pivot.At(c, y, x) * (sumWz / sumW)),
                                                    color.At(c, y, x));
            }
    return out;
}

namespace {

// One image through ratio, fits (or the bilateral filter) and gather; its stages prefixed.
Image PivotFilterOne(const Image &color, const Image &pivot, const Image *variance,
                     const PivotGuides &guides, const PivotParams &params,
                     const std::string &prefix,
                     std::vector<std::pair<std::string, Image>> *stages) {
    PivotRatio ratio = PivotRatioOf(color, pivot, variance, double(params.floor), guides.ids);
    const bool bilateral = params.filter == mcd::PivotFilter::Bilateral;
    Image out, fits;
    if (bilateral) {
        out = PivotBilateral(color, pivot, ratio, guides, params);
    } else {
        fits = PivotFit(ratio, guides, params);
        out = PivotGather(color, pivot, ratio, fits, guides, params.edge);
    }
    if (stages) {
        stages->emplace_back(prefix + "z", std::move(ratio.z));
        stages->emplace_back(prefix + "nu", std::move(ratio.nu));
        if (!bilateral) stages->emplace_back(prefix + "fits", std::move(fits));
        stages->emplace_back(prefix + "output", out);
    }
    return out;
}

// Section 8: each partial against its own pivot, summed, plus the remainder.
Image PivotFilterSum(const PivotFilterInputs &in, const PivotParams &params,
                     std::vector<std::pair<std::string, Image>> *stages) {
    Image out(in.remainder->width, in.remainder->height, in.remainder->channels);
    for (size_t k = 0; k < in.partials.size(); ++k) {
        const PivotPartialImage &partial = in.partials[k];
        Image filtered =
            PivotFilterOne(*partial.color, *partial.pivot, partial.variance, in.guides, params,
                           "partial" + std::to_string(k) + ".", stages);
        for (size_t i = 0; i < out.Size(); ++i) out.data[i] += filtered.data[i];
    }
    // The remainder is left unfiltered (section 8).
    for (size_t i = 0; i < out.Size(); ++i) out.data[i] += in.remainder->data[i];
    return out;
}

}  // namespace

Image PivotFilter(const PivotFilterInputs &in, const PivotParams &params,
                  std::vector<std::pair<std::string, Image>> *stages) {
    return in.partials.empty() ? PivotFilterOne(*in.color, *in.pivot, in.variance, in.guides,
                                                params, "", stages)
                               : PivotFilterSum(in, params, stages);
}

}  // namespace mcd::ref
