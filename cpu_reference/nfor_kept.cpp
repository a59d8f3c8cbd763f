#include "cpu_reference/nfor_kept.h"

#include <algorithm>
#include <cmath>

namespace mcd::ref {

namespace {

bool Same(const Image &input, const Image &output, int x, int y) {
    for (int c = 0; c < input.channels; ++c) {
        double i = input.At(c, y, x), o = output.At(c, y, x);
        if (!std::isfinite(i) || !std::isfinite(o)) return false;
        if (std::fabs(o - i) > 1e-3 * std::fabs(i) + 1e-6) return false;
    }
    return true;
}

bool Kept(const Image &input, const Image &output, const Image &mask, int r, int x, int y) {
    if (mask.At(0, y, x) != 1 || !Same(input, output, x, y)) return false;
    bool above = false;
    for (int c = 0; c < input.channels; ++c)
        if (input.At(c, y, x) > 1e-4) above = true;
    if (!above) return false;
    for (int dy = -r; dy <= r; ++dy)
        for (int dx = -r; dx <= r; ++dx) {
            int u = x + dx, v = y + dy;
            if ((dx == 0 && dy == 0) || u < 0 || v < 0 || u >= input.width || v >= input.height)
                continue;
            if (mask.At(0, v, u) == 1 && !Same(input, output, u, v)) return true;
        }
    return false;
}

}  // namespace

namespace {

// Whether (x, y) is an emitter smoothed with the kept pixels.
bool Weak(const Image &mask, const Image *albedo, double weakAlbedo, int x, int y) {
    if (mask.At(0, y, x) != 0 || weakAlbedo <= 0 || !albedo) return false;
    double most = 0;
    for (int c = 0; c < albedo->channels; ++c)
        most = std::max(most, double(albedo->At(c, y, x)));
    return most < weakAlbedo;
}

// S: the positive parts of (x, y)'s channels in o, summed; 0 where one is not finite.
double Positive(const Image &o, int x, int y) {
    double s = 0;
    for (int c = 0; c < o.channels; ++c) {
        double v = o.At(c, y, x);
        if (!std::isfinite(v)) return 0;
        s += v > 0 ? v : 0;
    }
    return s;
}

bool OnLine(const Image &o, double ratio, int x, int y) {
    if (!(ratio > 0)) return false;
    const int dirs[4][2] = {{1, 0}, {0, 1}, {1, 1}, {1, -1}};
    for (const auto &d : dirs) {
        int sides = 0;
        for (int side : {-1, 1}) {
            bool found = false;
            for (int k = 1; k <= 2; ++k) {
                int u = x + side * k * d[0], v = y + side * k * d[1];
                if (u < 0 || v < 0 || u >= o.width || v >= o.height) continue;
                if (Positive(o, u, v) >= ratio * Positive(o, x, y)) found = true;
            }
            sides += found;
        }
        if (sides == 2) return true;
    }
    return false;
}

}  // namespace

void NforSmoothKept(const Image &input, const Image &features,
                    const std::vector<double> &featureWeights, const Image &mask, int r,
                    double weakAlbedo, const Image *albedo, int albedoPlanes, Image *output,
                    bool keptPixels, double lineRatio, double lineRange) {
    if (r <= 0) return;
    Image o = *output;
    for (int y = 0; y < o.height; ++y)
        for (int x = 0; x < o.width; ++x) {
            bool weak = Weak(mask, albedo, weakAlbedo, x, y);
            if (!weak && (!keptPixels || !Kept(input, o, mask, r, x, y))) continue;
            bool line = weak && OnLine(o, lineRatio, x, y);
            for (int c = 0; c < o.channels; ++c) {
                double num = 0, den = 0;
                for (int dy = -r; dy <= r; ++dy)
                    for (int dx = -r; dx <= r; ++dx) {
                        int u = x + dx, v = y + dy;
                        if (u < 0 || v < 0 || u >= o.width || v >= o.height) continue;
                        bool weakQ = Weak(mask, albedo, weakAlbedo, u, v);
                        if (mask.At(0, v, u) != 1 && !weakQ) continue;
                        if ((dx != 0 || dy != 0) && !weakQ && Kept(input, o, mask, r, u, v))
                            continue;
                        bool finite = true;
                        for (int k = 0; k < o.channels; ++k)
                            if (!std::isfinite(o.At(k, v, u))) finite = false;
                        if (!finite) continue;
                        double e = double(dx * dx + dy * dy) / (0.5 * r * r);
                        for (int j = weak ? albedoPlanes : 0;
                             j < int(featureWeights.size()) && j < features.channels; ++j) {
                            double d = featureWeights[size_t(j)] *
                                       (double(features.At(j, v, u)) - features.At(j, y, x));
                            e += d * d;
                        }
                        if (line) {
                            double n = o.channels;
                            double l = std::log((Positive(o, u, v) / n + 0.01) /
                                                (Positive(o, x, y) / n + 0.01));
                            e += l * l / (2 * lineRange * lineRange);
                        }
                        double wq = std::exp(-e);
                        num += wq * o.At(c, v, u);
                        den += wq;
                    }
                if (den > 0) output->At(c, y, x) = float(num / den);
            }
        }
}

}  // namespace mcd::ref
