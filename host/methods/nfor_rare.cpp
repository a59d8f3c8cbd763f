#include "host/methods/nfor_rare.h"

#include <algorithm>
#include <cmath>

#include "host/error.h"

namespace mcd {

size_t NforSpreadRareLight(const Image &color, const Image &clamped,
                           const std::vector<char> &near, const NforRareLightSettings &s,
                           Image *output) {
    const int w = color.width, h = color.height, channels = color.channels;
    if (!color.SameShape(clamped) || !color.SameShape(*output) ||
        near.size() != color.PixelCount() || s.radius < 0 || !(s.sigma > 0) || s.others < 1 ||
        s.pair < 1 || s.pair > kNforRarePair)
        throw Error(
            "NforSpreadRareLight: images of one shape, one flag per pixel, a radius "
            ">= 0, a sigma > 0, a pair in 1..kNforRarePair and others >= 1",
            ErrorKind::Internal);
    const int r = s.radius;
    // The pixels the clamp cut to under 1 / ratio, away from `near`.
    std::vector<char> cut(color.PixelCount());
    for (size_t i = 0; i < cut.size(); ++i) {
        if (near[i]) continue;
        double a = 0, b = 0;
        for (int c = 0; c < channels; ++c) {
            a += color.Plane(c)[i];
            b += clamped.Plane(c)[i];
        }
        cut[i] = std::isfinite(a) && a > 0 && a > s.ratio * b;
    }
    // A lone one is a firefly, its light kept out: a source has s.others more within s.pair
    // (a reflection's footprint holds several hits). Its lost light, 0 elsewhere.
    Image loss(w, h, channels);
    size_t sources = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            if (!cut[size_t(y) * w + x]) continue;
            int others = 0;
            for (int v = std::max(0, y - s.pair);
                 v <= std::min(h - 1, y + s.pair) && others < s.others; ++v)
                for (int u = std::max(0, x - s.pair);
                     u <= std::min(w - 1, x + s.pair) && others < s.others; ++u)
                    others += (v != y || u != x) && cut[size_t(v) * w + u];
            if (others < s.others) continue;
            ++sources;
            for (int c = 0; c < channels; ++c)
                loss.At(c, y, x) = std::max(color.At(c, y, x) - clamped.At(c, y, x), 0.f);
        }
    if (sources == 0 || s.share == 0) return sources;
    const int n = 2 * r + 1;
    std::vector<double> taps(n);
    double sum = 0;
    for (int k = -r; k <= r; ++k)
        sum += taps[k + r] = std::exp(-k * k / (2.0 * s.sigma * s.sigma));
    for (double &t : taps) t /= sum;
    // Gathered per receiver in a fixed order of offsets: a tile's pixel sums what the whole
    // frame's does.
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            if (near[size_t(y) * w + x]) continue;
            for (int c = 0; c < channels; ++c) {
                double given = 0;
                for (int dy = -r; dy <= r; ++dy) {
                    const int v = y + dy;
                    if (v < 0 || v >= h) continue;
                    for (int dx = -r; dx <= r; ++dx) {
                        const int u = x + dx;
                        if (u < 0 || u >= w) continue;
                        given += taps[dy + r] * taps[dx + r] * loss.At(c, v, u);
                    }
                }
                if (given > 0)
                    output->At(c, y, x) = float(output->At(c, y, x) + s.share * given);
            }
        }
    return sources;
}

}  // namespace mcd
