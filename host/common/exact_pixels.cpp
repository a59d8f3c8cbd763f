#include "host/common/exact_pixels.h"

#include <cmath>
#include <limits>

#include "host/error.h"

namespace mcd {

size_t KeepExactPixels(const Image &input, const Image &variance, Image *output) {
    if (!input.SameShape(*output))
        throw Error("KeepExactPixels: the output must have the input's shape",
                    ErrorKind::Internal);
    if (variance.width != input.width || variance.height != input.height ||
        (variance.channels != 1 && variance.channels != input.channels))
        return 0;
    const size_t n = input.PixelCount();
    size_t kept = 0;
    for (int c = 0; c < input.channels; ++c) {
        const float *in = input.Plane(c);
        const float *var = variance.Plane(variance.channels == 1 ? 0 : c);
        float *out = output->Plane(c);
        for (size_t p = 0; p < n; ++p) {
            if (!(var[p] == 0 && std::isfinite(in[p]) && in[p] > 0)) continue;
            ++kept;
            out[p] = in[p];
        }
    }
    return kept;
}

Image ExactVariance(const ExactLayers &layers) {
    if (layers.variance) return *layers.variance;
    if (!layers.min || !layers.max || !layers.spp) return Image();
    const Image &min = *layers.min, &max = *layers.max, &spp = *layers.spp;
    if (!min.SameShape(max) || spp.width != min.width || spp.height != min.height)
        return Image();
    Image variance(min.width, min.height, min.channels);
    for (int c = 0; c < min.channels; ++c)
        for (int y = 0; y < min.height; ++y)
            for (int x = 0; x < min.width; ++x) {
                double range = double(max.At(c, y, x)) - min.At(c, y, x);
                double count = spp.At(0, y, x);
                // No samples: nothing is known.
                variance.At(c, y, x) = count > 0 ? float(range * range / count)
                                                 : std::numeric_limits<float>::infinity();
            }
    return variance;
}

}  // namespace mcd
