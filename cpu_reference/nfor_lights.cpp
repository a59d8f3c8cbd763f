#include "cpu_reference/nfor_lights.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace mcd::ref {

void NforSpreadLights(const Image &albedo, const Image *alpha, double emitterAlbedo,
                      double weakAlbedo, double weakShare, double strongShare, Image *output) {
    const Image before = *output;
    const int w = before.width, h = before.height;
    auto largest = [&](int x, int y) {
        double most = albedo.At(0, y, x);
        for (int c = 1; c < albedo.channels; ++c)
            most = std::max(most, double(albedo.At(c, y, x)));
        return most;
    };
    auto present = [&](int x, int y) { return !alpha || alpha->At(0, y, x) > 0.f; };
    auto emitter = [&](int x, int y) { return largest(x, y) > emitterAlbedo; };
    // An emitter's share where it gives: > 0 and every channel of its output finite.
    auto share = [&](int x, int y) {
        double s = largest(x, y) < weakAlbedo ? weakShare : strongShare;
        for (int c = 0; c < before.channels; ++c)
            if (!std::isfinite(before.At(c, y, x))) return 0.0;
        return s > 0 ? s : 0.0;
    };
    const int offsets[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            if (!present(x, y)) continue;
            bool self = emitter(x, y);
            double s = self ? share(x, y) : 0;
            if (self && s == 0) continue;
            int receivers = 0;
            std::vector<double> gathered(size_t(before.channels), 0.0);
            for (auto [dx, dy] : offsets) {
                int u = x + dx, v = y + dy;
                if (u < 0 || v < 0 || u >= w || v >= h || !present(u, v)) continue;
                if (self) {
                    receivers += !emitter(u, v);
                } else if (emitter(u, v)) {
                    double t = share(u, v);
                    if (t == 0) continue;
                    for (int c = 0; c < before.channels; ++c)
                        gathered[size_t(c)] += t * before.At(c, v, u);
                }
            }
            for (int c = 0; c < before.channels; ++c) {
                double value = before.At(c, y, x);
                output->At(c, y, x) =
                    float(self ? value * (1 - s * receivers) : value + gathered[size_t(c)]);
            }
        }
}

}  // namespace mcd::ref
