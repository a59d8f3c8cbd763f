#include "host/common/kept_edges.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

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

}  // namespace

KeptEdges ClampKeptEdgeValues(const Image &input, const Image *objectId, const Image *partId,
                              Image *output) {
    if (!input.SameShape(*output))
        throw Error("ClampKeptEdgeValues: the output must have the input's shape",
                    ErrorKind::Internal);
    for (const Image *id : {objectId, partId})
        if (id && (id->width != input.width || id->height != input.height || id->channels != 1))
            throw Error(
                "ClampKeptEdgeValues: an id layer must be one channel of the input's size",
                ErrorKind::Internal);
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
                float lo = 0, hi = 0;
                bool own = false, other = false;
                for (int v = std::max(0, y - 1); v <= std::min(h - 1, y + 1); ++v)
                    for (int u = std::max(0, x - 1); u <= std::min(w - 1, x + 1); ++u) {
                        const size_t q = size_t(v) * w + u;
                        if (q == p || Kept(in[q], out[q]) || !std::isfinite(out[q])) continue;
                        lo = own || other ? std::min(lo, out[q]) : out[q];
                        hi = own || other ? std::max(hi, out[q]) : out[q];
                        (ids.Same(p, q) ? own : other) = true;
                    }
                if (!own || !other) {
                    ++kept.alone;
                    continue;
                }
                if (in[p] >= lo && in[p] <= hi) continue;
                output->Plane(c)[p] = std::clamp(in[p], lo, hi);
                ++kept.clamped;
            }
        }
    return kept;
}

}  // namespace mcd
