#include "cpu_reference/nfor_coarse.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace mcd::ref {

Image NforHalf(const Image &image, bool ofMean) {
    Image half((image.width + 1) / 2, (image.height + 1) / 2, image.channels);
    for (int c = 0; c < image.channels; ++c)
        for (int y = 0; y < half.height; ++y)
            for (int x = 0; x < half.width; ++x) {
                double sum = 0;
                int count = 0;
                for (int dy = 0; dy < 2; ++dy)
                    for (int dx = 0; dx < 2; ++dx) {
                        int u = 2 * x + dx, v = 2 * y + dy;
                        if (u >= image.width || v >= image.height) continue;
                        sum += image.At(c, v, u);
                        ++count;
                    }
                double mean = sum / count;
                half.At(c, y, x) = float(ofMean ? mean / count : mean);
            }
    return half;
}

namespace {

// The Gaussian-weighted mean of plane 0 of `image` around (x, y).
double GaussianMean(const Image &image, int x, int y, double sigma) {
    int r = int(3 * sigma);
    double sum = 0, weights = 0;
    for (int v = y - r; v <= y + r; ++v)
        for (int u = x - r; u <= x + r; ++u) {
            if (u < 0 || v < 0 || u >= image.width || v >= image.height) continue;
            double k = std::exp(-((u - x) * (u - x) + (v - y) * (v - y)) / (2 * sigma * sigma));
            sum += k * image.At(0, v, u);
            weights += k;
        }
    return sum / weights;
}

// The bilinear value of plane c of the coarse image at the fine pixel (x, y).
double Bilinear(const Image &coarse, int c, int x, int y) {
    double px = (x + 0.5) / 2 - 0.5, py = (y + 0.5) / 2 - 0.5;
    double fx = px - std::floor(px), fy = py - std::floor(py);
    auto at = [&](int u, int v) {
        return double(coarse.At(c, std::clamp(v, 0, coarse.height - 1),
                                std::clamp(u, 0, coarse.width - 1)));
    };
    int x0 = int(std::floor(px)), y0 = int(std::floor(py));
    return (1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x0 + 1, y0)) +
           fy * ((1 - fx) * at(x0, y0 + 1) + fx * at(x0 + 1, y0 + 1));
}

}  // namespace

void NforAddCoarse(const Image &input, const Image &coarse, const Image *albedo,
                   double emitterAlbedo, double relative, double noise, Image *output) {
    const Image fine = *output;
    Image half = NforHalf(fine), difference = coarse;
    for (size_t i = 0; i < difference.Size(); ++i) difference.data[i] -= half.data[i];
    Image magnitude(fine.width, fine.height, 1), residual(fine.width, fine.height, 1);
    for (int y = 0; y < fine.height; ++y)
        for (int x = 0; x < fine.width; ++x) {
            double m = 0, s = 0;
            for (int c = 0; c < fine.channels; ++c) {
                m += std::abs(double(fine.At(c, y, x)));
                double r = double(input.At(c, y, x)) - fine.At(c, y, x);
                s += r * r;
            }
            magnitude.At(0, y, x) = float(m);
            residual.At(0, y, x) = float(s);
        }
    for (int y = 0; y < fine.height; ++y)
        for (int x = 0; x < fine.width; ++x) {
            if (albedo) {
                double a =
                    std::max({albedo->At(0, y, x), albedo->At(1, y, x), albedo->At(2, y, x)});
                if (a > emitterAlbedo) continue;
            }
            double t = std::min(relative * (GaussianMean(magnitude, x, y, 1) + 1e-3),
                                noise * std::sqrt(GaussianMean(residual, x, y, 2)));
            if (!(t > 0)) continue;
            double d[4] = {}, length = 0;
            for (int c = 0; c < fine.channels; ++c) {
                d[c] = Bilinear(difference, c, x, y);
                length += d[c] * d[c];
            }
            double weight = std::max(0.0, 1 - length / (t * t));
            for (int c = 0; c < fine.channels; ++c)
                output->At(c, y, x) = float(fine.At(c, y, x) + weight * d[c]);
        }
}

double NforRelativeNoise(const Image &color, const Image &variance) {
    std::vector<double> values;
    for (int y = 0; y < color.height; ++y)
        for (int x = 0; x < color.width; ++x) {
            double sum = 0;
            for (int c = 0; c < color.channels; ++c) {
                double v = color.At(c, y, x);
                sum += variance.At(c, y, x) / (v * v + 0.01);
            }
            double value = sum / color.channels;
            values.push_back(std::isfinite(value) ? value
                                                  : std::numeric_limits<double>::infinity());
        }
    if (values.empty()) return 0;
    std::sort(values.begin(), values.end());
    return values[(values.size() - 1) / 2];
}

}  // namespace mcd::ref
