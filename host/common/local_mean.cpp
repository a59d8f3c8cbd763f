#include "host/common/local_mean.h"

#include <algorithm>
#include <cmath>

#include "host/error.h"

namespace mcd {
namespace {

// Box means of radius r along rows or columns, clipped to the image. Each window summed
// on its own, in order: a pixel's mean does not depend on where the image starts (a tile
// gives the whole frame's values).
void BoxPass(const float *in, float *out, int w, int h, int r, bool rows) {
    int length = rows ? w : h, lines = rows ? h : w;
    size_t along = rows ? 1 : size_t(w), across = rows ? size_t(w) : 1;
    for (int line = 0; line < lines; ++line) {
        const float *src = in + line * across;
        float *dst = out + line * across;
        for (int i = 0; i < length; ++i) {
            int a = std::max(0, i - r), b = std::min(length - 1, i + r);
            double sum = 0;
            for (int j = a; j <= b; ++j) sum += src[j * along];
            dst[i * along] = float(sum / (b - a + 1));
        }
    }
}

}  // namespace

Image TentMean(const Image &image, int r) {
    Image a(image.width, image.height, image.channels), b = a;
    for (int c = 0; c < image.channels; ++c) {
        BoxPass(image.Plane(c), a.Plane(c), image.width, image.height, r, true);
        BoxPass(a.Plane(c), b.Plane(c), image.width, image.height, r, false);
        BoxPass(b.Plane(c), a.Plane(c), image.width, image.height, r, true);
        BoxPass(a.Plane(c), b.Plane(c), image.width, image.height, r, false);
    }
    return b;
}

LocalMeanFactors RestoreLocalMeans(const Image &input, int r, Image *output) {
    if (!input.SameShape(*output) || r <= 0)
        throw Error("RestoreLocalMeans: the output must have the input's shape, r > 0",
                    ErrorKind::Internal);
    // The values the method left as they were (an emitter without a pivot, an exact zero
    // restored) are left out of both means and kept: mass balances without them.
    Image clean = input, moved = *output;
    for (size_t i = 0; i < clean.data.size(); ++i) {
        float v = input.data[i];
        bool kept = output->data[i] == v;
        clean.data[i] = !kept && std::isfinite(v) && v > 0 ? v : 0.f;
        if (kept) moved.data[i] = 0;
    }
    Image mIn = TentMean(clean, r), mOut = TentMean(moved, r);
    LocalMeanFactors factors;
    bool any = false;
    for (size_t i = 0; i < mIn.data.size(); ++i) {
        if (output->data[i] == input.data[i]) continue;
        float a = mIn.data[i], b = mOut.data[i];
        if (!(a > 0 && b > 0 && std::isfinite(a) && std::isfinite(b))) continue;
        double ratio = double(a) / b;
        output->data[i] = float(output->data[i] * ratio);
        factors.lo = any ? std::min(factors.lo, ratio) : ratio;
        factors.hi = any ? std::max(factors.hi, ratio) : ratio;
        any = true;
    }
    return factors;
}

}  // namespace mcd
