#include "cpu_reference/nfor_line.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace mcd::ref {

namespace {

// A plane of doubles the size of the frame.
struct Grid {
    int w = 0, h = 0;
    std::vector<double> v;
    Grid(int width, int height) : w(width), h(height), v(size_t(width) * height, 0.0) {}
    double &operator()(int x, int y) { return v[size_t(y) * w + x]; }
    double operator()(int x, int y) const { return v[size_t(y) * w + x]; }
    // The value at a mirrored position (d c b | a b c d).
    double Mirrored(int x, int y) const { return (*this)(Fold(x, w), Fold(y, h)); }
    static int Fold(int i, int n) {
        if (n < 2) return 0;
        while (i < 0 || i >= n) i = i < 0 ? -i : 2 * (n - 1) - i;
        return i;
    }
    // Bilinear interpolation, 0 outside.
    double Sample(double px, double py) const {
        int x = int(std::floor(px)), y = int(std::floor(py));
        double fx = px - std::floor(px), fy = py - std::floor(py);
        auto get = [&](int u, int t) {
            if (u < 0 || t < 0 || u >= w || t >= h) return 0.0;
            return (*this)(u, t);
        };
        return get(x, y) * (1 - fx) * (1 - fy) + get(x + 1, y) * fx * (1 - fy) +
               get(x, y + 1) * (1 - fx) * fy + get(x + 1, y + 1) * fx * fy;
    }
};

Grid Gaussian(const Grid &in, double sigma) {
    int r = int(std::ceil(3 * sigma));
    std::vector<double> k;
    double norm = 0;
    for (int i = -r; i <= r; ++i) {
        k.push_back(std::exp(-i * i / (2 * sigma * sigma)));
        norm += k.back();
    }
    for (double &e : k) e /= norm;
    Grid horizontal(in.w, in.h), out(in.w, in.h);
    for (int y = 0; y < in.h; ++y)
        for (int x = 0; x < in.w; ++x)
            for (int i = -r; i <= r; ++i)
                horizontal(x, y) += k[size_t(i + r)] * in.Mirrored(x + i, y);
    for (int y = 0; y < in.h; ++y)
        for (int x = 0; x < in.w; ++x)
            for (int i = -r; i <= r; ++i)
                out(x, y) += k[size_t(i + r)] * horizontal.Mirrored(x, y + i);
    return out;
}

double Lum709(const Image &image, int x, int y) {
    if (image.channels < 3) return image.At(0, y, x);
    return 0.2126 * image.At(0, y, x) + 0.7152 * image.At(1, y, x) + 0.0722 * image.At(2, y, x);
}

// The smoothed luminance and its structure tensor's planes.
struct Structure {
    Grid smooth, xx, yy, xy;
    // The line's direction (ax, ay) and across it (nx, ny) at a pixel.
    void Direction(int x, int y, double *ax, double *ay, double *nx, double *ny) const {
        double angle = 0.5 * std::atan2(2 * xy(x, y), xx(x, y) - yy(x, y));
        *nx = std::cos(angle), *ny = std::sin(angle);
        *ax = -*ny, *ay = *nx;
    }
    // Whether the tensor's coherence is above 0.
    bool Coherent(int x, int y) const {
        double trace = xx(x, y) + yy(x, y), d = xx(x, y) - yy(x, y);
        if (!(trace > 0)) return false;
        double disc = std::sqrt(std::max(d * d / 4 + xy(x, y) * xy(x, y), 0.0));
        double c = 2 * disc / std::max(trace, 1e-30);
        return c * c > 0;
    }
};

Structure StructureOf(const Grid &L) {
    const int w = L.w, h = L.h;
    const Grid Ls = Gaussian(L, 1);
    Grid gxx(w, h), gyy(w, h), gxy(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            double gx = 0, gy = 0;
            if (w > 1) {
                int a = std::max(x - 1, 0), b = std::min(x + 1, w - 1);
                gx = (Ls(b, y) - Ls(a, y)) / (b - a);
            }
            if (h > 1) {
                int a = std::max(y - 1, 0), b = std::min(y + 1, h - 1);
                gy = (Ls(x, b) - Ls(x, a)) / (b - a);
            }
            gxx(x, y) = gx * gx, gyy(x, y) = gy * gy, gxy(x, y) = gx * gy;
        }
    return {Ls, Gaussian(gxx, 3), Gaussian(gyy, 3), Gaussian(gxy, 3)};
}

// A grid's mean over the 5 steps -2..2 along the pixel's line.
double LineMean(const Structure &st, const Grid &g, int x, int y) {
    double ax, ay, nx, ny, sum = 0;
    st.Direction(x, y, &ax, &ay, &nx, &ny);
    for (int t = -2; t <= 2; ++t) sum += g.Sample(x + t * ax, y + t * ay);
    return sum / 5;
}

// Each pixel adds of what it was given the share that lifts its output's luminance at most
// to Lin's mean along its line.
void AddCapped(const std::vector<Grid> &given, const Structure &st, const Grid &Lin,
               Image *output) {
    const int ch = output->channels;
    for (int y = 0; y < output->height; ++y)
        for (int x = 0; x < output->width; ++x) {
            double got = ch >= 3 ? 0.2126 * given[0](x, y) + 0.7152 * given[1](x, y) +
                                       0.0722 * given[2](x, y)
                                 : given[0](x, y);
            if (!(got > 0)) continue;
            double out = Lum709(*output, x, y);
            if (!std::isfinite(out)) continue;
            double share = std::min(
                1.0, std::max(LineMean(st, Lin, x, y) - out, 0.0) / std::max(got, 1e-12));
            for (int c = 0; c < ch; ++c)
                output->At(c, y, x) =
                    float(double(output->At(c, y, x)) + given[size_t(c)](x, y) * share);
        }
}

}  // namespace

int NforSpreadLine(const Image &color, const Image &clamped, const Image &albedo,
                   const Image *alpha, double lightAlbedo, int gateReach, double ratio,
                   int radius, Image *output) {
    const int w = color.width, h = color.height, ch = color.channels;
    if (!(lightAlbedo > 0)) return 0;
    auto isLight = [&](int x, int y) {
        for (int c = 0; c < albedo.channels; ++c)
            if (albedo.At(c, y, x) > lightAlbedo) return true;
        return false;
    };
    bool anyLight = false;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) anyLight = anyLight || isLight(x, y);
    if (!anyLight) return 0;
    Grid L(w, h), Lpos(w, h), Lin(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            double l = Lum709(clamped, x, y), li = Lum709(color, x, y);
            L(x, y) = std::isfinite(l) ? l : 0;
            Lpos(x, y) = std::max(L(x, y), 0.0);
            Lin(x, y) = std::isfinite(li) ? li : 0;
        }
    const Structure st = StructureOf(L);
    const Grid &Ls = st.smooth;
    auto present = [&](int x, int y) { return !alpha || alpha->At(0, y, x) > 0.f; };
    auto nearLight = [&](int x, int y) {
        for (int v = std::max(0, y - gateReach); v <= std::min(h - 1, y + gateReach); ++v)
            for (int u = std::max(0, x - gateReach); u <= std::min(w - 1, x + gateReach); ++u)
                if (isLight(u, v)) return true;
        return false;
    };
    std::vector<Grid> given(size_t(ch), Grid(w, h));
    int givers = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            if (!present(x, y) || !nearLight(x, y)) continue;
            std::vector<double> r(size_t(ch), 0.0);
            bool ok = true;
            double rsum = 0;
            for (int c = 0; c < ch; ++c) {
                r[size_t(c)] = std::max(double(color.At(c, y, x)) - clamped.At(c, y, x), 0.0);
                ok = ok && std::isfinite(r[size_t(c)]);
                rsum += r[size_t(c)];
            }
            if (!ok || !(rsum > 0) || !st.Coherent(x, y)) continue;
            double ax, ay, nx, ny;
            st.Direction(x, y, &ax, &ay, &nx, &ny);
            double along = 0;
            for (int t : {-2, -1, 1, 2}) along += Ls.Sample(x + t * ax, y + t * ay);
            double across =
                (Ls.Sample(x - 2 * nx, y - 2 * ny) + Ls.Sample(x + 2 * nx, y + 2 * ny)) / 2;
            if (!(along / 4 > ratio * across)) continue;
            // Targets in the order first reached, weights of a repeated one summed.
            std::vector<int> tx, ty;
            std::vector<double> tw;
            for (int t = -radius; t <= radius; ++t)
                for (int b = -1; b <= 1; ++b) {
                    int u = int(std::nearbyint(x + t * ax + b * nx));
                    int v = int(std::nearbyint(y + t * ay + b * ny));
                    if (u < 0 || v < 0 || u >= w || v >= h || !present(u, v)) continue;
                    double weight = (radius + 1 - std::abs(t)) *
                                    std::exp(-b * b / (2 * 0.7 * 0.7)) *
                                    std::max(LineMean(st, Lpos, u, v), 0.0);
                    size_t k = 0;
                    while (k < tx.size() && !(tx[k] == u && ty[k] == v)) ++k;
                    if (k == tx.size()) {
                        tx.push_back(u), ty.push_back(v), tw.push_back(weight);
                    } else {
                        tw[k] += weight;
                    }
                }
            double total = 0;
            for (double e : tw) total += e;
            if (!(total > 0)) continue;
            for (size_t k = 0; k < tx.size(); ++k)
                for (int c = 0; c < ch; ++c)
                    given[size_t(c)](tx[k], ty[k]) += r[size_t(c)] * tw[k] / total;
            ++givers;
        }
    AddCapped(given, st, Lin, output);
    return givers;
}

}  // namespace mcd::ref
