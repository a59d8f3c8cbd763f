// Method `auto`'s object floor (host/methods/auto_object_floor.h).
#include "host/methods/auto_object_floor.h"

#include <algorithm>
#include <cmath>
#include <map>

#include <fmt/format.h>

#include "host/error.h"

namespace mcd {
namespace {

// Rec. 709 luminance of the first three channels, else the channels' mean.
double Luminance(const Image &image, size_t i) {
    const size_t pixels = image.PixelCount();
    if (image.channels >= 3)
        return 0.2126 * image.data[i] + 0.7152 * image.data[pixels + i] +
               0.0722 * image.data[2 * pixels + i];
    double sum = 0;
    for (int c = 0; c < image.channels; ++c) sum += image.data[c * pixels + i];
    return sum / image.channels;
}

// The luminance (as Luminance) of the channels' standard deviations, from their variances.
double DeviationLuminance(const Image &variance, size_t i) {
    const size_t pixels = variance.PixelCount();
    auto deviation = [&](int c) {
        // A NaN stays NaN, so that the pixel is left out of the sums.
        double v = variance.data[c * pixels + i];
        return std::isnan(v) ? v : std::sqrt(std::max(0.0, v));
    };
    if (variance.channels >= 3)
        return 0.2126 * deviation(0) + 0.7152 * deviation(1) + 0.0722 * deviation(2);
    double sum = 0;
    for (int c = 0; c < variance.channels; ++c) sum += deviation(c);
    return sum / variance.channels;
}

// One object's sums over the pixels that count.
struct ObjectSums {
    size_t pixels = 0;
    double image = 0, weighted = 0;
    std::vector<double> outputs;
};

}  // namespace

Image AutoWeightedMean(const std::vector<const Image *> &outputs, const Image &weights,
                       const Image &image) {
    const size_t pixels = image.PixelCount();
    bool shapes = weights.width == image.width && weights.height == image.height &&
                  size_t(weights.channels) == outputs.size() &&
                  weights.data.size() == pixels * outputs.size();
    for (const Image *output : outputs) shapes = shapes && output->SameShape(image);
    if (!shapes)
        throw Error(
            fmt::format("auto: the weighted mean needs one weight plane per output ({}) "
                        "and outputs of the image's shape",
                        outputs.size()),
            ErrorKind::InvalidArgument);
    Image mean = image;
    for (size_t i = 0; i < pixels; ++i)
        for (int c = 0; c < image.channels; ++c) {
            // Normalise over the pairs that count, so a non-finite value biases nothing.
            auto counts = [&](size_t k) {
                float w = weights.data[k * pixels + i];
                return w > 0 && std::isfinite(w) &&
                       std::isfinite(outputs[k]->data[c * pixels + i]);
            };
            double total = 0;
            for (size_t k = 0; k < outputs.size(); ++k)
                if (counts(k)) total += weights.data[k * pixels + i];
            if (!(total > 0)) continue;
            double sum = 0;
            for (size_t k = 0; k < outputs.size(); ++k)
                if (counts(k))
                    sum +=
                        weights.data[k * pixels + i] / total * outputs[k]->data[c * pixels + i];
            mean.data[c * pixels + i] = float(sum);
        }
    return mean;
}

Image AutoFloorTarget(const Image &weightedMean, const Image &combination,
                      const Image &restored) {
    if (!weightedMean.SameShape(combination) || !weightedMean.SameShape(restored))
        throw Error("auto: the floor's target needs images of one shape",
                    ErrorKind::InvalidArgument);
    Image target = restored;
    for (size_t i = 0; i < target.data.size(); ++i)
        target.data[i] = restored.data[i] + (weightedMean.data[i] - combination.data[i]);
    return target;
}

std::vector<AutoObjectMove> AutoObjectFloor(const Image &ids,
                                            const std::vector<const Image *> &outputs,
                                            const Image &weighted, double level, Image *image,
                                            size_t minPixels, size_t *small) {
    const size_t pixels = image->PixelCount();
    // Each pixel's id where every image's luminance there is finite, else NaN.
    std::vector<float> pixelIds(pixels, NAN);
    std::map<float, ObjectSums> objects;
    std::vector<double> lum(outputs.size());
    for (size_t i = 0; i < pixels; ++i) {
        float id = ids.data[i];
        double own = Luminance(*image, i), mean = Luminance(weighted, i);
        bool finite = std::isfinite(id) && std::isfinite(own) && std::isfinite(mean);
        for (size_t k = 0; k < outputs.size(); ++k) {
            lum[k] = Luminance(*outputs[k], i);
            finite = finite && std::isfinite(lum[k]);
        }
        if (!finite) continue;
        pixelIds[i] = id;
        ObjectSums &sums = objects[id];
        sums.outputs.resize(outputs.size(), 0.0);
        ++sums.pixels;
        sums.image += own;
        sums.weighted += mean;
        for (size_t k = 0; k < outputs.size(); ++k) sums.outputs[k] += lum[k];
    }
    // The fraction each object moves: its sum brought to `level` times the darkest candidate's.
    std::map<float, double> alphas;
    std::vector<AutoObjectMove> moved;
    if (small) *small = 0;
    for (const auto &[id, sums] : objects) {
        if (sums.pixels < minPixels) {
            if (small) ++*small;
            continue;
        }
        if (sums.outputs.empty()) continue;
        int darkest = int(std::min_element(sums.outputs.begin(), sums.outputs.end()) -
                          sums.outputs.begin());
        double target = sums.outputs[darkest], floor = level * target;
        if (!(target > 0)) continue;  // a level of a sum at or below 0 is no floor
        if (!(sums.image < floor) || !(sums.weighted > sums.image)) continue;
        double alpha = std::min(1.0, (floor - sums.image) / (sums.weighted - sums.image));
        alphas[id] = alpha;
        moved.push_back({id, sums.pixels, sums.image, target, sums.weighted, darkest, alpha});
    }
    if (alphas.empty()) return moved;
    for (size_t i = 0; i < pixels; ++i) {
        if (std::isnan(pixelIds[i])) continue;
        auto it = alphas.find(pixelIds[i]);
        if (it == alphas.end()) continue;
        for (int c = 0; c < image->channels; ++c) {
            float &v = image->data[c * pixels + i];
            v = float(v + it->second * (double(weighted.data[c * pixels + i]) - v));
        }
    }
    return moved;
}

Image AutoLuminanceVariance(const Image &color, const Image *variance, const Image *half0,
                            const Image *half1) {
    if (!variance && !(half0 && half1)) return Image();
    auto sized = [&](const Image &layer) {
        return layer.width == color.width && layer.height == color.height && layer.channels > 0;
    };
    if (variance ? !sized(*variance) : !sized(*half0) || !sized(*half1))
        throw Error("auto: the object lift's variance needs layers of the colour's size",
                    ErrorKind::InvalidArgument);
    const size_t pixels = color.PixelCount();
    Image out(color.width, color.height, 1);
    for (size_t i = 0; i < pixels; ++i) {
        double v;
        if (variance) {
            // Fully correlated channels: the luminance's deviation is the weighted sum of
            // the channels' deviations.
            double d = DeviationLuminance(*variance, i);
            v = d * d;
        } else {
            // Each half holds half the samples: Var(h0 - h1) is four times the mean's.
            double d = Luminance(*half0, i) - Luminance(*half1, i);
            v = d * d / 4;
        }
        out.data[i] = float(v);
    }
    return out;
}

std::vector<AutoObjectLift> AutoObjectLiftToInput(const Image &ids, const Image &input,
                                                  const Image &lumVariance, const Image *half0,
                                                  const Image *half1, double k, Image *image,
                                                  size_t minPixels, size_t *small) {
    const size_t pixels = image->PixelCount();
    const bool halves = half0 && half1;
    if (!input.SameShape(*image) || ids.width != image->width || ids.height != image->height ||
        lumVariance.width != image->width || lumVariance.height != image->height ||
        (halves && (half0->width != image->width || half0->height != image->height ||
                    half1->width != image->width || half1->height != image->height)))
        throw Error(
            "auto: the object lift needs ids, input, variance and halves of the "
            "image's size",
            ErrorKind::InvalidArgument);
    struct Sums {
        size_t pixels = 0;
        double image = 0, input = 0, variance = 0, difference = 0;
    };
    // Each pixel's id where every value there is finite, else NaN.
    std::vector<float> pixelIds(pixels, NAN);
    std::map<float, Sums> objects;
    for (size_t i = 0; i < pixels; ++i) {
        float id = ids.data[i];
        double own = Luminance(*image, i), in = Luminance(input, i);
        double v = lumVariance.data[i];
        double d = halves ? Luminance(*half0, i) - Luminance(*half1, i) : 0;
        if (!std::isfinite(id) || !std::isfinite(own) || !std::isfinite(in) ||
            !std::isfinite(v) || !std::isfinite(d))
            continue;
        pixelIds[i] = id;
        Sums &sums = objects[id];
        ++sums.pixels;
        sums.image += own;
        sums.input += in;
        sums.variance += v;
        sums.difference += d;
    }
    // The scale each object takes: its sum brought to the input's less k standard errors.
    std::map<float, double> scales;
    std::vector<AutoObjectLift> lifted;
    if (small) *small = 0;
    for (const auto &[id, sums] : objects) {
        if (sums.pixels < minPixels) {
            if (small) ++*small;
            continue;
        }
        // Var(S0 - S1) is four times the variance of the object's sum.
        double shared = sums.difference * sums.difference / 4;
        double error = std::sqrt(std::max(sums.variance, shared));
        double bound = sums.input - k * error;
        if (!(sums.image > 0) || !(sums.image < bound)) continue;
        // An object nearly black but for its input is a fault the scale would turn into
        // fireflies: it rises at most kAutoObjectLiftMaxScale times.
        double scale = std::min(bound / sums.image, kAutoObjectLiftMaxScale);
        scales[id] = scale;
        lifted.push_back({id, sums.pixels, sums.image, sums.input, error, bound, scale,
                          shared > sums.variance});
    }
    if (scales.empty()) return lifted;
    // Scale the channels the luminance reads (a fourth, alpha, keeps its value).
    const int lit = image->channels >= 3 ? 3 : image->channels;
    for (size_t i = 0; i < pixels; ++i) {
        if (std::isnan(pixelIds[i])) continue;
        auto it = scales.find(pixelIds[i]);
        if (it == scales.end()) continue;
        for (int c = 0; c < lit; ++c) {
            float &v = image->data[c * pixels + i];
            v = float(v * it->second);
        }
    }
    return lifted;
}

}  // namespace mcd
