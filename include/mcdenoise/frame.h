// A frame: the named layers of one render (color, variance, histograms, pivot, G-buffer,
// ...; the layer names are the README's table), each either an mcd::Image the frame owns
// (what ReadFrame gives, mcdenoise/io.h) or a view of the caller's memory that it borrows.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "mcdenoise/image.h"
#include "mcdenoise/view.h"

namespace mcd {

// One frame: its layers by name, all width x height, and the file's string metadata.
struct Frame {
    std::string path;  // where it was read from ("" for a frame built in memory)
    int width = 0, height = 0;
    std::map<std::string, Image> layers;     // owned, planar
    std::map<std::string, LayerView> views;  // borrowed: the caller's memory
    std::map<std::string, std::string> metadata;

    Frame() = default;
    Frame(int width, int height) : width(width), height(height) {}

    // Borrow `view` as layer `name` (replacing an owned layer of that name): nothing is
    // copied here; each Method::Run reads the layers its method uses from the view, so the
    // memory must stay valid and unchanged while a run on this frame is under way. The
    // first layer of an empty frame sets its size; throws mcd::Error (invalid argument)
    // for a view of another size, a null pointer or a size or channel count below 1.
    void SetLayer(const std::string &name, const LayerView &view);
    // Own `image` as layer `name` (replacing a borrowed one), sized as above.
    void SetLayer(const std::string &name, Image image);

    // Whether the frame has the layer, owned or borrowed.
    bool Has(const std::string &layer) const;
    // Every layer's name, owned and borrowed, sorted.
    std::vector<std::string> Names() const;
    // The layer's channel count (owned or borrowed); throws as Get when it is missing.
    int Channels(const std::string &layer) const;
    // An owned layer. Throws mcd::Error naming the file, the layer and the layers the frame
    // has (missing layer), or saying that the layer is borrowed (Copy reads those).
    const Image &Get(const std::string &layer) const;
    // The layer, owned or borrowed, as a planar float image (a copy).
    Image Copy(const std::string &layer) const;
};

// The image a view shows, as planar float32 (half converted, strides followed).
Image CopyView(const LayerView &view);

}  // namespace mcd
