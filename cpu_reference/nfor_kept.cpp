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

}  // namespace

void NforSmoothKept(const Image &input, const Image &features,
                    const std::vector<double> &featureWeights, const Image &mask, int r,
                    double weakAlbedo, const Image *albedo, int albedoPlanes, Image *output,
                    bool keptPixels) {
    if (r <= 0) return;
    Image o = *output;
    for (int y = 0; y < o.height; ++y)
        for (int x = 0; x < o.width; ++x) {
            bool weak = Weak(mask, albedo, weakAlbedo, x, y);
            if (!weak && (!keptPixels || !Kept(input, o, mask, r, x, y))) continue;
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
                        double wq = std::exp(-e);
                        num += wq * o.At(c, v, u);
                        den += wq;
                    }
                if (den > 0) output->At(c, y, x) = float(num / den);
            }
        }
}

}  // namespace mcd::ref
