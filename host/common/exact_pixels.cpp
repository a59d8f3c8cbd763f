#include "host/common/exact_pixels.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "host/error.h"

namespace mcd {

namespace {

// One channel's return of energy (exact_pixels.h): `exact` marks the exact values, `moved` is
// the method's output before they were reset.
void ReturnEnergy(const float *in, const float *moved, const std::vector<char> &exact, int w,
                  int h, int reach, float *out) {
    const size_t n = size_t(w) * h;
    std::vector<double> gain(n, 0), loss(n, 0);  // what each value gets back, each way
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            size_t p = size_t(y) * w + x;
            double e = exact[p] ? double(moved[p]) - in[p] : 0;
            if (!(e != 0 && std::isfinite(e))) continue;
            // The values the method moved the other way: lowered ones for energy it put here.
            auto weight = [&](size_t q) {
                double d = e > 0 ? double(in[q]) - moved[q] : double(moved[q]) - in[q];
                return !exact[q] && std::isfinite(d) && d > 0 ? d : 0.0;
            };
            int y0 = std::max(0, y - reach), y1 = std::min(h - 1, y + reach);
            int x0 = std::max(0, x - reach), x1 = std::min(w - 1, x + reach);
            double total = 0;
            for (int v = y0; v <= y1; ++v)
                for (int u = x0; u <= x1; ++u) total += weight(size_t(v) * w + u);
            if (!(total > 0)) continue;
            for (int v = y0; v <= y1; ++v)
                for (int u = x0; u <= x1; ++u) {
                    size_t q = size_t(v) * w + u;
                    double share = e * weight(q) / total;
                    (e > 0 ? gain : loss)[q] += std::fabs(share);
                }
        }
    for (size_t q = 0; q < n; ++q) {
        if (exact[q] || (gain[q] == 0 && loss[q] == 0)) continue;
        double lowered = std::max(0.0, double(in[q]) - moved[q]);
        double raised = std::max(0.0, double(moved[q]) - in[q]);
        out[q] = float(out[q] + std::min(gain[q], lowered) - std::min(loss[q], raised));
    }
}

}  // namespace

size_t KeepExactPixels(const Image &input, const Image &variance, Image *output, int reach) {
    if (!input.SameShape(*output))
        throw Error("KeepExactPixels: the output must have the input's shape",
                    ErrorKind::Internal);
    if (variance.width != input.width || variance.height != input.height ||
        (variance.channels != 1 && variance.channels != input.channels))
        return 0;
    const size_t n = input.PixelCount();
    size_t kept = 0;
    for (int c = 0; c < input.channels; ++c) {
        const float *in = input.Plane(c);
        const float *var = variance.Plane(variance.channels == 1 ? 0 : c);
        float *out = output->Plane(c);
        std::vector<char> exact(n, 0);
        for (size_t p = 0; p < n; ++p)
            exact[p] = var[p] == 0 && std::isfinite(in[p]) && in[p] > 0;
        std::vector<float> moved(out, out + n);
        for (size_t p = 0; p < n; ++p)
            if (exact[p]) out[p] = in[p], ++kept;
        if (reach > 0)
            ReturnEnergy(in, moved.data(), exact, input.width, input.height, reach, out);
    }
    return kept;
}

Image ExactVariance(const ExactLayers &layers) {
    if (layers.variance) return *layers.variance;
    if (!layers.min || !layers.max || !layers.spp) return Image();
    const Image &min = *layers.min, &max = *layers.max, &spp = *layers.spp;
    if (!min.SameShape(max) || spp.width != min.width || spp.height != min.height)
        return Image();
    Image variance(min.width, min.height, min.channels);
    for (int c = 0; c < min.channels; ++c)
        for (int y = 0; y < min.height; ++y)
            for (int x = 0; x < min.width; ++x) {
                double range = double(max.At(c, y, x)) - min.At(c, y, x);
                double count = spp.At(0, y, x);
                // No samples: nothing is known.
                variance.At(c, y, x) = count > 0 ? float(range * range / count)
                                                 : std::numeric_limits<float>::infinity();
            }
    return variance;
}

}  // namespace mcd
