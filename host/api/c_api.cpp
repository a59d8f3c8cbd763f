// The C API (include/mcdenoise/mcdenoise_c.h) over the C++ one: handles that hold the C++
// objects, and every exception turned into the calling thread's error.
#include "host/api/c_api.h"

#include <fmt/format.h>

#include "host/api/views.h"

using namespace mcd;
using namespace mcd::api;

namespace {

struct LastError {
    MCDError code = MCD_ERROR_NONE;
    std::string message, reported;
};
thread_local LastError lastError;

DataType TypeOf(MCDFormat format) {
    if (format == MCD_FORMAT_FLOAT) return DataType::Float32;
    if (format == MCD_FORMAT_HALF) return DataType::Float16;
    throw Error(fmt::format("unknown MCDFormat {}", int(format)), ErrorKind::InvalidArgument);
}

template <class View>
View ViewOf(const MCDView &view, decltype(View::data) data) {
    return View{data,
                view.width,
                view.height,
                view.channels,
                TypeOf(view.format),
                std::ptrdiff_t(view.pixelByteStride),
                std::ptrdiff_t(view.rowByteStride),
                std::ptrdiff_t(view.channelByteStride)};
}

const char *Line(const std::vector<std::string> &lines, int index) {
    return index >= 0 && size_t(index) < lines.size() ? lines[size_t(index)].c_str() : nullptr;
}

const std::vector<std::string> &AllMethodNames() {
    static const std::vector<std::string> names = [] {
        std::vector<std::string> all = {"auto"};
        for (const std::string &name : MethodNames()) all.push_back(name);
        return all;
    }();
    return names;
}

}  // namespace

namespace mcd::api {

void SetLastError(MCDError code, const std::string &message) {
    lastError.code = code;
    lastError.message = message;
}

MCDError ErrorCode(ErrorKind kind) {
    switch (kind) {
        case ErrorKind::InvalidArgument:
            return MCD_ERROR_INVALID_ARGUMENT;
        case ErrorKind::MissingLayer:
            return MCD_ERROR_MISSING_LAYER;
        case ErrorKind::NonFiniteInput:
            return MCD_ERROR_NON_FINITE_INPUT;
        case ErrorKind::OutOfMemory:
            return MCD_ERROR_OUT_OF_MEMORY;
        case ErrorKind::Device:
            return MCD_ERROR_DEVICE;
        case ErrorKind::Io:
            return MCD_ERROR_IO;
        case ErrorKind::Internal:
            return MCD_ERROR_INTERNAL;
        case ErrorKind::Cancelled:
            return MCD_ERROR_CANCELLED;
    }
    return MCD_ERROR_INTERNAL;
}

void Require(const void *pointer, const char *what) {
    if (!pointer) throw Error(fmt::format("{} is NULL", what), ErrorKind::InvalidArgument);
}

LayerView LayerViewOf(const MCDView &view) {
    return ViewOf<LayerView>(view, view.data);
}

OutputView OutputViewOf(const MCDView &view) {
    return ViewOf<OutputView>(view, view.data);
}

}  // namespace mcd::api

extern "C" {

MCDError mcdGetError(const char **message) {
    MCDError code = lastError.code;
    lastError.reported = std::move(lastError.message);
    lastError.code = MCD_ERROR_NONE;
    lastError.message.clear();
    if (message) *message = lastError.reported.c_str();
    return code;
}

const char *mcdErrorName(MCDError code) {
    if (code == MCD_ERROR_NONE) return "none";
    if (code < MCD_ERROR_NONE || code > MCD_ERROR_CANCELLED) return "unknown";
    return ErrorKindName(ErrorKind(int(code)));
}

const char *mcdVersion(void) {
    return Version();
}

MCDView mcdInterleaved(void *data, MCDFormat format, int width, int height, int channels) {
    int64_t element = format == MCD_FORMAT_HALF ? 2 : 4;
    return {
        data,   format, width, height, channels, element * channels, element * channels * width,
        element};
}

MCDView mcdPlanar(void *data, MCDFormat format, int width, int height, int channels) {
    int64_t element = format == MCD_FORMAT_HALF ? 2 : 4;
    return {data,     format,  width,           height,
            channels, element, element * width, element * width * height};
}

MCDDevice mcdNewDevice(const char *name) {
    return Guarded<MCDDevice>(nullptr, [&] {
        DeviceOptions options;
        if (name) options.device = name;
        auto *device = new MCDDeviceImpl{Device(options), ""};
        device->name = device->device.Name();
        return device;
    });
}

void mcdReleaseDevice(MCDDevice device) {
    delete device;
}

const char *mcdGetDeviceName(MCDDevice device) {
    return Guarded<const char *>(nullptr, [&] {
        Require(device, "the device");
        return device->name.c_str();
    });
}

MCDFrame mcdNewFrame(void) {
    return Guarded<MCDFrame>(nullptr, [] { return new MCDFrameImpl; });
}

void mcdReleaseFrame(MCDFrame frame) {
    delete frame;
}

bool mcdSetFrameLayer(MCDFrame frame, const char *layer, const MCDView *view) {
    return Guarded(false, [&] {
        Require(frame, "the frame");
        Require(layer, "the layer's name");
        Require(view, "the view");
        frame->frame.SetLayer(layer, LayerViewOf(*view));
        return true;
    });
}

int mcdGetFrameWidth(MCDFrame frame) {
    return Guarded(0, [&] {
        Require(frame, "the frame");
        return frame->frame.width;
    });
}

int mcdGetFrameHeight(MCDFrame frame) {
    return Guarded(0, [&] {
        Require(frame, "the frame");
        return frame->frame.height;
    });
}

int mcdGetFrameLayerCount(MCDFrame frame) {
    return Guarded(0, [&] {
        Require(frame, "the frame");
        return int(frame->frame.Names().size());
    });
}

const char *mcdGetFrameLayerName(MCDFrame frame, int index) {
    return Guarded<const char *>(nullptr, [&] {
        Require(frame, "the frame");
        const std::vector<std::string> names = frame->frame.Names();
        const char *name = Line(names, index);
        return name ? frame->handed.Keep(name) : nullptr;
    });
}

int mcdGetFrameLayerChannels(MCDFrame frame, const char *layer) {
    return Guarded(0, [&] {
        Require(frame, "the frame");
        Require(layer, "the layer's name");
        return frame->frame.Channels(layer);
    });
}

bool mcdCopyFrameLayer(MCDFrame frame, const char *layer, const MCDView *output) {
    return Guarded(false, [&] {
        Require(frame, "the frame");
        Require(layer, "the layer's name");
        Require(output, "the output view");
        Image image = frame->frame.Copy(layer);
        OutputView view = OutputViewOf(*output);
        CheckView(view, fmt::format("layer '{}'", layer));
        if (view.width != image.width || view.height != image.height ||
            view.channels != image.channels)
            throw Error(fmt::format("layer '{}' is {}x{}x{}, the view {}x{}x{}", layer,
                                    image.width, image.height, image.channels, view.width,
                                    view.height, view.channels),
                        ErrorKind::InvalidArgument);
        WriteView(image, view);
        return true;
    });
}

int mcdGetMethodCount(void) {
    return int(AllMethodNames().size());
}

const char *mcdGetMethodName(int index) {
    return Line(AllMethodNames(), index);
}

MCDMethod mcdNewMethod(const char *name) {
    return Guarded<MCDMethod>(nullptr, [&] {
        Require(name, "the method's name");
        auto *method = new MCDMethodImpl{Method(name)};
        method->summary = method->method.Summary();
        return method;
    });
}

void mcdReleaseMethod(MCDMethod method) {
    delete method;
}

const char *mcdGetMethodSummary(MCDMethod method) {
    return Guarded<const char *>(nullptr, [&] {
        Require(method, "the method");
        return method->summary.c_str();
    });
}

}  // extern "C"
