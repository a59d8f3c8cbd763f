#include "host/common/samples.h"

#include <cstdlib>

namespace mcd {

namespace {

// A whole number above 0 and below 2^30 written as `text` and nothing else, else 0.
int PositiveInt(const std::string &text) {
    char *end = nullptr;
    long v = std::strtol(text.c_str(), &end, 10);
    return end != text.c_str() && *end == 0 && v > 0 && v < (1l << 30) ? int(v) : 0;
}

}  // namespace

int SppFromMetadata(const std::map<std::string, std::string> &metadata) {
    for (const auto &[key, value] : metadata)
        if (key == "mcd:spp" || key == "samplesPerPixel" || key == "pbrt:samplesPerPixel" ||
            (key.starts_with("cycles.") && key.ends_with(".samples")))
            if (int spp = PositiveInt(value)) return spp;
    return 0;
}

}  // namespace mcd
