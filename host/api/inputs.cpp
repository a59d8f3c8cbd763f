#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "host/api/front_end.h"
#include "host/common/non_finite.h"
#include "host/common/parallel.h"
#include "host/methods/run_memo.h"

namespace mcd::api {

Inputs::Inputs(const Frame &frame, bool refuseNonFinite, std::string method)
    : frame(frame),
      refuseNonFinite(refuseNonFinite),
      method(std::move(method)),
      width(frame.width),
      height(frame.height) {}

Inputs::Inputs(Inputs &parent, int x0, int y0, int x1, int y1)
    : frame(parent.frame),
      refuseNonFinite(parent.refuseNonFinite),
      method(parent.method),
      width(x1 - x0),
      height(y1 - y0),
      parent(&parent),
      memo(parent.memo),
      x0(x0),
      y0(y0) {}

bool Inputs::Has(const std::string &layer) const {
    if (auto it = aliases.find(layer); it != aliases.end()) return Has(it->second);
    if (overrides.count(layer) > 0) return true;
    return parent ? parent->Has(layer) : frame.Has(layer);
}

void Inputs::Override(const std::string &layer, Image image) {
    overrides[layer] = std::move(image);
    aliases.erase(layer);
    checked.erase(layer);
    crops.erase(layer);
    ids.erase(layer);
}

void Inputs::Alias(const std::string &layer, const std::string &source) {
    if (layer == source)
        throw Error(fmt::format("layer '{}' read from itself", layer), ErrorKind::Internal);
    if (aliases.count(source) > 0)
        throw Error(
            fmt::format("layer '{}' read from '{}', itself read from another", layer, source),
            ErrorKind::Internal);
    // The source must exist and be readable (checked, repaired) before the layer follows it.
    Get(source);
    // Keep the layer's own entry, emptied, so that references from Get stay valid.
    if (auto it = overrides.find(layer); it != overrides.end()) it->second = Image();
    aliases[layer] = source;
    checked.erase(layer);
    crops.erase(layer);
    ids.erase(layer);
}

Inputs::Held Inputs::Take(const std::string &layer) {
    Get(layer);
    // Nothing below allocates, so nothing moved out can be lost to an exception.
    Held held;
    if (auto it = overrides.find(layer); it != overrides.end()) {
        held.image = std::move(it->second);
        it->second = Image();
    }
    if (auto it = aliases.find(layer); it != aliases.end()) {
        held.alias = std::move(it->second);
        aliases.erase(it);
    }
    if (auto it = checked.find(layer); it != checked.end()) held.checked = it->second;
    held.crop = crops.count(layer) > 0;
    if (auto it = ids.find(layer); it != ids.end()) held.id = std::move(it->second);
    checked.erase(layer);
    crops.erase(layer);
    ids.erase(layer);
    return held;
}

void Inputs::Put(const std::string &layer, Held held) {
    aliases.erase(layer);
    // Into the entry in place where there is one (references from Get stay valid).
    if (held.image)
        overrides[layer] = std::move(*held.image);
    else
        overrides.erase(layer);
    if (held.alias) aliases[layer] = std::move(*held.alias);
    checked[layer] = held.checked;
    if (held.crop)
        crops.insert(layer);
    else
        crops.erase(layer);
    if (held.id)
        ids[layer] = std::move(*held.id);
    else
        ids.erase(layer);
}

const std::string &Inputs::LayerId(const std::string &layer) {
    if (auto it = aliases.find(layer); it != aliases.end()) return LayerId(it->second);
    if (auto it = ids.find(layer); it != ids.end()) return it->second;
    const Image &image = Get(layer);
    // A crop is its parent's layer seen through the window: the same parent and window
    // give the same values.
    std::string id = parent && crops.count(layer) > 0
                         ? fmt::format("{} window [{}, {}) x [{}, {})", parent->LayerId(layer),
                                       x0, x0 + width, y0, y0 + height)
                         : MemoImageId(image);
    return ids[layer] = std::move(id);
}

std::vector<std::string> Inputs::Names() const {
    std::vector<std::string> names = parent ? parent->Names() : frame.Names();
    for (const auto &[name, image] : overrides) names.push_back(name);
    for (const auto &[name, source] : aliases) names.push_back(name);
    std::sort(names.begin(), names.end());
    names.erase(std::unique(names.begin(), names.end()), names.end());
    return names;
}

const Image &Inputs::Get(const std::string &layer) {
    if (auto it = aliases.find(layer); it != aliases.end()) return Get(it->second);
    auto it = overrides.find(layer);
    if (parent) {
        // The parent checks the whole layer (warnings in frame coordinates); crop once.
        if (it != overrides.end()) return it->second;
        const Image &whole = parent->Get(layer);
        if (whole.width != parent->Width() || whole.height != parent->Height())
            throw Error(
                fmt::format("{}: layer '{}' is {}x{}, the frame {}x{}", Path(), layer,
                            whole.width, whole.height, parent->Width(), parent->Height()),
                ErrorKind::InvalidArgument);
        // Rows of every plane split among the cores (rhf's histograms: 61 planes).
        Image crop(width, height, whole.channels);
        const int rows = whole.channels * height;
        ParallelFor(rows, size_t(rows) * size_t(width), [&](int begin, int end) {
            for (int row = begin; row < end; ++row) {
                const int c = row / height, y = row % height;
                std::copy_n(whole.Plane(c) + size_t(y0 + y) * whole.width + x0, width,
                            crop.Plane(c) + size_t(y) * width);
            }
        });
        crops.insert(layer);
        return overrides[layer] = std::move(crop);
    }
    // A borrowed layer is read from the caller's memory once, as planar float32.
    if (it == overrides.end() && !frame.layers.count(layer) && frame.views.count(layer))
        it = overrides.emplace(layer, frame.Copy(layer)).first;
    const Image &image = it != overrides.end() ? it->second : frame.Get(layer);
    if (checked[layer]) return image;
    checked[layer] = true;
    const NonFiniteCount bad = CountNonFinite(image);
    if (bad.count == 0) return image;
    std::string where = fmt::format(
        "layer '{}' of {} has {} NaN/Inf value{}, the first at "
        "pixel ({}, {}), channel {}",
        layer, frame.path.empty() ? "the frame" : frame.path, bad.count,
        bad.count == 1 ? "" : "s", bad.x, bad.y, bad.channel);
    if (refuseNonFinite)
        throw Error(
            fmt::format("{}: {} (--non-finite zero replaces them with 0)", method, where),
            ErrorKind::NonFiniteInput);
    Image repaired = image;
    for (float &v : repaired.data)
        if (!std::isfinite(v)) v = 0.f;
    warnings.push_back(fmt::format("{}: replaced by 0 (--non-finite zero)", where));
    overrides[layer] = std::move(repaired);
    return overrides[layer];
}

}  // namespace mcd::api
