#include "cpu_reference/kept_edges.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

namespace mcd::ref {
namespace {

double IdAt(const Image *id, int x, int y) {
    return id ? id->At(0, y, x) : 0;
}

bool SameIds(const Image *objectId, const Image *partId, int x0, int y0, int x1, int y1) {
    return IdAt(objectId, x0, y0) == IdAt(objectId, x1, y1) &&
           IdAt(partId, x0, y0) == IdAt(partId, x1, y1);
}

bool SameFloat(float a, float b) {
    uint32_t ua, ub;
    std::memcpy(&ua, &a, 4);
    std::memcpy(&ub, &b, 4);
    return ua == ub;
}

}  // namespace

float FilteredValue(float value, float input) {
    if (value != input || !std::isfinite(value)) return value;
    if (value == 0) return input;
    if (std::fabs(value) == std::numeric_limits<float>::max())
        return std::nextafter(value, 0.f);
    return std::nextafter(value, std::copysign(INFINITY, value));
}

size_t ClampKeptEdgeValues(const Image &input, const Image &pivot, const Image *objectId,
                           const Image *partId, Image *output) {
    if (!objectId && !partId) return 0;
    const Image before = *output;
    const int w = input.width, h = input.height;
    size_t changed = 0;
    for (int c = 0; c < input.channels; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                bool edge = false;
                const int nx[4] = {x - 1, x + 1, x, x}, ny[4] = {y, y, y - 1, y + 1};
                for (int k = 0; k < 4; ++k)
                    if (nx[k] >= 0 && nx[k] < w && ny[k] >= 0 && ny[k] < h &&
                        !SameIds(objectId, partId, x, y, nx[k], ny[k]))
                        edge = true;
                float in = input.At(c, y, x);
                if (!edge || !SameFloat(in, before.At(c, y, x)) || !std::isfinite(in)) continue;
                std::vector<float> values;
                bool own = false, other = false;
                for (int v = y - 1; v <= y + 1; ++v)
                    for (int u = x - 1; u <= x + 1; ++u) {
                        if (v < 0 || v >= h || u < 0 || u >= w || (u == x && v == y)) continue;
                        float o = before.At(c, v, u);
                        if (SameFloat(input.At(c, v, u), o) || !std::isfinite(o)) continue;
                        values.push_back(o);
                        if (SameIds(objectId, partId, x, y, u, v))
                            own = true;
                        else
                            other = true;
                    }
                if (!own || !other) {
                    // A thin part: the lower of the upper median of its own ids' values within
                    // 2 and the pivot times the upper median of their ratios value / pivot.
                    std::vector<float> line, ratios;
                    for (int v = y - 2; v <= y + 2; ++v)
                        for (int u = x - 2; u <= x + 2; ++u) {
                            if (v < 0 || v >= h || u < 0 || u >= w || (u == x && v == y) ||
                                !SameIds(objectId, partId, x, y, u, v))
                                continue;
                            float o = before.At(c, v, u), a = pivot.At(c, v, u);
                            if (!std::isfinite(o)) continue;
                            line.push_back(o);
                            float ratio = o / a;
                            if (a > 0 && std::isfinite(ratio)) ratios.push_back(ratio);
                        }
                    if (line.empty()) continue;
                    // The other ids' values in the 3x3 window, kept ones too.
                    for (int v = y - 1; v <= y + 1; ++v)
                        for (int u = x - 1; u <= x + 1; ++u)
                            if (v >= 0 && v < h && u >= 0 && u < w &&
                                !SameIds(objectId, partId, x, y, u, v) &&
                                std::isfinite(before.At(c, v, u)))
                                values.push_back(before.At(c, v, u));
                    std::sort(line.begin(), line.end());
                    float level = line[line.size() / 2];
                    const float here = pivot.At(c, y, x);
                    if (!ratios.empty() && here > 0) {
                        std::sort(ratios.begin(), ratios.end());
                        float scaled = here * ratios[ratios.size() / 2];
                        if (std::isfinite(scaled) && scaled < level) level = scaled;
                    }
                    values.push_back(level);
                }
                float lo = values[0], hi = values[0];
                for (float o : values) {
                    if (o < lo) lo = o;
                    if (o > hi) hi = o;
                }
                float clamped = in < lo ? lo : in > hi ? hi : in;
                if (clamped != in) {
                    output->At(c, y, x) = clamped;
                    ++changed;
                }
            }
    return changed;
}

size_t ClampEdgeFitsToSides(const Image &input, const Image &pivot, const Image *objectId,
                            const Image *partId, Image *output) {
    if (!objectId && !partId) return 0;
    const int w = input.width, h = input.height;
    auto onEdge = [&](int x, int y) {
        const int nx[4] = {x - 1, x + 1, x, x}, ny[4] = {y, y, y - 1, y + 1};
        for (int k = 0; k < 4; ++k)
            if (nx[k] >= 0 && nx[k] < w && ny[k] >= 0 && ny[k] < h &&
                !SameIds(objectId, partId, x, y, nx[k], ny[k]))
                return true;
        return false;
    };
    const Image before = *output;
    size_t changed = 0;
    for (int c = 0; c < input.channels; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const float o = before.At(c, y, x), a = pivot.At(c, y, x);
                if (!onEdge(x, y) || !(a > 0) || !std::isfinite(o) ||
                    SameFloat(input.At(c, y, x), o))
                    continue;
                std::vector<float> own, other, line;
                for (int v = y - 2; v <= y + 2; ++v)
                    for (int u = x - 2; u <= x + 2; ++u) {
                        if (v < 0 || v >= h || u < 0 || u >= w) continue;
                        const float ov = before.At(c, v, u), av = pivot.At(c, v, u);
                        const bool same = SameIds(objectId, partId, x, y, u, v);
                        if (!(av > 0)) continue;
                        if (onEdge(u, v)) {
                            const float z = input.At(c, v, u) / av;
                            if (same && std::isfinite(z)) line.push_back(z);
                            continue;
                        }
                        if (!std::isfinite(ov) || SameFloat(input.At(c, v, u), ov)) continue;
                        const float z = ov / av;
                        if (std::isfinite(z)) (same ? own : other).push_back(z);
                    }
                if (own.empty() || other.empty()) continue;
                float lo = *std::min_element(own.begin(), own.end());
                float hi = *std::max_element(own.begin(), own.end());
                lo = std::min(lo, *std::min_element(other.begin(), other.end()));
                hi = std::max(hi, *std::max_element(other.begin(), other.end()));
                if (!line.empty()) {
                    std::sort(line.begin(), line.end());
                    lo = std::min(lo, line[line.size() / 2]);
                    hi = std::max(hi, line[line.size() / 2]);
                }
                const float z = o / a;
                if (!std::isfinite(z) || (z >= lo && z <= hi)) continue;
                output->At(c, y, x) = FilteredValue((z < lo ? lo : hi) * a, input.At(c, y, x));
                ++changed;
            }
    return changed;
}

}  // namespace mcd::ref
