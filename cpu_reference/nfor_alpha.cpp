#include "cpu_reference/nfor_alpha.h"

#include <cmath>

namespace mcd::ref {

bool NforPartlyCovered(double a) {
    return a >= 1e-3 && a < 1.0;
}

Image NforStraight(const Image &image, const Image &alpha, int power) {
    Image out = image;
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) {
            double a = alpha.At(0, y, x);
            if (!NforPartlyCovered(a)) continue;
            for (int c = 0; c < image.channels; ++c)
                out.At(c, y, x) = float(double(image.At(c, y, x)) / std::pow(a, power));
        }
    return out;
}

Image NforPremultiply(const Image &image, const Image &alpha) {
    Image out = image;
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) {
            double a = alpha.At(0, y, x);
            if (!NforPartlyCovered(a)) continue;
            for (int c = 0; c < image.channels; ++c)
                out.At(c, y, x) = float(double(image.At(c, y, x)) * a);
        }
    return out;
}

}  // namespace mcd::ref
