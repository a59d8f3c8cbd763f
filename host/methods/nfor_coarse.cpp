#include "host/methods/nfor_coarse.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "host/methods/nfor_emitters.h"

namespace mcd {

Image NforHalf(const Image &image, bool ofMean) {
    int w = image.width, h = image.height;
    Image half((w + 1) / 2, (h + 1) / 2, image.channels);
    for (int c = 0; c < image.channels; ++c)
        for (int y = 0; y < half.height; ++y)
            for (int x = 0; x < half.width; ++x) {
                double sum = 0;
                int count = 0;
                for (int v = 2 * y; v < std::min(2 * y + 2, h); ++v)
                    for (int u = 2 * x; u < std::min(2 * x + 2, w); ++u)
                        sum += image.At(c, v, u), ++count;
                half.At(c, y, x) = float(sum / count / (ofMean ? count : 1));
            }
    return half;
}

namespace {

// One plane convolved along x (dx 1) or y with the clipped, normalised kernel.
void GaussianPass(const Image &in, const std::vector<double> &kernel, bool alongX, Image *out) {
    int r = int(kernel.size()) - 1;
    for (int c = 0; c < in.channels; ++c)
        for (int y = 0; y < in.height; ++y)
            for (int x = 0; x < in.width; ++x) {
                double sum = 0, weights = 0;
                for (int o = -r; o <= r; ++o) {
                    int u = alongX ? x + o : x, v = alongX ? y : y + o;
                    if (u < 0 || v < 0 || u >= in.width || v >= in.height) continue;
                    double k = kernel[std::abs(o)];
                    sum += k * in.At(c, v, u);
                    weights += k;
                }
                out->At(c, y, x) = float(sum / weights);
            }
}

// The coarse image's bilinear value at the fine pixel x along one axis: the two coarse
// indices and the second's weight.
struct Tap {
    int i0, i1;
    double f;
};
Tap TapAt(int x, int coarseSize) {
    double pos = (x + 0.5) / 2 - 0.5, lower = std::floor(pos);
    int i0 = int(lower);
    return {std::clamp(i0, 0, coarseSize - 1), std::clamp(i0 + 1, 0, coarseSize - 1),
            pos - lower};
}

}  // namespace

Image NforGaussian(const Image &image, double sigma) {
    int r = int(3 * sigma);
    std::vector<double> kernel(r + 1);
    for (int o = 0; o <= r; ++o) kernel[o] = std::exp(-0.5 * (o / sigma) * (o / sigma));
    Image rows(image.width, image.height, image.channels), out = rows;
    GaussianPass(image, kernel, true, &rows);
    GaussianPass(rows, kernel, false, &out);
    return out;
}

void NforAddCoarse(const Image &input, const Image &coarse, const Image *albedo,
                   float emitterAlbedo, float relative, float noise, Image *output) {
    int w = output->width, h = output->height, ch = output->channels;
    Image difference = coarse, half = NforHalf(*output);
    for (size_t i = 0; i < difference.Size(); ++i) difference.data[i] -= half.data[i];
    Image magnitude(w, h, 1), residual(w, h, 1);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < ch; ++c) {
                float value = output->At(c, y, x), r = input.At(c, y, x) - value;
                magnitude.At(0, y, x) += std::abs(value);
                residual.At(0, y, x) += r * r;
            }
    magnitude = NforGaussian(magnitude, 1);
    residual = NforGaussian(residual, 2);
    for (int y = 0; y < h; ++y) {
        Tap ty = TapAt(y, coarse.height);
        for (int x = 0; x < w; ++x) {
            if (albedo &&
                NforLargestAlbedo(*albedo, size_t(y) * albedo->width + x) > emitterAlbedo)
                continue;
            Tap tx = TapAt(x, coarse.width);
            float d[4] = {}, length = 0;
            for (int c = 0; c < ch; ++c) {
                auto at = [&](int v, int u) { return double(difference.At(c, v, u)); };
                double top = at(ty.i0, tx.i0) * (1 - tx.f) + at(ty.i0, tx.i1) * tx.f;
                double bottom = at(ty.i1, tx.i0) * (1 - tx.f) + at(ty.i1, tx.i1) * tx.f;
                d[c] = float(top * (1 - ty.f) + bottom * ty.f);
                length += d[c] * d[c];
            }
            float t = std::min(relative * (magnitude.At(0, y, x) + 1e-3f),
                               noise * std::sqrt(residual.At(0, y, x)));
            if (!(t > 0)) continue;
            float weight = std::max(0.f, 1 - length / (t * t));
            for (int c = 0; c < ch; ++c) output->At(c, y, x) += weight * d[c];
        }
    }
}

double NforRelativeNoise(const Image &color, const Image &variance) {
    const size_t pixels = size_t(color.width) * color.height;
    if (pixels == 0) return 0;
    std::vector<double> relative(pixels, 0.0);
    for (int c = 0; c < color.channels; ++c) {
        const float *v = variance.Plane(c), *x = color.Plane(c);
        for (size_t i = 0; i < pixels; ++i)
            relative[i] += double(v[i]) / (double(x[i]) * x[i] + 0.01) / color.channels;
    }
    for (double &r : relative)
        if (!std::isfinite(r)) r = std::numeric_limits<double>::infinity();
    auto middle = relative.begin() + (pixels - 1) / 2;
    std::nth_element(relative.begin(), middle, relative.end());
    return *middle;
}

}  // namespace mcd
