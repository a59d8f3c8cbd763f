#include "host/methods/nfor_lights.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "host/methods/nfor_emitters.h"

namespace mcd {

size_t NforSpreadLights(const Image &albedo, const Image *alpha, const NforLightSettings &s,
                        Image *output) {
    const Image in = *output;
    const int w = in.width, h = in.height;
    const size_t n = in.PixelCount();
    // Per pixel: the share it gives each neighbour, -1 where it is no emitter, 0 where it
    // takes no part (fully transparent).
    std::vector<double> share(n, -1.0);
    for (size_t i = 0; i < n; ++i) {
        if (alpha && !(alpha->data[i] > 0.f)) {
            share[i] = 0;
            continue;
        }
        const float most = NforLargestAlbedo(albedo, i);
        if (!(most > s.emitterAlbedo)) continue;
        share[i] = double(most < s.weakAlbedo ? s.weakShare : s.strongShare);
    }
    std::vector<double> delta(in.Size(), 0.0);
    size_t giving = 0;
    const int dx[4] = {1, -1, 0, 0}, dy[4] = {0, 0, 1, -1};
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const size_t p = size_t(y) * w + x;
            if (!(share[p] > 0)) continue;
            bool finite = true;
            for (int c = 0; c < in.channels; ++c)
                finite = finite && std::isfinite(in.Plane(c)[p]);
            if (!finite) continue;
            bool gave = false;
            for (int k = 0; k < 4; ++k) {
                const int u = x + dx[k], v = y + dy[k];
                if (u < 0 || v < 0 || u >= w || v >= h) continue;
                const size_t q = size_t(v) * w + u;
                if (share[q] >= 0) continue;
                for (int c = 0; c < in.channels; ++c) {
                    const double given = share[p] * double(in.Plane(c)[p]);
                    delta[size_t(c) * n + q] += given;
                    delta[size_t(c) * n + p] -= given;
                }
                gave = true;
            }
            giving += gave;
        }
    for (size_t i = 0; i < in.Size(); ++i)
        if (delta[i] != 0) output->data[i] = float(double(in.data[i]) + delta[i]);
    return giving;
}

namespace {

// The mean of pixel i's channels.
double ChannelMean(const Image &image, size_t i) {
    double sum = 0;
    for (int c = 0; c < image.channels; ++c) sum += image.Plane(c)[i];
    return sum / image.channels;
}

// The median of `values` (the mean of the middle two where their count is even); reorders.
double Median(std::vector<double> &values) {
    const size_t k = values.size() / 2;
    std::nth_element(values.begin(), values.begin() + long(k), values.end());
    if (values.size() % 2) return values[k];
    const double upper = values[k];
    return (*std::max_element(values.begin(), values.begin() + long(k)) + upper) / 2;
}

}  // namespace

size_t NforFoldRimHits(const Image &color, const Image &albedo, const Image *alpha,
                       const NforRimSettings &s, Image *output) {
    if (!(s.coreRatio > 0)) return 0;
    const Image in = *output;
    const int w = in.width, h = in.height, channels = in.channels;
    const size_t n = in.PixelCount();
    // Per pixel: its largest albedo channel where it is an emitter with a finite output, -1
    // where it is no emitter, -2 where it takes no part (transparent, or an emitter whose
    // output is not finite).
    std::vector<double> level(n, -1.0);
    for (size_t i = 0; i < n; ++i) {
        if (alpha && !(alpha->data[i] > 0.f)) {
            level[i] = -2;
            continue;
        }
        const float most = NforLargestAlbedo(albedo, i);
        if (!(most > s.emitterAlbedo)) continue;
        bool finite = true;
        for (int c = 0; c < channels; ++c) finite = finite && std::isfinite(in.Plane(c)[i]);
        level[i] = finite ? double(most) : -2;
    }
    std::vector<double> delta(in.Size(), 0.0), ground;
    std::vector<size_t> core;
    size_t folded = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const size_t p = size_t(y) * w + x;
            if (level[p] < 0) continue;
            // The light's core around p, and p's neighbours that are no emitter.
            core.clear();
            ground.clear();
            for (int v = std::max(y - s.radius, 0); v <= std::min(y + s.radius, h - 1); ++v)
                for (int u = std::max(x - s.radius, 0); u <= std::min(x + s.radius, w - 1);
                     ++u) {
                    const size_t q = size_t(v) * w + u;
                    if (q != p && level[q] >= double(s.coreRatio) * level[p]) core.push_back(q);
                    if (std::abs(u - x) > 1 || std::abs(v - y) > 1 || level[q] != -1) continue;
                    const double value = ChannelMean(color, q);
                    if (std::isfinite(value)) ground.push_back(value);
                }
            if (core.empty() || ground.empty()) continue;
            const double input = ChannelMean(color, p), out = ChannelMean(in, p);
            if (!(input > 0) || !std::isfinite(input)) continue;
            const double cap = std::sqrt(std::max(Median(ground), 0.0) * input);
            if (!(out > cap)) continue;
            const double keep = cap / out;
            for (int c = 0; c < channels; ++c) {
                const float *plane = in.Plane(c);
                const double lost = double(plane[p]) * (1 - keep);
                double sum = 0;
                for (size_t q : core) sum += std::max(double(plane[q]), 0.0);
                delta[size_t(c) * n + p] -= lost;
                for (size_t q : core)
                    delta[size_t(c) * n + q] +=
                        sum > 0 ? lost * std::max(double(plane[q]), 0.0) / sum
                                : lost / double(core.size());
            }
            ++folded;
        }
    for (size_t i = 0; i < in.Size(); ++i)
        if (delta[i] != 0) output->data[i] = float(double(in.data[i]) + delta[i]);
    return folded;
}

}  // namespace mcd
