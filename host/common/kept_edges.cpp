#include "host/common/kept_edges.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include <fmt/format.h>

#include "host/error.h"

namespace mcd {
namespace {

// The ids of pixel p, one plane each (0 where absent).
struct Ids {
    const Image *object, *part;
    bool Same(size_t p, size_t q) const {
        return (!object || object->data[p] == object->data[q]) &&
               (!part || part->data[p] == part->data[q]);
    }
};

// Whether (x, y) has a 4-neighbour of other ids.
bool BesideOtherIds(const Ids &ids, int w, int h, int x, int y) {
    const size_t p = size_t(y) * w + x;
    return (x > 0 && !ids.Same(p, p - 1)) || (x + 1 < w && !ids.Same(p, p + 1)) ||
           (y > 0 && !ids.Same(p, p - w)) || (y + 1 < h && !ids.Same(p, p + w));
}

bool Kept(float in, float out) {
    return std::memcmp(&in, &out, sizeof(float)) == 0;
}

// The level of p's part along it: over the pixels of p's ids within 2 of it (itself left out)
// whose value is finite, the upper median of their values and, where p's pivot is above 0,
// p's pivot times the upper median of value / pivot over those whose pivot is above 0, the
// lower of the two. Each misleads upward where the other does not: the values where p covers
// less of the part than its neighbours, the ratios where p's pivot carries a firefly of its
// own (an emitter's albedo). False without such pixels.
bool OwnLevel(const Ids &ids, const float *plane, const float *pivot, int w, int h, int x,
              int y, float *level) {
    const size_t p = size_t(y) * w + x;
    float values[24], ratios[24];
    int n = 0, m = 0;
    for (int v = std::max(0, y - 2); v <= std::min(h - 1, y + 2); ++v)
        for (int u = std::max(0, x - 2); u <= std::min(w - 1, x + 2); ++u) {
            const size_t q = size_t(v) * w + u;
            if (q == p || !ids.Same(p, q) || !std::isfinite(plane[q])) continue;
            values[n++] = plane[q];
            const float ratio = plane[q] / pivot[q];
            if (pivot[q] > 0 && std::isfinite(ratio)) ratios[m++] = ratio;
        }
    if (n == 0) return false;
    std::nth_element(values, values + n / 2, values + n);
    *level = values[n / 2];
    if (m > 0 && pivot[p] > 0) {
        std::nth_element(ratios, ratios + m / 2, ratios + m);
        const float scaled = pivot[p] * ratios[m / 2];
        if (std::isfinite(scaled)) *level = std::min(*level, scaled);
    }
    return true;
}

// Refuses an output or pivot not of the input's shape, or an id layer not one channel of its
// size, before anything is read.
void CheckEdgeLayers(const char *step, const Image &input, const Image &pivot,
                     const Image *objectId, const Image *partId, const Image &output) {
    if (!input.SameShape(output) || !input.SameShape(pivot))
        throw Error(
            fmt::format("{}: the output and the pivot must have the input's shape", step),
            ErrorKind::Internal);
    for (const Image *id : {objectId, partId})
        if (id && (id->width != input.width || id->height != input.height || id->channels != 1))
            throw Error(
                fmt::format("{}: an id layer must be one channel of the input's size", step),
                ErrorKind::Internal);
}

}  // namespace

float FilteredValue(float value, float input) {
    if (value != input || !std::isfinite(value)) return value;
    if (value == 0) return input;
    uint32_t bits;
    std::memcpy(&bits, &value, sizeof bits);
    bits = (bits & 0x7fffffffu) == 0x7f7fffffu ? bits - 1 : bits + 1;
    std::memcpy(&value, &bits, sizeof bits);
    return value;
}

void MarkFiltered(const Image &input, Image *output) {
    if (!input.SameShape(*output))
        throw Error("MarkFiltered: the output must be of the input's shape",
                    ErrorKind::Internal);
    for (size_t i = 0; i < output->data.size(); ++i)
        output->data[i] = FilteredValue(output->data[i], input.data[i]);
}

KeptEdges ClampKeptEdgeValues(const Image &input, const Image &pivot, const Image *objectId,
                              const Image *partId, Image *output) {
    CheckEdgeLayers("ClampKeptEdgeValues", input, pivot, objectId, partId, *output);
    KeptEdges kept;
    if (!objectId && !partId) return kept;
    const Ids ids{objectId, partId};
    const int w = input.width, h = input.height;
    const Image before = *output;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            if (!BesideOtherIds(ids, w, h, x, y)) continue;
            const size_t p = size_t(y) * w + x;
            for (int c = 0; c < input.channels; ++c) {
                const float *in = input.Plane(c), *out = before.Plane(c);
                if (!Kept(in[p], out[p]) || !std::isfinite(in[p])) continue;
                float lo = 0, hi = 0, otherLo = 0, otherHi = 0;
                bool own = false, other = false, otherKept = false;
                for (int v = std::max(0, y - 1); v <= std::min(h - 1, y + 1); ++v)
                    for (int u = std::max(0, x - 1); u <= std::min(w - 1, x + 1); ++u) {
                        const size_t q = size_t(v) * w + u;
                        if (q == p || !std::isfinite(out[q])) continue;
                        const bool same = ids.Same(p, q);
                        // Other ids' values, kept ones too (a light's, as written).
                        if (!same) {
                            otherLo = otherKept ? std::min(otherLo, out[q]) : out[q];
                            otherHi = otherKept ? std::max(otherHi, out[q]) : out[q];
                            otherKept = true;
                        }
                        if (Kept(in[q], out[q])) continue;
                        lo = own || other ? std::min(lo, out[q]) : out[q];
                        hi = own || other ? std::max(hi, out[q]) : out[q];
                        (same ? own : other) = true;
                    }
                // Without filtered values of both kinds (a thin part, or a side kept whole):
                // its own ids' level along it and the other ids' values around it, kept ones
                // too, join the range (a light's rim seen as the wall keeps
                // the light's share).
                const bool thin = !own || !other;
                if (thin) {
                    float level;
                    if (!OwnLevel(ids, out, pivot.Plane(c), w, h, x, y, &level)) {
                        ++kept.alone;
                        continue;
                    }
                    lo = own || other ? std::min(lo, level) : level;
                    hi = own || other ? std::max(hi, level) : level;
                    if (otherKept) lo = std::min(lo, otherLo), hi = std::max(hi, otherHi);
                }
                if (in[p] >= lo && in[p] <= hi) continue;
                output->Plane(c)[p] = std::clamp(in[p], lo, hi);
                ++kept.clamped;
                kept.thin += thin ? 1 : 0;
            }
        }
    return kept;
}

size_t ClampEdgeFitsToSides(const Image &input, const Image &pivot, const Image *objectId,
                            const Image *partId, Image *output) {
    CheckEdgeLayers("ClampEdgeFitsToSides", input, pivot, objectId, partId, *output);
    if (!objectId && !partId) return 0;
    const Ids ids{objectId, partId};
    const int w = input.width, h = input.height;
    std::vector<char> edge(size_t(w) * h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) edge[size_t(y) * w + x] = BesideOtherIds(ids, w, h, x, y);
    size_t moved = 0;
    for (int c = 0; c < input.channels; ++c) {
        const float *in = input.Plane(c), *piv = pivot.Plane(c);
        float *out = output->Plane(c);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const size_t p = size_t(y) * w + x;
                if (!edge[p] || !(piv[p] > 0) || !std::isfinite(out[p]) || Kept(in[p], out[p]))
                    continue;
                float lo = 0, hi = 0, line[25];
                bool own = false, other = false;
                int n = 0;
                for (int v = std::max(0, y - 2); v <= std::min(h - 1, y + 2); ++v)
                    for (int u = std::max(0, x - 2); u <= std::min(w - 1, x + 2); ++u) {
                        const size_t q = size_t(v) * w + u;
                        if (!(piv[q] > 0)) continue;
                        // Its outline: the inputs of its own ids along the edge.
                        if (edge[q]) {
                            const float z = in[q] / piv[q];
                            if (ids.Same(p, q) && std::isfinite(z)) line[n++] = z;
                            continue;
                        }
                        if (!std::isfinite(out[q]) || Kept(in[q], out[q])) continue;
                        const float z = out[q] / piv[q];
                        if (!std::isfinite(z)) continue;
                        lo = own || other ? std::min(lo, z) : z;
                        hi = own || other ? std::max(hi, z) : z;
                        (ids.Same(p, q) ? own : other) = true;
                    }
                if (!own || !other) continue;
                if (n > 0) {
                    std::nth_element(line, line + n / 2, line + n);
                    lo = std::min(lo, line[n / 2]);
                    hi = std::max(hi, line[n / 2]);
                }
                const float z = out[p] / piv[p];
                if (!std::isfinite(z) || (z >= lo && z <= hi)) continue;
                out[p] = FilteredValue(std::clamp(z, lo, hi) * piv[p], in[p]);
                ++moved;
            }
    }
    return moved;
}

}  // namespace mcd
