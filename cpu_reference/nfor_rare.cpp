#include "cpu_reference/nfor_rare.h"

#include <algorithm>
#include <cmath>

namespace mcd::ref {

size_t NforSpreadRareLight(const Image &color, const Image &clamped,
                           const std::vector<char> &near, double share, double ratio,
                           double sigma, int radius, int pair, int others, Image *output) {
    const int w = color.width, h = color.height;
    std::vector<double> g(2 * radius + 1);
    double total = 0;
    for (int k = -radius; k <= radius; ++k)
        total += g[k + radius] = std::exp(-double(k) * k / (2 * sigma * sigma));
    for (double &t : g) t /= total;
    auto isCut = [&](int y, int x) {
        if (near[size_t(y) * w + x]) return false;
        double a = 0, b = 0;
        for (int c = 0; c < color.channels; ++c) {
            a += color.At(c, y, x);
            b += clamped.At(c, y, x);
        }
        return std::isfinite(a) && a > 0 && a > ratio * b;
    };
    std::vector<double> given(color.data.size(), 0.0);
    size_t sources = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            if (!isCut(y, x)) continue;
            int count = 0;
            for (int v = std::max(0, y - pair); v <= std::min(h - 1, y + pair); ++v)
                for (int u = std::max(0, x - pair); u <= std::min(w - 1, x + pair); ++u)
                    count += (v != y || u != x) && isCut(v, u);
            if (count < others) continue;
            ++sources;
            for (int v = std::max(0, y - radius); v <= std::min(h - 1, y + radius); ++v)
                for (int u = std::max(0, x - radius); u <= std::min(w - 1, x + radius); ++u) {
                    if (near[size_t(v) * w + u]) continue;
                    const double weight = g[v - y + radius] * g[u - x + radius];
                    for (int c = 0; c < color.channels; ++c)
                        given[(size_t(c) * h + v) * w + u] +=
                            weight *
                            std::max(0.0, double(color.At(c, y, x)) - clamped.At(c, y, x));
                }
        }
    if (share == 0) return sources;
    for (size_t i = 0; i < given.size(); ++i)
        if (given[i] > 0) output->data[i] = float(output->data[i] + share * given[i]);
    return sources;
}

}  // namespace mcd::ref
