#include "cpu_reference/exact_pixels.h"

#include <cmath>

namespace mcd::ref {

void KeepExactPixels(const Image &input, const Image &variance, Image *output) {
    if (variance.width != input.width || variance.height != input.height) return;
    if (variance.channels != 1 && variance.channels != input.channels) return;
    for (int c = 0; c < input.channels; ++c)
        for (int y = 0; y < input.height; ++y)
            for (int x = 0; x < input.width; ++x) {
                double v = variance.At(variance.channels == 1 ? 0 : c, y, x);
                double in = input.At(c, y, x);
                if (v == 0 && std::isfinite(in) && in > 0)
                    output->At(c, y, x) = input.At(c, y, x);
            }
}

}  // namespace mcd::ref
