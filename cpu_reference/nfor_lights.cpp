#include "cpu_reference/nfor_lights.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace mcd::ref {

namespace {

// The largest albedo channel at (x, y), taken in channel order.
double LargestAlbedo(const Image &albedo, int x, int y) {
    double most = albedo.At(0, y, x);
    for (int c = 1; c < albedo.channels; ++c) most = std::max(most, double(albedo.At(c, y, x)));
    return most;
}

// Whether (x, y) takes part: no alpha, or an alpha above 0.
bool Present(const Image *alpha, int x, int y) {
    return !alpha || alpha->At(0, y, x) > 0.f;
}

}  // namespace

void NforSpreadLights(const Image &albedo, const Image *alpha, double emitterAlbedo,
                      double weakAlbedo, double weakShare, double strongShare, Image *output) {
    const Image before = *output;
    const int w = before.width, h = before.height;
    auto largest = [&](int x, int y) { return LargestAlbedo(albedo, x, y); };
    auto present = [&](int x, int y) { return Present(alpha, x, y); };
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

void NforFoldRimHits(const Image &color, const Image &albedo, const Image *alpha,
                     double emitterAlbedo, double coreRatio, int radius, Image *output) {
    if (coreRatio == 0) return;
    const Image before = *output;
    const int w = before.width, h = before.height, channels = before.channels;
    auto largest = [&](int x, int y) { return LargestAlbedo(albedo, x, y); };
    auto present = [&](int x, int y) { return Present(alpha, x, y); };
    auto finiteOutput = [&](int x, int y) {
        for (int c = 0; c < channels; ++c)
            if (!std::isfinite(before.At(c, y, x))) return false;
        return true;
    };
    auto emitter = [&](int x, int y) { return present(x, y) && largest(x, y) > emitterAlbedo; };
    // An emitter that gives or takes: present, above the threshold, its output finite.
    auto lit = [&](int x, int y) { return emitter(x, y) && finiteOutput(x, y); };
    auto mean = [&](const Image &image, int x, int y) {
        double sum = 0;
        for (int c = 0; c < image.channels; ++c) sum += image.At(c, y, x);
        return sum / image.channels;
    };
    auto inside = [&](int u, int v) { return u >= 0 && v >= 0 && u < w && v < h; };
    // Whether (u, v) is in the core of rim pixel (x, y).
    auto inCore = [&](int x, int y, int u, int v) {
        return (u != x || v != y) && std::abs(u - x) <= radius && std::abs(v - y) <= radius &&
               inside(u, v) && lit(u, v) && largest(u, v) >= coreRatio * largest(x, y);
    };
    // The factor a rim pixel keeps of its output, 1 where it is none.
    auto kept = [&](int x, int y) {
        if (!lit(x, y)) return 1.0;
        bool hasCore = false;
        for (int v = y - radius; v <= y + radius; ++v)
            for (int u = x - radius; u <= x + radius; ++u)
                hasCore = hasCore || inCore(x, y, u, v);
        std::vector<double> ground;
        for (int v = y - 1; v <= y + 1; ++v)
            for (int u = x - 1; u <= x + 1; ++u) {
                if (!inside(u, v) || !present(u, v) || largest(u, v) > emitterAlbedo) continue;
                double value = mean(color, u, v);
                if (std::isfinite(value)) ground.push_back(value);
            }
        double input = mean(color, x, y), out = mean(before, x, y);
        if (!hasCore || ground.empty() || !(input > 0) || !std::isfinite(input)) return 1.0;
        std::sort(ground.begin(), ground.end());
        size_t k = ground.size();
        double median = k % 2 ? ground[k / 2] : (ground[k / 2 - 1] + ground[k / 2]) / 2;
        double target = std::sqrt(std::max(median, 0.0) * input);
        return out > target ? target / out : 1.0;
    };
    std::vector<double> keep(size_t(w) * h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) keep[size_t(y) * w + x] = kept(x, y);
    for (int c = 0; c < channels; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                double value = before.At(c, y, x) * keep[size_t(y) * w + x];
                // The light of every rim pixel within radius whose core holds (x, y).
                for (int v = y - radius; v <= y + radius; ++v)
                    for (int u = x - radius; u <= x + radius; ++u) {
                        if (!inside(u, v) || keep[size_t(v) * w + u] == 1.0 ||
                            !inCore(u, v, x, y))
                            continue;
                        double lost = before.At(c, v, u) * (1 - keep[size_t(v) * w + u]);
                        double sum = 0;
                        int members = 0;
                        for (int b = v - radius; b <= v + radius; ++b)
                            for (int a = u - radius; a <= u + radius; ++a)
                                if (inCore(u, v, a, b)) {
                                    sum += std::max(double(before.At(c, b, a)), 0.0);
                                    ++members;
                                }
                        value += sum > 0
                                     ? lost * std::max(double(before.At(c, y, x)), 0.0) / sum
                                     : lost / members;
                    }
                output->At(c, y, x) = float(value);
            }
}

}  // namespace mcd::ref
