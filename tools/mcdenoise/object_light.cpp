#include "tools/mcdenoise/object_light.h"

#include <fmt/format.h>

#include <cmath>

#include "host/metrics.h"

namespace mcd::tool {

double ObjectLights::Darkest() const {
    return darkestId >= 0 ? objects.at(darkestId).ratio : NAN;
}

std::string DarkestCsv(const ObjectLights &lights) {
    return lights.darkestId >= 0 ? fmt::format("{:.5f},{}", lights.Darkest(), lights.darkestId)
                                 : ",";
}

ObjectMap ObjectsOf(const Frame &frame) {
    ObjectMap objects;
    if (frame.Has("objectId")) objects.ids = frame.Get("objectId");
    if (frame.Has("alpha")) objects.coverage = frame.Get("alpha");
    return objects;
}

ObjectLights MeasureObjectLights(const Image &output, const Image &reference,
                                 const ObjectMap &objects) {
    ObjectLights lights;
    const Image &ids = objects.ids, &coverage = objects.coverage;
    bool hasCoverage =
        coverage.width == ids.width && coverage.height == ids.height && coverage.channels >= 1;
    if (ids.width != output.width || ids.height != output.height || ids.channels < 1 ||
        reference.width != output.width || reference.height != output.height)
        return lights;
    struct Sums {
        int pixels = 0, empty = 0;
        double output = 0, reference = 0;
    };
    std::map<int, Sums> sums;
    for (int y = 0; y < output.height; ++y)
        for (int x = 0; x < output.width; ++x) {
            float id = ids.At(0, y, x);
            if (!std::isfinite(id)) continue;
            Sums &s = sums[int(std::lround(id))];
            ++s.pixels;
            if (hasCoverage && coverage.At(0, y, x) == 0) ++s.empty;
            s.output += Luminance(output, y, x);
            s.reference += Luminance(reference, y, x);
        }
    double darkest = INFINITY;
    for (const auto &[id, s] : sums) {
        if (s.pixels < kObjectPixels || !(s.reference > 0) || 2 * s.empty > s.pixels) continue;
        // A non-finite output makes the object's ratio NaN: the darkest there can be.
        double ratio = std::isfinite(s.output) ? s.output / s.reference : NAN;
        lights.objects[id] = {s.pixels, ratio};
        double rank = std::isnan(ratio) ? -INFINITY : ratio;
        if (rank < darkest) {
            darkest = rank;
            lights.darkestId = id;
        }
    }
    return lights;
}

}  // namespace mcd::tool
