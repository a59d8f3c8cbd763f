#include "cpu_reference/exact_pixels.h"

#include <algorithm>
#include <cmath>

namespace mcd::ref {

namespace {

bool Exact(const Image &input, const Image &variance, int c, int y, int x) {
    double v = variance.At(variance.channels == 1 ? 0 : c, y, x);
    double in = input.At(c, y, x);
    return v == 0 && std::isfinite(in) && in > 0;
}

}  // namespace

void KeepExactPixels(const Image &input, const Image &variance, Image *output, int reach) {
    if (variance.width != input.width || variance.height != input.height) return;
    if (variance.channels != 1 && variance.channels != input.channels) return;
    const Image before = *output;
    const int w = input.width, h = input.height;
    for (int c = 0; c < input.channels && reach > 0; ++c)
        for (int qy = 0; qy < h; ++qy)
            for (int qx = 0; qx < w; ++qx) {
                if (Exact(input, variance, c, qy, qx)) continue;
                double in = input.At(c, qy, qx), o = before.At(c, qy, qx);
                double gain = 0, loss = 0;
                for (int py = qy - reach; py <= qy + reach; ++py)
                    for (int px = qx - reach; px <= qx + reach; ++px) {
                        if (px < 0 || py < 0 || px >= w || py >= h) continue;
                        if (!Exact(input, variance, c, py, px)) continue;
                        double e = double(before.At(c, py, px)) - input.At(c, py, px);
                        if (!(e != 0 && std::isfinite(e))) continue;
                        auto weight = [&](int u, int v) {
                            if (Exact(input, variance, c, v, u)) return 0.0;
                            double d = e > 0 ? double(input.At(c, v, u)) - before.At(c, v, u)
                                             : double(before.At(c, v, u)) - input.At(c, v, u);
                            return std::isfinite(d) && d > 0 ? d : 0.0;
                        };
                        double total = 0;
                        for (int v = py - reach; v <= py + reach; ++v)
                            for (int u = px - reach; u <= px + reach; ++u)
                                if (u >= 0 && v >= 0 && u < w && v < h) total += weight(u, v);
                        if (!(total > 0)) continue;
                        (e > 0 ? gain : loss) += std::fabs(e) * weight(qx, qy) / total;
                    }
                output->At(c, qy, qx) = float(o + std::min(gain, std::max(0.0, in - o)) -
                                              std::min(loss, std::max(0.0, o - in)));
            }
    for (int c = 0; c < input.channels; ++c)
        for (int y = 0; y < input.height; ++y)
            for (int x = 0; x < input.width; ++x) {
                double v = variance.At(variance.channels == 1 ? 0 : c, y, x);
                double in = input.At(c, y, x);
                if (v == 0 && std::isfinite(in) && in > 0)
                    output->At(c, y, x) = input.At(c, y, x);
            }
}

}  // namespace mcd::ref
