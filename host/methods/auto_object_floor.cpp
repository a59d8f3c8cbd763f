// Method `auto`'s object floor (host/methods/auto_object_floor.h).
#include "host/methods/auto_object_floor.h"

#include <algorithm>
#include <cmath>
#include <map>

#include <fmt/format.h>

#include "host/common/parallel.h"
#include "host/error.h"
#include "host/methods/auto_halves.h"

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
    // Each pixel on its own: the pixels split among the cores, each value written once.
    Image mean(image.width, image.height, image.channels);
    const size_t cost = 8 * outputs.size() * size_t(image.channels);
    ParallelValues(pixels, cost, [&](size_t begin, size_t end) {
        for (size_t i = begin; i < end; ++i)
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
                float &value = mean.data[c * pixels + i];
                value = image.data[c * pixels + i];
                if (!(total > 0)) continue;
                double sum = 0;
                for (size_t k = 0; k < outputs.size(); ++k)
                    if (counts(k))
                        sum += weights.data[k * pixels + i] / total *
                               outputs[k]->data[c * pixels + i];
                value = float(sum);
            }
    });
    return mean;
}

Image AutoFloorTarget(const Image &weightedMean, const Image &combination,
                      const Image &restored, const Image *input, float inputShare) {
    if (!weightedMean.SameShape(combination) || !weightedMean.SameShape(restored) ||
        (input && !input->SameShape(restored)))
        throw Error("auto: the floor's target needs images of one shape",
                    ErrorKind::InvalidArgument);
    // Without an input no share of it is taken.
    const double share = input ? inputShare : 0.0;
    Image target = restored;
    for (size_t i = 0; i < target.data.size(); ++i) {
        double mean = double(restored.data[i]) + (weightedMean.data[i] - combination.data[i]);
        target.data[i] = float(share > 0 ? mean + share * (input->data[i] - mean) : mean);
    }
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

namespace {

// One object's sums over the pixels that count: the input's luminance, its variance, the
// halves' difference and each image's luminance.
struct InputSums {
    size_t pixels = 0;
    double input = 0, variance = 0, difference = 0;
    std::vector<double> images;
    // The standard error of the input's sum: the pixels' variance summed, or the halves'
    // difference over the object where that says more (Var(S0 - S1) is four times the
    // variance of the object's sum).
    double Error() const { return std::sqrt(std::max(variance, difference * difference / 4)); }
    bool Halves() const { return difference * difference / 4 > variance; }
};

// Per object of `ids`, the sums over the pixels where the id and every value (the input's,
// its variance, the halves' difference, each of `images`) are finite; `pixelIds` gets each
// pixel's id there, NaN elsewhere. Throws where a size does not match the input's.
std::map<float, InputSums> SumObjects(const Image &ids, const Image &input,
                                      const Image &lumVariance, const Image *half0,
                                      const Image *half1,
                                      const std::vector<const Image *> &images,
                                      std::vector<float> *pixelIds) {
    const size_t pixels = input.PixelCount();
    const bool halves = half0 && half1;
    auto sized = [&](const Image &layer) {
        return layer.width == input.width && layer.height == input.height;
    };
    bool shapes =
        sized(ids) && sized(lumVariance) && (!halves || (sized(*half0) && sized(*half1)));
    for (const Image *image : images) shapes = shapes && image->SameShape(input);
    if (!shapes)
        throw Error(
            "auto: the object sums need ids, input, variance, halves and images of the "
            "input's size",
            ErrorKind::InvalidArgument);
    pixelIds->assign(pixels, NAN);
    std::map<float, InputSums> objects;
    std::vector<double> lum(images.size());
    for (size_t i = 0; i < pixels; ++i) {
        float id = ids.data[i];
        double in = Luminance(input, i), v = lumVariance.data[i];
        double d = halves ? Luminance(*half0, i) - Luminance(*half1, i) : 0;
        bool finite =
            std::isfinite(id) && std::isfinite(in) && std::isfinite(v) && std::isfinite(d);
        for (size_t k = 0; k < images.size(); ++k) {
            lum[k] = Luminance(*images[k], i);
            finite = finite && std::isfinite(lum[k]);
        }
        if (!finite) continue;
        (*pixelIds)[i] = id;
        InputSums &sums = objects[id];
        sums.images.resize(images.size(), 0.0);
        ++sums.pixels;
        sums.input += in;
        sums.variance += v;
        sums.difference += d;
        for (size_t k = 0; k < images.size(); ++k) sums.images[k] += lum[k];
    }
    return objects;
}

}  // namespace

std::vector<AutoObjectLift> AutoObjectLiftToInput(const Image &ids, const Image &input,
                                                  const Image &lumVariance, const Image *half0,
                                                  const Image *half1, double k, Image *image,
                                                  size_t minPixels, size_t *small) {
    const size_t pixels = image->PixelCount();
    // Each pixel's id where every value there is finite, else NaN.
    std::vector<float> pixelIds;
    const std::map<float, InputSums> objects =
        SumObjects(ids, input, lumVariance, half0, half1, {image}, &pixelIds);
    // The scale each object takes: its sum brought to the input's less k standard errors.
    std::map<float, double> scales;
    std::vector<AutoObjectLift> lifted;
    if (small) *small = 0;
    for (const auto &[id, sums] : objects) {
        if (sums.pixels < minPixels) {
            if (small) ++*small;
            continue;
        }
        const double own = sums.images[0], error = sums.Error();
        double bound = sums.input - k * error;
        if (!(own > 0) || !(own < bound)) continue;
        // An object nearly black but for its input is a fault the scale would turn into
        // fireflies: it rises at most kAutoObjectLiftMaxScale times.
        double scale = std::min(bound / own, kAutoObjectLiftMaxScale);
        scales[id] = scale;
        lifted.push_back(
            {id, sums.pixels, own, sums.input, error, bound, scale, sums.Halves()});
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

AutoObjectGuardResult AutoObjectGuardFactors(const Image &ids, const Image &input,
                                             const Image &lumVariance, const Image *half0,
                                             const Image *half1,
                                             const std::vector<const Image *> &outputs,
                                             const AutoObjectGuard &guard) {
    const size_t pixels = input.PixelCount(), count = outputs.size();
    AutoObjectGuardResult result;
    result.factors = Image(input.width, input.height, int(count));
    std::fill(result.factors.data.begin(), result.factors.data.end(), 1.f);
    if (guard.z <= 0) return result;
    std::vector<float> pixelIds;
    const std::map<float, InputSums> objects =
        SumObjects(ids, input, lumVariance, half0, half1, outputs, &pixelIds);
    // Each guarded object's factor per candidate (1: unguarded).
    std::map<float, std::vector<float>> factors;
    const double z2 = double(guard.z) * guard.z;
    for (const auto &[id, sums] : objects) {
        if (sums.pixels < guard.minPixels) {
            ++result.small;
            continue;
        }
        // At least the mean guard's least share of the sum: a departure of a few parts in a
        // hundred of a large object is a candidate's bias, not a faded object.
        const double error = std::max(sums.Error(), kAutoGuardRelative * std::abs(sums.input));
        if (!(error > 0)) continue;
        for (size_t k = 0; k < count; ++k) {
            const double t = (sums.images[k] - sums.input) / error;
            if (!(guard.both ? std::abs(t) > guard.z : t < -guard.z)) continue;
            // The normal density's ratio at z over that at t, as the mean guard's.
            const double factor = std::exp(std::min(0.5 * (t * t - z2), kAutoGuardMostLog));
            std::vector<float> &row = factors[id];
            row.resize(count, 1.f);
            row[k] = float(factor);
            result.hits.push_back({id, sums.pixels, int(k), t, factor});
        }
    }
    for (size_t i = 0; i < pixels && !factors.empty(); ++i) {
        if (std::isnan(pixelIds[i])) continue;
        auto it = factors.find(pixelIds[i]);
        if (it == factors.end()) continue;
        for (size_t k = 0; k < count; ++k) result.factors.data[k * pixels + i] = it->second[k];
    }
    return result;
}

void AutoApplyObjectGuard(Image &smooth, const Image &factors, float floorError) {
    if (factors.Empty()) return;
    if (factors.width != smooth.width || factors.height != smooth.height ||
        factors.channels != smooth.channels)
        throw Error("auto: the object guard's factors need one plane per estimate",
                    ErrorKind::Internal);
    for (size_t i = 0; i < smooth.data.size(); ++i) {
        const float factor = factors.data[i];
        float &e = smooth.data[i];
        // An unguarded pixel keeps its estimate to the bit; a left-out one (inf) stays out.
        if (factor == 1.f || !std::isfinite(e)) continue;
        e = float(double(std::max(e, floorError)) * factor);
    }
}

}  // namespace mcd
