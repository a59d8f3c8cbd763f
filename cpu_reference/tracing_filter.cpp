#include "cpu_reference/tracing_filter.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "host/error.h"

namespace mcd::ref {
namespace {

constexpr double kPi = 3.14159265358979323846;

double Dot3(const float a[3], const double b[3]) {
    return double(a[0]) * b[0] + double(a[1]) * b[1] + double(a[2]) * b[2];
}

// Density of the von Mises-Fisher lobe of concentration kappa around unit `axis`.
double Vmf(double cosToAxis, double kappa) {
    if (kappa <= 0) return 1 / (4 * kPi);
    return kappa / (2 * kPi * -std::expm1(-2 * kappa)) * std::exp(kappa * (cosToAxis - 1));
}

// The mirror direction of the camera ray about n: reflect(-wo, n) = 2 (wo.n) n - wo.
void MirrorAxis(const TracingSurface &s, double axis[3]) {
    double wn = double(s.wo[0]) * s.normal[0] + double(s.wo[1]) * s.normal[1] +
                double(s.wo[2]) * s.normal[2];
    for (int c = 0; c < 3; ++c) axis[c] = 2 * wn * s.normal[c] - s.wo[c];
}

// The scalar lobe of eq. 17's F: `material`'s channel-mean weights on `geometry`'s normal
// and view direction.
double ScalarLobe(const TracingSurface &material, const TracingSurface &geometry,
                  const double u[3]) {
    double cosN = Dot3(geometry.normal, u);
    if (cosN <= 0) return 0;
    double d = (double(material.diffuse[0]) + material.diffuse[1] + material.diffuse[2]) / 3;
    double g = (double(material.glossy[0]) + material.glossy[1] + material.glossy[2]) / 3;
    double axis[3];
    MirrorAxis(geometry, axis);
    double cosAxis = axis[0] * u[0] + axis[1] * u[1] + axis[2] * u[2];
    return d * cosN / kPi + g * Vmf(cosAxis, material.kappa);
}

}  // namespace

void TracingBsdfCos(const TracingSurface &s, const double u[3], double out[3]) {
    double cosN = Dot3(s.normal, u);
    if (cosN <= 0) {
        out[0] = out[1] = out[2] = 0;
        return;
    }
    double axis[3];
    MirrorAxis(s, axis);
    double vmf = Vmf(axis[0] * u[0] + axis[1] * u[1] + axis[2] * u[2], s.kappa);
    for (int c = 0; c < 3; ++c) out[c] = s.diffuse[c] * cosN / kPi + s.glossy[c] * vmf;
}

std::vector<float> TracingFilter(const TracingRecords &records, const TracingParams &params,
                                 int outY0, int outRows, std::vector<float> *magnitude) {
    const int width = records.width, spp = records.spp;
    if (width <= 0 || records.rows <= 0 || spp <= 0 ||
        records.surfaces.size() != size_t(width) * records.rows ||
        records.samples.size() != records.surfaces.size() * spp)
        throw Error("tracing records: sizes do not match width x rows x spp",
                    ErrorKind::Internal);
    if (outRows <= 0 || outY0 < records.y0 || outY0 + outRows > records.y0 + records.rows)
        throw Error("tracing filter: output rows " + std::to_string(outY0) + ".." +
                        std::to_string(outY0 + outRows) + " are not inside the records' rows",
                    ErrorKind::Internal);
    auto finiteNonNegative = [](float v) { return std::isfinite(v) && v >= 0; };
    if (params.radius < 0 || !finiteNonNegative(params.alpha) ||
        !finiteNonNegative(params.beta) || !finiteNonNegative(params.gamma) ||
        !finiteNonNegative(params.selfFloor) || params.selfFloor > 1)
        throw Error(
            "tracing filter: radius, alpha, beta, gamma must be finite and >= 0, selfFloor "
            "in [0, 1]",
            ErrorKind::InvalidArgument);
    // A disk past the records' diagonal holds the same neighbours (and radius^2 fits an int).
    const int radius = std::min(params.radius, width + records.rows);
    std::vector<float> out(size_t(width) * outRows * 3, 0.f);
    if (magnitude) magnitude->assign(out.size(), 0.f);
    auto surfaceAt = [&](int x, int y) -> const TracingSurface & {
        return records.surfaces[size_t(y - records.y0) * width + x];
    };
    auto sampleAt = [&](int x, int y, int s) -> const TracingSample & {
        return records.samples[(size_t(y - records.y0) * width + x) * spp + s];
    };

    struct Neighbour {
        int x, y;
        double fixed;
    };
    std::vector<Neighbour> neighbours;
    for (int y = outY0; y < outY0 + outRows; ++y) {
        for (int x = 0; x < width; ++x) {
            const TracingSurface &p = surfaceAt(x, y);
            double sum[3] = {0, 0, 0};
            if (!(p.valid > 0)) {
                // Nothing to filter: the plain mean of the pixel's own values.
                double size[3] = {0, 0, 0};
                for (int s = 0; s < spp; ++s)
                    for (int c = 0; c < 3; ++c) {
                        sum[c] += sampleAt(x, y, s).own[c];
                        size[c] += std::abs(double(sampleAt(x, y, s).own[c]));
                    }
                for (int c = 0; c < 3; ++c) {
                    out[(size_t(y - outY0) * width + x) * 3 + c] = float(sum[c] / spp);
                    if (magnitude)
                        (*magnitude)[(size_t(y - outY0) * width + x) * 3 + c] =
                            float(size[c] / spp);
                }
                continue;
            }
            // The fixed part of eq. 17 for every neighbour, and C_p from its sum.
            neighbours.clear();
            double fixedSum = 0;
            for (int dy = -radius; dy <= radius; ++dy) {
                int ny = y + dy;
                if (ny < records.y0 || ny >= records.y0 + records.rows) continue;
                for (int dx = -radius; dx <= radius; ++dx) {
                    int nx = x + dx, d2 = dx * dx + dy * dy;
                    if ((dx == 0 && dy == 0) || d2 > radius * radius || nx < 0 || nx >= width)
                        continue;
                    const TracingSurface &q = surfaceAt(nx, ny);
                    if (!(q.valid > 0)) continue;
                    double nn = double(p.normal[0]) * q.normal[0] +
                                double(p.normal[1]) * q.normal[1] +
                                double(p.normal[2]) * q.normal[2];
                    double fixed = std::exp(-double(params.alpha) * d2) *
                                   std::exp(-double(params.beta) * (1 - nn));
                    neighbours.push_back({nx, ny, fixed});
                    fixedSum += fixed;
                }
            }
            double scale =
                fixedSum > 0 ? std::min(1.0, double(params.selfFloor) / fixedSum) : 1;
            // w(p <- p', u) of eq. 17, including Theta(u . n') through F.
            auto weight = [&](const Neighbour &n, const double u[3]) {
                const TracingSurface &q = surfaceAt(n.x, n.y);
                double here = ScalarLobe(p, p, u), there = ScalarLobe(p, q, u);
                if (!(here > 0) || !(there > 0)) return 0.0;
                // gamma 0 leaves the variable part 1 (0 x an infinite F would be NaN).
                if (params.gamma == 0) return scale * n.fixed;
                double ratio = there / here, f = std::max(ratio, 1 / ratio);
                return scale * n.fixed * std::exp(-double(params.gamma) * f * f);
            };
            // The sum of the terms' sizes (for the error bound of a float twin): |own|, not
            // |self own|, since self's error is absolute; a lent term at its weight's bound
            // C_p x fixed part, since exp(-gamma F^2)'s error is at most that times F's.
            double size[3] = {0, 0, 0};
            // Eq. 16: the pixel's own samples, each with its self weight.
            for (int s = 0; s < spp; ++s) {
                const TracingSample &own = sampleAt(x, y, s);
                double self = 1;
                if (own.pdf > 0) {
                    double u[3] = {own.direction[0], own.direction[1], own.direction[2]};
                    // A neighbour lends from the share of its samples that reach a
                    // surface (`valid`): the self weight gives up that share of w.
                    for (const Neighbour &n : neighbours)
                        self -= double(surfaceAt(n.x, n.y).valid) * weight(n, u);
                }
                for (int c = 0; c < 3; ++c) {
                    // A non-finite own value passes alone (self x inf would be NaN or -inf
                    // for a self weight rounded to 0 or below).
                    double kept = std::isfinite(own.own[c]) ? self * own.own[c] : own.own[c];
                    sum[c] += kept / spp;
                    size[c] += std::abs(double(own.own[c])) / spp;
                }
            }
            // Eq. 15's sum over the neighbours: their samples re-weighted for p (eq. 14).
            for (const Neighbour &n : neighbours) {
                for (int s = 0; s < spp; ++s) {
                    const TracingSample &t = sampleAt(n.x, n.y, s);
                    if (!(t.pdf > 0) || !std::isfinite(t.pdf) ||
                        !std::isfinite(t.radiance[0]) || !std::isfinite(t.radiance[1]) ||
                        !std::isfinite(t.radiance[2]))
                        continue;
                    double u[3] = {t.direction[0], t.direction[1], t.direction[2]};
                    double w = weight(n, u);
                    if (w == 0) continue;
                    double fcos[3];
                    TracingBsdfCos(p, u, fcos);
                    for (int c = 0; c < 3; ++c) {
                        sum[c] += w * fcos[c] * t.radiance[c] / (double(t.pdf) * spp);
                        size[c] += scale * n.fixed * std::abs(fcos[c] * t.radiance[c]) /
                                   (double(t.pdf) * spp);
                    }
                }
            }
            for (int c = 0; c < 3; ++c) {
                out[(size_t(y - outY0) * width + x) * 3 + c] = float(sum[c]);
                if (magnitude)
                    (*magnitude)[(size_t(y - outY0) * width + x) * 3 + c] = float(size[c]);
            }
        }
    }
    return out;
}

}  // namespace mcd::ref
