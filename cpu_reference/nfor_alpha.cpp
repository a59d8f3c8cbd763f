#include "cpu_reference/nfor_alpha.h"

#include <cmath>

namespace mcd::ref {

namespace {

// The image with each channel of every partly covered pixel replaced by f(value, alpha).
template <typename F>
Image MapPartlyCovered(const Image &image, const Image &alpha, F f) {
    Image out = image;
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) {
            double a = alpha.At(0, y, x);
            if (!NforPartlyCovered(a)) continue;
            for (int c = 0; c < image.channels; ++c)
                out.At(c, y, x) = float(f(double(image.At(c, y, x)), a));
        }
    return out;
}

}  // namespace

bool NforPartlyCovered(double a) {
    return a >= 1e-3 && a < 1.0;
}

Image NforStraight(const Image &image, const Image &alpha, int power) {
    return MapPartlyCovered(image, alpha,
                            [power](double v, double a) { return v / std::pow(a, power); });
}

Image NforPremultiply(const Image &image, const Image &alpha) {
    return MapPartlyCovered(image, alpha, [](double v, double a) { return v * a; });
}

}  // namespace mcd::ref
