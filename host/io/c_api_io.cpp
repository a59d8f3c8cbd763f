// The C API for files (include/mcdenoise/io_c.h): ReadFrame and WriteExr behind handles.
#include <fmt/format.h>

#include <algorithm>
#include <memory>

#include "host/api/c_api.h"
#include "mcdenoise/io.h"
#include "mcdenoise/io_c.h"

using namespace mcd;
using namespace mcd::api;

extern "C" {

MCDFrame mcdReadFrame(const char *path, const char *const *layers, int layerCount) {
    return Guarded<MCDFrame>(nullptr, [&] {
        Require(path, "the path");
        ReadOptions options;
        if (layers)
            for (int i = 0; i < layerCount; ++i) {
                Require(layers[i], "a layer's name");
                options.layers.push_back(layers[i]);
            }
        auto frame = std::make_unique<MCDFrameImpl>();
        frame->frame = ReadFrame(path, options);
        return frame.release();
    });
}

bool mcdWriteExr(const char *path, const char *const *names, const MCDView *views, int count) {
    return Guarded(false, [&] {
        Require(path, "the path");
        Require(names, "the names");
        Require(views, "the views");
        std::vector<Image> images;
        images.reserve(size_t(std::max(count, 0)));
        std::vector<std::pair<std::string, const Image *>> layers;
        for (int i = 0; i < count; ++i) {
            Require(names[i], "a layer's name");
            images.push_back(CopyView(LayerViewOf(views[i])));
            layers.push_back({names[i], &images.back()});
        }
        WriteExr(path, layers);
        return true;
    });
}

}  // extern "C"
