#include "cpu_reference/nfor_band.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace mcd::ref {

namespace {

double Max(const Image &image, int y, int x) {
    double m = -INFINITY;
    for (int c = 0; c < image.channels; ++c) m = std::max(m, double(image.At(c, y, x)));
    return m;
}

double LuminanceOf(const double *v, int channels) {
    return channels < 3 ? v[0] : 0.2126 * v[0] + 0.7152 * v[1] + 0.0722 * v[2];
}

}  // namespace

size_t NforSmoothGlintBands(const Image &albedo, const Image *alpha, int radius, double sigma,
                            double tensorSigma, double bound, double glintAlbedo, int reach,
                            double emitterAlbedo, Image *output) {
    const int w = output->width, h = output->height, channels = std::min(output->channels, 4);
    if (radius == 0) return 0;
    const Image in = *output;
    auto pixel = [&](int y, int x, double *v) {
        for (int c = 0; c < channels; ++c) v[c] = in.At(c, y, x);
    };
    auto logLum = [&](int y, int x) {
        double v[4] = {0, 0, 0, 0};
        pixel(y, x, v);
        return std::log(std::max(LuminanceOf(v, channels), 0.0) + 0.01);
    };
    auto gradient = [&](int y, int x, double *gx, double *gy) {
        const int x0 = std::max(x - 1, 0), x1 = std::min(x + 1, w - 1);
        const int y0 = std::max(y - 1, 0), y1 = std::min(y + 1, h - 1);
        *gx = x1 > x0 ? (logLum(y, x1) - logLum(y, x0)) / (x1 - x0) : 0;
        *gy = y1 > y0 ? (logLum(y1, x) - logLum(y0, x)) / (y1 - y0) : 0;
    };
    const int tr = int(3 * tensorSigma) + 1;
    std::vector<double> g(2 * tr + 1);
    double gsum = 0;
    for (int k = -tr; k <= tr; ++k)
        gsum += g[k + tr] = std::exp(-k * k / (2 * tensorSigma * tensorSigma));
    // 1 for an emitter or an empty pixel: neither moves nor gives.
    auto emitter = [&](int y, int x) {
        const bool empty = alpha && !(alpha->At(0, y, x) > 0);
        return empty || Max(albedo, y, x) > emitterAlbedo ? 1.0 : 0.0;
    };
    auto finite = [&](const double *v) {
        for (int c = 0; c < channels; ++c)
            if (!std::isfinite(v[c])) return false;
        return true;
    };
    // Bilinear, the position held inside the frame, the taps past its last row or column
    // reading that row or column.
    auto bilinear = [&](auto at, double x, double y) {
        x = std::clamp(x, 0.0, double(w - 1));
        y = std::clamp(y, 0.0, double(h - 1));
        const int x0 = int(std::floor(x)), y0 = int(std::floor(y));
        const double fx = x - x0, fy = y - y0;
        auto tap = [&](int v, int u) { return at(std::min(v, h - 1), std::min(u, w - 1)); };
        return tap(y0, x0) * (1 - fx) * (1 - fy) + tap(y0, x0 + 1) * fx * (1 - fy) +
               tap(y0 + 1, x0) * (1 - fx) * fy + tap(y0 + 1, x0 + 1) * fx * fy;
    };
    size_t moved = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            bool near = false;
            for (int v = std::max(0, y - reach); v <= std::min(h - 1, y + reach) && !near; ++v)
                for (int u = std::max(0, x - reach); u <= std::min(w - 1, x + reach) && !near;
                     ++u)
                    near = Max(albedo, v, u) > glintAlbedo;
            if (!near || emitter(y, x) > 0) continue;
            double jxx = 0, jxy = 0, jyy = 0;
            for (int dy = -tr; dy <= tr; ++dy)
                for (int dx = -tr; dx <= tr; ++dx) {
                    double gx, gy;
                    gradient(std::clamp(y + dy, 0, h - 1), std::clamp(x + dx, 0, w - 1), &gx,
                             &gy);
                    const double wt = g[dy + tr] * g[dx + tr] / (gsum * gsum);
                    jxx += wt * gx * gx;
                    jxy += wt * gx * gy;
                    jyy += wt * gy * gy;
                }
            const double trace = jxx + jyy;
            const double d = std::sqrt((jxx - jyy) * (jxx - jyy) + 4 * jxy * jxy);
            const double l1 = (trace + d) / 2, l2 = (trace - d) / 2;
            const double vx = jxy, vy = l1 - jxx, norm = std::hypot(vx, vy);
            if (!(trace > 0) || !(norm > 0)) continue;
            const double tx = -vy / norm, ty = vx / norm;
            const double coherence = ((l1 - l2) / trace) * ((l1 - l2) / trace);
            if (!(coherence > 0)) continue;
            double own[4] = {0, 0, 0, 0};
            pixel(y, x, own);
            if (!finite(own)) continue;
            const double ownLum = std::max(LuminanceOf(own, channels), 0.0);
            double mean[4] = {0, 0, 0, 0}, weights = 0;
            for (int k = -radius; k <= radius; ++k) {
                const double px = x + k * tx, py = y + k * ty;
                const double weight =
                    std::exp(-k * k / (2 * sigma * sigma)) * (1 - bilinear(emitter, px, py));
                if (!(weight > 0)) continue;
                double s[4] = {0, 0, 0, 0};
                for (int c = 0; c < channels; ++c)
                    s[c] =
                        bilinear([&](int v, int u) { return double(in.At(c, v, u)); }, px, py);
                if (!finite(s)) continue;
                const double lum = LuminanceOf(s, channels);
                const double held = std::clamp(lum, ownLum / bound, ownLum * bound + 0.01);
                for (int c = 0; c < channels; ++c)
                    mean[c] += weight * s[c] * (lum > 0 ? held / lum : 0);
                weights += weight;
            }
            if (!(weights > 0)) continue;
            for (int c = 0; c < channels; ++c)
                output->At(c, y, x) = float(own[c] + coherence * (mean[c] / weights - own[c]));
            ++moved;
        }
    return moved;
}

}  // namespace mcd::ref
