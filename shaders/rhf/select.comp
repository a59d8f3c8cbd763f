#version 450
#extension GL_GOOGLE_include_directive : require

#include "rhf/select.h"

// One invocation per centre: x across, strip row from the grid.
layout(local_size_x = RHF_SELECT_LOCAL_SIZE) in;
layout(std430, binding = RHF_SELECT_DISTANCE) readonly buffer Distance { float dist[]; };
layout(std430, binding = RHF_SELECT_MASK) writeonly buffer Mask { uint mask[]; };

// Candidate order: by distance, then the patch itself, then scan order.
bool Before(float d0, int rank0, float d1, int rank1) {
    return d0 < d1 || (d0 == d1 && rank0 < rank1);
}

void main() {
    int x = int(gl_GlobalInvocationID.x), r = int(gl_WorkGroupID.y);
    if (x >= push.width) return;
    int side = 2 * push.searchHalf + 1, offsets = side * side, self = offsets / 2;
    int plane = push.rows * push.width, base = r * push.width + x;
    // The k-th nearest key, found by k passes of "smallest key after the previous one".
    float lastD = -1.0;
    int lastRank = -2;
    for (int k = 0; k < push.knn; ++k) {
        float bestD = 0.0;
        int bestRank = offsets;
        for (int o = 0; o < offsets; ++o) {
            float d = dist[o * plane + base];
            int rank = o == self ? -1 : o;
            if (d < 0.0 || !Before(lastD, lastRank, d, rank)) continue;
            if (bestRank == offsets || Before(d, rank, bestD, bestRank)) {
                bestD = d;
                bestRank = rank;
            }
        }
        if (bestRank == offsets) break;  // fewer candidates than k
        lastD = bestD;
        lastRank = bestRank;
    }
    int y = push.rowBase + r;
    for (int word = 0; word < push.words; ++word) {
        uint bits = 0u;
        for (int bit = 0; bit < 32; ++bit) {
            int o = word * 32 + bit;
            if (o >= offsets) break;
            float d = dist[o * plane + base];
            int rank = o == self ? -1 : o;
            if (d >= 0.0 && (d < push.threshold || !Before(lastD, lastRank, d, rank)))
                bits |= 1u << bit;
        }
        mask[(word * push.height + y) * push.width + x] = bits;
    }
}
