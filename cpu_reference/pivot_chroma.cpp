#include "cpu_reference/pivot_chroma.h"

#include <cmath>
#include <vector>

#include "cpu_reference/local_mean.h"

namespace mcd::ref {
namespace {

// noise(a, v) of the header.
double Noise(const std::vector<double> &a, const std::vector<double> &v) {
    double total = 0;
    for (double x : a) total += x;
    double noise = 0;
    for (size_t c = 0; c < a.size(); ++c) {
        const double k = a[c] / total;
        double others = 0;
        for (size_t j = 0; j < a.size(); ++j)
            if (j != c) others += v[j];
        noise += std::sqrt(v[c] * (1 - k) * (1 - k) + k * k * others);
    }
    return noise / total;
}

double Sum(const std::vector<double> &a) {
    double s = 0;
    for (double x : a) s += x;
    return s;
}

// ramp(d, a, lo, hi) of the header: 0 up to lo a, 1 from hi a, linear between.
double Ramp(double d, double a, double lo, double hi) {
    if (d <= lo * a) return 0;
    if (d >= hi * a) return 1;
    return (d - lo * a) / ((hi - lo) * a);
}

// sum_c |a_c / sum a - b_c / sum b|.
double Distance(const std::vector<double> &a, const std::vector<double> &b) {
    const double sa = Sum(a), sb = Sum(b);
    double d = 0;
    for (size_t c = 0; c < a.size(); ++c) d += std::fabs(a[c] / sa - b[c] / sb);
    return d;
}

}  // namespace

size_t KeepWindowChroma(const Image &color, const Image &pivot, const Image &variance,
                        const Image *objectId, const Image *partId, double bound,
                        Image *output) {
    const int w = color.width, h = color.height, n = color.channels;
    if (n < 2) return 0;
    auto at = [](const Image &image, int c, int y, int x) {
        return double(image.At(image.channels == 1 ? 0 : c, y, x));
    };
    auto usable = [&](int y, int x) {
        for (int c = 0; c < n; ++c) {
            const double v = at(color, c, y, x), s = at(variance, c, y, x),
                         p = at(pivot, c, y, x);
            if (!std::isfinite(v) || !std::isfinite(s) || !std::isfinite(p) || s < 0 || p < 0)
                return false;
        }
        return true;
    };
    size_t moved = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            std::vector<double> o(n), in(n), inVar(n);
            bool differs = false;
            for (int c = 0; c < n; ++c) {
                o[c] = output->At(c, y, x), in[c] = color.At(c, y, x);
                inVar[c] = at(variance, c, y, x);
                differs |= o[c] != in[c];
            }
            if (!differs || !std::isfinite(Sum(o)) || !(Sum(o) > 0) || !usable(y, x)) continue;
            std::vector<double> s(n, 0), g(n, 0), u(n, 0);
            for (int yy = y - 2; yy <= y + 2; ++yy)
                for (int xx = x - 2; xx <= x + 2; ++xx) {
                    if (xx < 0 || yy < 0 || xx >= w || yy >= h || !usable(yy, xx)) continue;
                    if (objectId && objectId->At(0, yy, xx) != objectId->At(0, y, x)) continue;
                    if (partId && partId->At(0, yy, xx) != partId->At(0, y, x)) continue;
                    for (int c = 0; c < n; ++c) {
                        s[c] += at(color, c, yy, xx);
                        g[c] += at(pivot, c, yy, xx);
                        u[c] += at(variance, c, yy, xx);
                    }
                }
            std::vector<double> e(n), ue(n);
            bool defined = true;
            for (int c = 0; c < n; ++c) {
                const double own = at(pivot, c, y, x);
                defined &= own > 0 && g[c] > 0;
                e[c] = own * s[c] / g[c];
                ue[c] = own * own * u[c] / (g[c] * g[c]);
            }
            if (!defined || !(Sum(e) > 0)) continue;
            double w = Ramp(Distance(o, e), Noise(e, ue), 1.5, 5);
            if (Sum(in) > 0) w *= 1 - Ramp(Distance(in, e), Noise(in, inVar), 2, 4);
            if (Sum(inVar) > 0)
                w *= 1 -
                     Ramp(std::fabs(Sum(e) - Sum(in)), std::sqrt(Sum(inVar) + Sum(ue)), 2, 4);
            if (!(w > 0)) continue;
            const double total = Sum(o), eTotal = Sum(e);
            std::vector<double> mended(n);
            bool held = true;
            for (int c = 0; c < n; ++c) {
                const float target = float(total * (e[c] / eTotal));
                const double spread = NoiseSpread(variance, c, x, y);
                held &= target >= 0 && !(bound > 0 && spread >= 0 &&
                                         std::fabs(target - in[c]) > bound * spread);
                mended[c] = o[c] + w * (target - o[c]);
            }
            if (!held) continue;
            for (int c = 0; c < n; ++c) output->At(c, y, x) = float(mended[c]);
            ++moved;
        }
    return moved;
}

}  // namespace mcd::ref
