#include "host/methods/nfor_kept.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "host/methods/nfor_emitters.h"

namespace mcd {

namespace {

// Whether every channel of (x, y) in `output` is finite and within 1e-3 |input| + 1e-6 of
// `input` there.
bool Unmoved(const Image &input, const Image &output, int x, int y) {
    for (int c = 0; c < input.channels; ++c) {
        float in = input.At(c, y, x), out = output.At(c, y, x);
        if (!std::isfinite(in) || !std::isfinite(out)) return false;
        if (std::abs(out - in) > 1e-3f * std::abs(in) + 1e-6f) return false;
    }
    return true;
}

}  // namespace

bool NforKeptPixel(const Image &input, const Image &output, const Image &mask, int r, int x,
                   int y) {
    if (mask.At(0, y, x) == 0 || !Unmoved(input, output, x, y)) return false;
    bool lit = false;
    for (int c = 0; c < input.channels; ++c) lit = lit || input.At(c, y, x) > 1e-4f;
    if (!lit) return false;
    // The fits moved a pixel near: this one was left alone, not reproduced by its fit.
    for (int v = std::max(0, y - r); v <= std::min(input.height - 1, y + r); ++v)
        for (int u = std::max(0, x - r); u <= std::min(input.width - 1, x + r); ++u)
            if ((u != x || v != y) && mask.At(0, v, u) != 0 && !Unmoved(input, output, u, v))
                return true;
    return false;
}

namespace {

// The feature term sum_j (s_j (F_q,j - F_p,j))^2 between pixels p and q.
float FeatureTerm(const Image &features, const std::vector<float> &s, int px, int py, int qx,
                  int qy) {
    float e = 0;
    for (int j = 0; j < features.channels && j < int(s.size()); ++j) {
        float d = s[j] * (features.At(j, qy, qx) - features.At(j, py, px));
        e += d * d;
    }
    return e;
}

// The positive parts of (x, y)'s channels in `image`, summed in double (0 where one is not
// finite: such a pixel reads as dark).
double PositiveSum(const Image &image, int x, int y) {
    double sum = 0;
    for (int c = 0; c < image.channels; ++c) {
        float v = image.At(c, y, x);
        if (!std::isfinite(v)) return 0;
        sum += std::max(0.f, v);
    }
    return sum;
}

}  // namespace

bool NforWeakEmitterOnLine(const Image &output, float ratio, int x, int y) {
    if (!(ratio > 0)) return false;
    const double bound = double(ratio) * PositiveSum(output, x, y);
    static const int kDirections[4][2] = {{1, 0}, {0, 1}, {1, 1}, {1, -1}};
    for (const auto &d : kDirections) {
        bool both = true;
        for (int side = -1; side <= 1 && both; side += 2) {
            bool bright = false;
            for (int step = 1; step <= 2 && !bright; ++step) {
                int u = x + side * step * d[0], v = y + side * step * d[1];
                if (u < 0 || v < 0 || u >= output.width || v >= output.height) continue;
                bright = PositiveSum(output, u, v) >= bound;
            }
            both = bright;
        }
        if (both) return true;
    }
    return false;
}

namespace {

// Per pixel: 0 not an emitter, 1 a weak emitter (smoothed), 2 an emitter left.
std::vector<uint8_t> EmitterKinds(const Image &mask, const NforKeptSettings &k) {
    std::vector<uint8_t> kind(mask.PixelCount(), 0);
    for (int y = 0; y < mask.height; ++y)
        for (int x = 0; x < mask.width; ++x) {
            if (mask.At(0, y, x) != 0) continue;
            const float most =
                k.albedo ? NforLargestAlbedo(*k.albedo, size_t(y) * mask.width + x) : 0.f;
            bool weak = k.weakEmitterAlbedo > 0 && most < k.weakEmitterAlbedo;
            kind[size_t(y) * mask.width + x] = weak ? 1 : 2;
        }
    return kind;
}

}  // namespace

size_t NforSmoothKept(const Image &input, const Image &features,
                      const std::vector<float> &featureWeights, const Image &mask,
                      const NforKeptSettings &k, Image *output) {
    int r = k.radius;
    if (r <= 0) return 0;
    int w = input.width, h = input.height, ch = input.channels;
    const Image before = *output;
    std::vector<uint8_t> kind = EmitterKinds(mask, k);
    // A weak emitter's albedo is its coverage, noisy as its colour: not compared.
    std::vector<float> unlit = featureWeights;
    for (int j = 0; j < k.albedoPlanes && j < int(unlit.size()); ++j) unlit[j] = 0;
    float sigma2 = 0.25f * float(r) * float(r);
    // The pixels smoothed; none reads another kept one (its input: a firefly would spread).
    std::vector<uint8_t> kept(size_t(w) * h, 0);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            kept[size_t(y) * w + x] =
                kind[size_t(y) * w + x] == 1 || NforKeptPixel(input, before, mask, r, x, y);
    size_t changed = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            bool weak = kind[size_t(y) * w + x] == 1;
            if (!kept[size_t(y) * w + x] || (!weak && !k.keptPixels)) continue;
            const std::vector<float> &s = weak ? unlit : featureWeights;
            // A weak emitter on a bright line averages along it (lineRatio).
            const bool line = weak && NforWeakEmitterOnLine(before, k.lineRatio, x, y);
            const double own = std::log(PositiveSum(before, x, y) / ch + 0.01);
            const double range2 = 2.0 * double(k.lineRange) * double(k.lineRange);
            std::vector<double> sum(size_t(ch), 0.0);
            double total = 0;
            for (int v = std::max(0, y - r); v <= std::min(h - 1, y + r); ++v)
                for (int u = std::max(0, x - r); u <= std::min(w - 1, x + r); ++u) {
                    size_t q = size_t(v) * w + u;
                    if (kind[q] == 2 || (kept[q] && kind[q] != 1 && (u != x || v != y)))
                        continue;
                    bool finite = true;
                    for (int c = 0; c < ch; ++c)
                        finite = finite && std::isfinite(before.At(c, v, u));
                    if (!finite) continue;
                    float d2 = float((u - x) * (u - x) + (v - y) * (v - y));
                    double wq =
                        std::exp(-d2 / (2 * sigma2) - FeatureTerm(features, s, x, y, u, v));
                    if (line) {
                        double l = std::log(PositiveSum(before, u, v) / ch + 0.01) - own;
                        wq *= std::exp(-l * l / range2);
                    }
                    for (int c = 0; c < ch; ++c) sum[size_t(c)] += wq * before.At(c, v, u);
                    total += wq;
                }
            if (!(total > 0)) continue;
            for (int c = 0; c < ch; ++c) output->At(c, y, x) = float(sum[size_t(c)] / total);
            ++changed;
        }
    return changed;
}

}  // namespace mcd
