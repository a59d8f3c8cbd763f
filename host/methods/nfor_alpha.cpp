#include "host/methods/nfor_alpha.h"

namespace mcd {

size_t NforPartlyCovered(const Image &alpha) {
    size_t count = 0;
    for (float a : alpha.data) count += NforPartlyCovered(a);
    return count;
}

Image NforDivideByAlpha(const Image &image, const Image &alpha, int power) {
    Image divided = image;
    for (size_t i = 0; i < alpha.PixelCount(); ++i) {
        const float a = alpha.data[i];
        if (!NforPartlyCovered(a)) continue;
        const float divisor = power == 2 ? a * a : a;
        for (int c = 0; c < divided.channels; ++c) divided.Plane(c)[i] /= divisor;
    }
    return divided;
}

void NforMultiplyByAlpha(const Image &alpha, Image *image) {
    for (size_t i = 0; i < alpha.PixelCount(); ++i) {
        const float a = alpha.data[i];
        if (!NforPartlyCovered(a)) continue;
        for (int c = 0; c < image->channels; ++c) image->Plane(c)[i] *= a;
    }
}

}  // namespace mcd
