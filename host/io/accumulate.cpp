#include "host/io/accumulate.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>

#include "host/error.h"
#include "host/io/image_file.h"
#include "host/io/layer_names.h"

namespace mcd::io {

namespace {

// Averaged over the frames; the light passes and guides are linear in the samples, so
// their mean over frames is their mean over all samples.
bool IsMeanLayer(const std::string &name) {
    return name == "albedo" || name == "normal" || name == "depth" || name == "pivot" ||
           name == "direct" || name == "indirect" || name == "alpha";
}

// Ids are not averaged: a mean of two ids is a third id.
bool IsFirstLayer(const std::string &name) {
    return name == "objectId" || name == "partId";
}

// Averaged, and the variance of their mean measured from the spread of the frames (auto's
// estimate of bayes's split output reads it).
bool HasSpread(const std::string &name) {
    return name == "direct" || name == "indirect";
}

// Made anew from the frames (an input's own variance and hist describe one frame only).
bool IsRecomputed(const std::string &name) {
    return name == "color" || name == "variance" || name == "spp" || name == "min" ||
           name == "max" || name == "hist" || name == "direct.variance" ||
           name == "indirect.variance";
}

bool AllFinite(const Image &image, size_t i) {
    for (int c = 0; c < image.channels; ++c)
        if (!std::isfinite(image.Plane(c)[i])) return false;
    return true;
}

}  // namespace

std::vector<std::string> AccumulatorReads() {
    return {"color", "spp",    "min",      "max",   "albedo",   "normal", "depth",
            "pivot", "direct", "indirect", "alpha", "objectId", "partId"};
}

bool AccumulatorKeeps(const std::string &layer) {
    return IsMeanLayer(layer) || IsFirstLayer(layer) || IsRecomputed(layer);
}

FrameHeader ReadFrameHeader(const std::string &path) {
    ImageHeader spec = ReadImageHeader(path);
    FrameHeader header;
    header.path = path;
    header.width = spec.width;
    header.height = spec.height;
    try {
        for (const LayerChannels &layer : GroupChannels(spec.channelNames))
            header.layers[layer.name] = int(layer.channels.size());
    } catch (const Error &e) {
        throw Error(fmt::format("cannot read '{}': {}", path, e.what()), ErrorKind::Io);
    }
    for (const auto &[name, value] : spec.strings)
        if (!name.starts_with("oiio:")) header.metadata[name] = value;
    for (const auto &[name, value] : spec.ints) header.metadata[name] = std::to_string(value);
    AddWindows(spec, header.metadata);
    return header;
}

void CheckSameLayout(const FrameHeader &first, const FrameHeader &other) {
    if (other.width != first.width || other.height != first.height)
        throw Error(fmt::format("'{}' is {}x{} but '{}' is {}x{}: accumulate needs one size",
                                other.path, other.width, other.height, first.path, first.width,
                                first.height),
                    ErrorKind::InvalidArgument);
    // The frames' pixels must be the same pixels of the image.
    auto window = [](const FrameHeader &h) {
        auto it = h.metadata.find(kDataWindowKey);
        return it == h.metadata.end() ? WindowText(0, 0, h.width, h.height) : it->second;
    };
    if (window(other) != window(first))
        throw Error(fmt::format("'{}' has data window {} but '{}' has {}: accumulate needs one "
                                "window",
                                other.path, window(other), first.path, window(first)),
                    ErrorKind::InvalidArgument);
    auto list = [](const std::map<std::string, int> &layers) {
        std::string text;
        for (const auto &[name, channels] : layers)
            text += fmt::format("{}{} ({})", text.empty() ? "" : ", ", name, channels);
        return text;
    };
    if (other.layers != first.layers)
        throw Error(fmt::format("'{}' has layers {} but '{}' has {}: accumulate needs the "
                                "same layers in every frame",
                                other.path, list(other.layers), first.path, list(first.layers)),
                    ErrorKind::InvalidArgument);
}

namespace {

// Where one channel's value falls: bins `low` and `low + 1` get 1 - high and high.
void RhfBin(double value, int bins, int *low, double *high) {
    const double gamma = 2.2, scale = 2.5, saturation = 2.0;
    double v = std::max(value, 0.0);
    v = std::min(std::pow(v, 1 / gamma) / scale, saturation);
    double fbin = v * (bins - 2);
    *low = int(std::floor(fbin));
    if (*low < bins - 2) {
        *high = fbin - *low;
    } else {
        // The last bin stands for the saturation value: split [1, saturation] linearly.
        *low = bins - 2;
        *high = (v - 1) / (saturation - 1);
    }
}

}  // namespace

void AddToRhfHistogram(const double color[3], int bins, float *histogram) {
    for (int c = 0; c < 3; ++c) {
        int low;
        double high;
        RhfBin(color[c], bins, &low, &high);
        histogram[c * bins + low] += float(1 - high);
        histogram[c * bins + low + 1] += float(high);
    }
}

Accumulator::Accumulator(AccumulateOptions options) : options(options) {
    if (options.histBins < 3)
        throw Error("a histogram needs at least 3 bins per channel",
                    ErrorKind::InvalidArgument);
    if (options.half0Layers) {
        AccumulateOptions inner = options;
        inner.half0Layers = false;
        half0 = std::make_unique<Accumulator>(inner);
    }
}

void Accumulator::Start(const Frame &frame) {
    firstPath = frame.path;
    width = frame.width, height = frame.height;
    size_t n = size_t(width) * height;
    for (const auto &[name, image] : frame.layers) layout[name] = image.channels;
    mean.assign(3 * n, 0), m2.assign(3 * n, 0), spp.assign(n, 0), count.assign(n, 0);
    lo.assign(3 * n, std::numeric_limits<float>::infinity());
    hi.assign(3 * n, -std::numeric_limits<float>::infinity());
    hist = Image(width, height, 3 * options.histBins + 1);
    for (MeanLayer &half : halves) half = {std::vector<double>(3 * n), {}, 3};
    for (MeanLayer &half : halves) half.count.assign(n, 0);
    for (const auto &[name, image] : frame.layers) {
        if (IsMeanLayer(name))
            means[name] = {std::vector<double>(size_t(image.channels) * n),
                           std::vector<uint32_t>(n), image.channels,
                           HasSpread(name) ? std::vector<double>(size_t(image.channels) * n)
                                           : std::vector<double>()};
        else if (IsFirstLayer(name))
            firstOf[name] = image;
        else if (!IsRecomputed(name))
            dropped.push_back(name);
    }
    firstRays["color"] = frame.Get("color");
    for (const char *name : {"albedo", "normal", "depth"})
        if (frame.Has(name)) {
            rayLayers.push_back(name);
            firstRays[name] = frame.Get(name);
        }
}

void Accumulator::CompareWithFirst(const Frame &frame) {
    for (auto it = firstRays.begin(); it != firstRays.end();) {
        const std::vector<float> &first = it->second.data, &data = frame.Get(it->first).data;
        // Bits, not float ==: the same ray gives the same bits, NaN included.
        if (std::memcmp(first.data(), data.data(), first.size() * sizeof(float)) == 0) {
            ++it;
            continue;
        }
        (it->first == "color" ? colorDiffers : geometryDiffers) = true;
        it = firstRays.erase(it);
    }
    // One geometry layer that differs settles it: the rays differ.
    if (geometryDiffers) firstRays.clear();
}

CameraRays Accumulator::SharedCameraRays() const {
    if (frames < 2) return CameraRays::Unknown;
    if (geometryDiffers) return CameraRays::Distinct;
    if (!colorDiffers) return CameraRays::Identical;
    return rayLayers.empty() ? CameraRays::Unknown : CameraRays::Shared;
}

void Accumulator::AddMean(MeanLayer &layer, const std::string &name, const Image &image) {
    size_t n = image.PixelCount();
    for (size_t i = 0; i < n; ++i) {
        if (!AllFinite(image, i)) {
            ++nonFinite[name];
            continue;
        }
        uint32_t k = ++layer.count[i];
        for (int c = 0; c < layer.channels; ++c) {
            size_t j = c * n + i;
            double value = image.Plane(c)[i];
            if (!layer.m2.empty() && k > 1) {
                // Welford, with the running mean kept as the sum.
                double before = layer.sum[j] / (k - 1), after = (layer.sum[j] + value) / k;
                layer.m2[j] += (value - before) * (value - after);
            }
            layer.sum[j] += value;
        }
    }
}

void Accumulator::Add(const Frame &frame) {
    const Image &color = frame.Get("color");
    if (color.channels != 3)
        throw Error(fmt::format("'{}': color has {} channels; accumulate needs R, G, B",
                                frame.path, color.channels),
                    ErrorKind::InvalidArgument);
    if (frames == 0) {
        Start(frame);
    } else {
        FrameHeader a{firstPath, width, height, layout, {}},
            b{frame.path, frame.width, frame.height, {}, {}};
        for (const auto &[name, image] : frame.layers) b.layers[name] = image.channels;
        CheckSameLayout(a, b);
        CompareWithFirst(frame);
    }
    size_t n = size_t(width) * height;
    const Image *sppLayer = frame.Has("spp") ? &frame.Get("spp") : nullptr;
    const Image *minLayer = frame.Has("min") ? &frame.Get("min") : nullptr;
    const Image *maxLayer = frame.Has("max") ? &frame.Get("max") : nullptr;
    int metadataSpp = SppFromMetadata(frame.metadata);
    MeanLayer &half = halves[frames % 2];
    const int bins = options.histBins;
    for (size_t i = 0; i < n; ++i) {
        // A pixel with a NaN/Inf channel is left out whole, so that its count stays one
        // for all three channels and the histogram.
        if (!AllFinite(color, i)) {
            ++nonFinite["color"];
            continue;
        }
        double value[3];
        uint32_t k = ++count[i];
        for (int c = 0; c < 3; ++c) {
            value[c] = color.Plane(c)[i];
            size_t j = c * n + i;
            double delta = value[c] - mean[j];
            mean[j] += delta / k;
            m2[j] += delta * (value[c] - mean[j]);
            half.sum[j] += value[c];
        }
        ++half.count[i];
        float frameSpp = metadataSpp > 0 ? float(metadataSpp) : 1.f;
        if (sppLayer) {
            float v = sppLayer->Plane(0)[i];
            if (std::isfinite(v) && v > 0)
                frameSpp = v;
            else
                ++nonFinite["spp"];
        }
        spp[i] += frameSpp;
        for (int c = 0; c < 3; ++c) {
            int low;
            double high;
            RhfBin(value[c], bins, &low, &high);
            hist.Plane(c * bins + low)[i] += float(1 - high);
            hist.Plane(c * bins + low + 1)[i] += float(high);
        }
    }
    // min and max: the frames' own sample ranges when they have them, else their means.
    for (int c = 0; c < 3; ++c) {
        const float *low = (minLayer ? *minLayer : color).Plane(c);
        const float *high = (maxLayer ? *maxLayer : color).Plane(c);
        for (size_t i = 0; i < n; ++i) {
            size_t j = c * n + i;
            if (std::isfinite(low[i]))
                lo[j] = std::min(lo[j], low[i]);
            else if (minLayer)
                ++nonFinite["min"];
            if (std::isfinite(high[i]))
                hi[j] = std::max(hi[j], high[i]);
            else if (maxLayer)
                ++nonFinite["max"];
        }
    }
    for (auto &[name, layer] : means) AddMean(layer, name, frame.Get(name));
    for (const auto &[name, image] : firstOf)
        if (frames == 0)
            for (size_t i = 0; i < n; ++i)
                if (!AllFinite(image, i)) ++nonFinite[name];
    // half0's frames again, alone (their non-finite values are counted above).
    if (half0 && frames % 2 == 0) half0->Add(frame);
    ++frames;
}

Frame Accumulator::Finish() {
    if (frames == 0)
        throw Error("accumulate: no frames were added", ErrorKind::InvalidArgument);
    size_t n = size_t(width) * height;
    Frame out;
    out.width = width, out.height = height;
    Image color(width, height, 3), variance(width, height, 3), sppImage(width, height, 1);
    Image mn(width, height, 3), mx(width, height, 3);
    for (size_t i = 0; i < n; ++i) {
        double k = count[i];
        sppImage.data[i] = float(spp[i]);
        hist.Plane(3 * options.histBins)[i] = float(k);
        for (int c = 0; c < 3; ++c) {
            size_t j = c * n + i;
            color.data[j] = k > 0 ? float(mean[j]) : 0.f;
            // Variance of the mean: the unbiased variance of the frame means over their
            // count, as the renderer's over its samples; 0 with one frame, as there.
            variance.data[j] = k > 1 ? float(m2[j] / (k - 1) / k) : 0.f;
            mn.data[j] = std::isfinite(lo[j]) ? lo[j] : 0.f;
            mx.data[j] = std::isfinite(hi[j]) ? hi[j] : 0.f;
        }
    }
    out.layers["color"] = std::move(color);
    out.layers["variance"] = std::move(variance);
    out.layers["spp"] = std::move(sppImage);
    out.layers["min"] = std::move(mn);
    out.layers["max"] = std::move(mx);
    out.layers["hist"] = std::move(hist);
    auto meanOf = [&](const MeanLayer &layer) {
        Image image(width, height, layer.channels);
        for (int c = 0; c < layer.channels; ++c)
            for (size_t i = 0; i < n; ++i)
                image.Plane(c)[i] =
                    layer.count[i] ? float(layer.sum[c * n + i] / layer.count[i]) : 0.f;
        return image;
    };
    out.layers["half0.color"] = meanOf(halves[0]);
    out.layers["half1.color"] = meanOf(halves[1]);
    for (const auto &[name, layer] : means) {
        out.layers[name] = meanOf(layer);
        if (layer.m2.empty()) continue;
        // As color's variance: of the mean, unbiased, 0 with one frame.
        Image spread(width, height, layer.channels);
        for (int c = 0; c < layer.channels; ++c)
            for (size_t i = 0; i < n; ++i) {
                double k = layer.count[i];
                spread.Plane(c)[i] = k > 1 ? float(layer.m2[c * n + i] / (k - 1) / k) : 0.f;
            }
        out.layers[name + ".variance"] = std::move(spread);
    }
    for (auto &[name, image] : firstOf) out.layers[name] = std::move(image);
    // half0's own layers: from three frames on, so half0 holds two and its variances are
    // not 0 (with one frame there is no half1 to keep them apart from).
    if (half0 && frames > 2) {
        Frame own = half0->Finish();
        for (auto &[name, image] : own.layers)
            if (IsHalf0LayerName("half0." + name))
                out.layers["half0." + name] = std::move(image);
    }
    out.metadata["mcd:accumulatedFrames"] = std::to_string(frames);
    // "1" when the frames share their camera rays (identical frames do too), "0" when
    // they do not, absent when it cannot tell.
    CameraRays rays = SharedCameraRays();
    if (rays != CameraRays::Unknown)
        out.metadata["mcd:sharedCameraRays"] =
            std::to_string(rays == CameraRays::Distinct ? 0 : 1);
    return out;
}

}  // namespace mcd::io
