#include "host/methods/nfor_band.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "host/error.h"

namespace mcd {

namespace {

double Luminance(const Image &image, int y, int x) {
    if (image.channels < 3) return image.At(0, y, x);
    return 0.2126 * image.At(0, y, x) + 0.7152 * image.At(1, y, x) + 0.0722 * image.At(2, y, x);
}

// A Gaussian of `sigma` over -r..r, r = int(3 sigma) + 1, normalised to sum 1.
std::vector<double> GaussianTaps(double sigma) {
    const int r = int(3 * sigma) + 1;
    std::vector<double> taps(2 * r + 1);
    double sum = 0;
    for (int k = -r; k <= r; ++k) sum += taps[k + r] = std::exp(-k * k / (2 * sigma * sigma));
    for (double &t : taps) t /= sum;
    return taps;
}

// `plane` (w x h) blurred by `taps` along rows, then columns, the edges repeated.
std::vector<double> Blur(const std::vector<double> &plane, int w, int h,
                         const std::vector<double> &taps) {
    const int r = int(taps.size() / 2);
    std::vector<double> rows(plane.size()), out(plane.size());
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            double s = 0;
            for (int k = -r; k <= r; ++k)
                s += taps[k + r] * plane[size_t(y) * w + std::clamp(x + k, 0, w - 1)];
            rows[size_t(y) * w + x] = s;
        }
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            double s = 0;
            for (int k = -r; k <= r; ++k)
                s += taps[k + r] * rows[size_t(std::clamp(y + k, 0, h - 1)) * w + x];
            out[size_t(y) * w + x] = s;
        }
    return out;
}

// Whether each pixel lies within `reach` (Chebyshev) of a glint.
std::vector<char> NearGlints(const Image &albedo, float glintAlbedo, int reach) {
    const int w = albedo.width, h = albedo.height;
    std::vector<char> glint(size_t(w) * h), rows(glint.size()), near(glint.size());
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < albedo.channels; ++c)
                glint[size_t(y) * w + x] |= albedo.At(c, y, x) > glintAlbedo;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int u = std::max(0, x - reach); u <= std::min(w - 1, x + reach); ++u)
                rows[size_t(y) * w + x] |= glint[size_t(y) * w + u];
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int v = std::max(0, y - reach); v <= std::min(h - 1, y + reach); ++v)
                near[size_t(y) * w + x] |= rows[size_t(v) * w + x];
    return near;
}

// The line's direction (tx, ty) and coherence at each pixel: the structure tensor of
// log(luminance + 0.01), central differences (one-sided at the edges), blurred by `sigma`.
void LineDirections(const Image &output, double sigma, std::vector<double> *tx,
                    std::vector<double> *ty, std::vector<double> *coherence) {
    const int w = output.width, h = output.height;
    std::vector<double> l(size_t(w) * h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            l[size_t(y) * w + x] = std::log(std::max(Luminance(output, y, x), 0.0) + 0.01);
    auto at = [&](int y, int x) { return l[size_t(y) * w + x]; };
    std::vector<double> jxx(l.size()), jxy(l.size()), jyy(l.size());
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const int x0 = std::max(x - 1, 0), x1 = std::min(x + 1, w - 1);
            const int y0 = std::max(y - 1, 0), y1 = std::min(y + 1, h - 1);
            const double gx = x1 > x0 ? (at(y, x1) - at(y, x0)) / (x1 - x0) : 0;
            const double gy = y1 > y0 ? (at(y1, x) - at(y0, x)) / (y1 - y0) : 0;
            const size_t i = size_t(y) * w + x;
            jxx[i] = gx * gx;
            jxy[i] = gx * gy;
            jyy[i] = gy * gy;
        }
    const std::vector<double> taps = GaussianTaps(sigma);
    jxx = Blur(jxx, w, h, taps);
    jxy = Blur(jxy, w, h, taps);
    jyy = Blur(jyy, w, h, taps);
    tx->assign(l.size(), 0);
    ty->assign(l.size(), 0);
    coherence->assign(l.size(), 0);
    for (size_t i = 0; i < l.size(); ++i) {
        const double trace = jxx[i] + jyy[i];
        const double d = std::sqrt((jxx[i] - jyy[i]) * (jxx[i] - jyy[i]) + 4 * jxy[i] * jxy[i]);
        const double l1 = (trace + d) / 2, l2 = (trace - d) / 2;
        // The gradient's direction, the larger eigenvalue's vector; the line across it.
        const double vx = jxy[i], vy = l1 - jxx[i], norm = std::sqrt(vx * vx + vy * vy);
        if (!(trace > 0) || !(norm > 0)) continue;
        (*tx)[i] = -vy / norm;
        (*ty)[i] = vx / norm;
        const double c = (l1 - l2) / trace;
        (*coherence)[i] = c * c;
    }
}

// `plane`'s bilinear value at (x, y), the position held inside the frame (a frame one pixel
// wide or tall reads its one column or row).
template <typename At>
double Bilinear(At at, int w, int h, double x, double y) {
    x = std::clamp(x, 0.0, double(w - 1));
    y = std::clamp(y, 0.0, double(h - 1));
    const int x0 = std::min(int(x), w - 1), y0 = std::min(int(y), h - 1);
    const int x1 = std::min(x0 + 1, w - 1), y1 = std::min(y0 + 1, h - 1);
    const double fx = x - x0, fy = y - y0;
    return at(y0, x0) * (1 - fx) * (1 - fy) + at(y0, x1) * fx * (1 - fy) +
           at(y1, x0) * (1 - fx) * fy + at(y1, x1) * fx * fy;
}

// Whether the pixel's channels (at most 4) are all finite.
bool FinitePixel(const Image &image, int y, int x) {
    for (int c = 0; c < image.channels && c < 4; ++c)
        if (!std::isfinite(image.At(c, y, x))) return false;
    return true;
}

}  // namespace

size_t NforSmoothGlintBands(const Image &albedo, const Image *alpha,
                            const NforGlintBandSettings &s, Image *output) {
    const int w = output->width, h = output->height, channels = output->channels;
    if (albedo.width != w || albedo.height != h ||
        (alpha && (alpha->width != w || alpha->height != h)) || s.radius < 0 ||
        !(s.sigma > 0) || !(s.tensorSigma > 0) || !(s.bound >= 1) || s.reach < 0)
        throw Error(
            "NforSmoothGlintBands: an albedo (and alpha) of the output's size, a radius >= 0, "
            "sigmas > 0 and a bound >= 1",
            ErrorKind::Internal);
    // A frame without a glint (most) is left at the cost of one read of its albedo.
    if (s.radius == 0 || std::none_of(albedo.data.begin(), albedo.data.end(),
                                      [&](float a) { return a > s.glintAlbedo; }))
        return 0;
    const std::vector<char> near = NearGlints(albedo, s.glintAlbedo, s.reach);
    // Emitters and empty pixels (alpha 0) neither move nor give: 1 in `emitter`.
    std::vector<double> emitter(size_t(w) * h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            double &e = emitter[size_t(y) * w + x];
            for (int c = 0; c < albedo.channels; ++c)
                if (albedo.At(c, y, x) > s.emitterAlbedo) e = 1;
            if (alpha && !(alpha->At(0, y, x) > 0)) e = 1;
        }
    std::vector<double> tx, ty, coherence;
    LineDirections(*output, s.tensorSigma, &tx, &ty, &coherence);
    const Image in = *output;
    auto emitterAt = [&](int y, int x) { return emitter[size_t(y) * w + x]; };
    size_t moved = 0;
    std::vector<double> mean(channels);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const size_t i = size_t(y) * w + x;
            if (!near[i] || emitter[i] > 0 || !(coherence[i] > 0) || !FinitePixel(in, y, x))
                continue;
            const double own = std::max(Luminance(in, y, x), 0.0);
            std::fill(mean.begin(), mean.end(), 0.0);
            double weights = 0;
            for (int k = -s.radius; k <= s.radius; ++k) {
                const double px = x + k * tx[i], py = y + k * ty[i];
                const double weight = std::exp(-k * k / (2.0 * s.sigma * s.sigma)) *
                                      (1 - Bilinear(emitterAt, w, h, px, py));
                if (!(weight > 0)) continue;
                double sample[4] = {0, 0, 0, 0}, lum = 0;
                bool finite = true;
                for (int c = 0; c < channels && c < 4; ++c) {
                    sample[c] = Bilinear([&](int v, int u) { return double(in.At(c, v, u)); },
                                         w, h, px, py);
                    finite = finite && std::isfinite(sample[c]);
                }
                // A non-finite value near the line gives nothing, so it does not spread.
                if (!finite) continue;
                lum = channels < 3
                          ? sample[0]
                          : 0.2126 * sample[0] + 0.7152 * sample[1] + 0.0722 * sample[2];
                // A bright line beside a dim pixel gives it at most bound x its own; a
                // sample of no light counts as black.
                const double held = std::clamp(lum, own / s.bound, own * s.bound + 0.01);
                const double scale = lum > 0 ? held / lum : 0;
                for (int c = 0; c < channels && c < 4; ++c)
                    mean[c] += weight * sample[c] * scale;
                weights += weight;
            }
            if (!(weights > 0)) continue;
            for (int c = 0; c < channels && c < 4; ++c)
                output->At(c, y, x) =
                    float(in.At(c, y, x) + coherence[i] * (mean[c] / weights - in.At(c, y, x)));
            ++moved;
        }
    return moved;
}

}  // namespace mcd
