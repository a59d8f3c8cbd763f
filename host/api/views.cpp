// mcd::Frame's layers, owned or borrowed, and the copies between the caller's buffers
// (views) and planar images.
#include <fmt/format.h>

#include <algorithm>
#include <cstring>
#include <type_traits>

#include "host/api/views.h"
#include "host/common/half.h"
#include "mcdenoise/error.h"

namespace mcd {

namespace {

// The element at (x, y, c) of a resolved view.
template <class Pointer>
auto ElementAt(const BasicView<Pointer> &view, int x, int y, int c) {
    using Byte = std::conditional_t<std::is_const_v<std::remove_pointer_t<Pointer>>,
                                    const unsigned char, unsigned char>;
    return static_cast<Byte *>(view.data) + std::ptrdiff_t(y) * view.rowStride +
           std::ptrdiff_t(x) * view.pixelStride + std::ptrdiff_t(c) * view.channelStride;
}

}  // namespace

namespace api {

template <class Pointer>
void CheckView(const BasicView<Pointer> &view, const std::string &what) {
    if (!view.data)
        throw Error(fmt::format("{}: the view has no data", what), ErrorKind::InvalidArgument);
    if (view.width < 1 || view.height < 1 || view.channels < 1)
        throw Error(fmt::format("{}: the view is {}x{} with {} channel(s); each must be at "
                                "least 1",
                                what, view.width, view.height, view.channels),
                    ErrorKind::InvalidArgument);
    if (view.type != DataType::Float32 && view.type != DataType::Float16)
        throw Error(fmt::format("{}: unknown data type {}", what, int(view.type)),
                    ErrorKind::InvalidArgument);
}
template void CheckView(const LayerView &, const std::string &);
template void CheckView(const OutputView &, const std::string &);

void WriteView(const Image &image, const OutputView &output, int first) {
    OutputView view = output.Resolved();
    for (int c = 0; c < image.channels; ++c)
        for (int y = 0; y < image.height; ++y) {
            const float *row = image.Plane(c) + size_t(y) * image.width;
            for (int x = 0; x < image.width; ++x) {
                unsigned char *at = ElementAt(view, x, y, first + c);
                if (view.type == DataType::Float16) {
                    uint16_t half = FloatToHalf(row[x]);
                    std::memcpy(at, &half, sizeof half);
                } else {
                    std::memcpy(at, &row[x], sizeof(float));
                }
            }
        }
}

void CheckOutput(const Frame &frame, const OutputView &output) {
    CheckView(output, "the output");
    if (output.width != frame.width || output.height != frame.height)
        throw Error(fmt::format("the output is {}x{}, the frame {}x{}", output.width,
                                output.height, frame.width, frame.height),
                    ErrorKind::InvalidArgument);
    if (!frame.Has("color")) return;  // the method says what it misses
    int channels = frame.Channels("color");
    if (output.channels != channels && output.channels != channels + 1)
        throw Error(fmt::format("the output has {} channel(s); the color has {}, so it takes "
                                "{} (color) or {} (color and alpha)",
                                output.channels, channels, channels, channels + 1),
                    ErrorKind::InvalidArgument);
}

void WriteOutput(const Image &color, const Image &alpha, const OutputView &output) {
    if (output.width != color.width || output.height != color.height ||
        (output.channels != color.channels && output.channels != color.channels + 1))
        throw Error(fmt::format("the output is {}x{}x{}, the result {}x{}x{}", output.width,
                                output.height, output.channels, color.width, color.height,
                                color.channels),
                    ErrorKind::InvalidArgument);
    WriteView(color, output, 0);
    if (output.channels == color.channels) return;
    if (alpha.width == color.width && alpha.height == color.height && alpha.channels >= 1) {
        Image first(alpha.width, alpha.height, 1);
        std::copy_n(alpha.Plane(0), alpha.PixelCount(), first.Plane(0));
        WriteView(first, output, color.channels);
    } else {
        WriteView(Image(color.width, color.height, 1, 1.f), output, color.channels);
    }
}

}  // namespace api

Image CopyView(const LayerView &layer) {
    api::CheckView(layer, "CopyView");
    LayerView view = layer.Resolved();
    Image image(view.width, view.height, view.channels);
    for (int c = 0; c < view.channels; ++c)
        for (int y = 0; y < view.height; ++y) {
            float *row = image.Plane(c) + size_t(y) * view.width;
            for (int x = 0; x < view.width; ++x) {
                const unsigned char *at = ElementAt(view, x, y, c);
                if (view.type == DataType::Float16) {
                    uint16_t half;
                    std::memcpy(&half, at, sizeof half);
                    row[x] = HalfToFloat(half);
                } else {
                    std::memcpy(&row[x], at, sizeof(float));
                }
            }
        }
    return image;
}

namespace {

// Size the frame by its first layer; else refuse a layer of another size.
void Fit(Frame &frame, const std::string &name, int width, int height) {
    if (frame.layers.empty() && frame.views.empty() && frame.width == 0 && frame.height == 0) {
        frame.width = width;
        frame.height = height;
    }
    if (width != frame.width || height != frame.height)
        throw Error(fmt::format("layer '{}' is {}x{}, the frame {}x{}", name, width, height,
                                frame.width, frame.height),
                    ErrorKind::InvalidArgument);
}

}  // namespace

void Frame::SetLayer(const std::string &name, const LayerView &view) {
    api::CheckView(view, fmt::format("layer '{}'", name));
    Fit(*this, name, view.width, view.height);
    layers.erase(name);
    views[name] = view;
}

void Frame::SetLayer(const std::string &name, Image image) {
    if (image.width < 1 || image.height < 1 || image.channels < 1 ||
        image.data.size() != size_t(image.width) * image.height * image.channels)
        throw Error(
            fmt::format("layer '{}': the image is {}x{} with {} channel(s) and {} "
                        "values",
                        name, image.width, image.height, image.channels, image.data.size()),
            ErrorKind::InvalidArgument);
    Fit(*this, name, image.width, image.height);
    views.erase(name);
    layers[name] = std::move(image);
}

bool Frame::Has(const std::string &layer) const {
    return layers.count(layer) > 0 || views.count(layer) > 0;
}

std::vector<std::string> Frame::Names() const {
    std::vector<std::string> names;
    for (const auto &[name, image] : layers) names.push_back(name);
    for (const auto &[name, view] : views)
        if (!layers.count(name)) names.push_back(name);
    std::sort(names.begin(), names.end());
    return names;
}

int Frame::Channels(const std::string &layer) const {
    if (auto it = views.find(layer); it != views.end()) return it->second.channels;
    return Get(layer).channels;
}

const Image &Frame::Get(const std::string &layer) const {
    if (auto it = layers.find(layer); it != layers.end()) return it->second;
    if (views.count(layer))
        throw Error(fmt::format("layer '{}' of {} is borrowed (a view of the caller's memory); "
                                "Frame::Copy reads it",
                                layer, path.empty() ? "the frame" : "'" + path + "'"),
                    ErrorKind::InvalidArgument);
    std::string have;
    for (const std::string &name : Names()) have += (have.empty() ? "" : ", ") + name;
    throw Error(fmt::format("{} has no layer '{}' (it has: {})",
                            path.empty() ? "the frame" : "'" + path + "'", layer,
                            have.empty() ? "no layers" : have),
                ErrorKind::MissingLayer);
}

Image Frame::Copy(const std::string &layer) const {
    if (auto it = views.find(layer); it != views.end()) return CopyView(it->second);
    return Get(layer);
}

}  // namespace mcd
