#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "rhf/select.h"

// One invocation per centre: x across, strip row from the grid. The centre's distances
// are read once into registers; the k_NN passes and the mask then never touch memory.
layout(local_size_x = RHF_SELECT_LOCAL_SIZE) in;
layout(constant_id = RHF_SELECT_SPEC_SEARCH_HALF) const int B = 6;
const int SIDE = 2 * B + 1, OFFSETS = SIDE * SIDE, SELF = OFFSETS / 2;
layout(binding = RHF_SELECT_DISTANCE) uniform samplerBuffer dist;
layout(std430, binding = RHF_SELECT_MASK) writeonly buffer Mask { uint mask[]; };

float d[OFFSETS];

// Candidate order: by distance, then the patch itself, then scan order.
bool Before(float d0, int rank0, float d1, int rank1) {
    return d0 < d1 || (d0 == d1 && rank0 < rank1);
}

int Rank(int o) {
    return o == SELF ? -1 : o;
}

void main() {
    int x = int(gl_GlobalInvocationID.x), r = int(gl_WorkGroupID.y);
    if (x >= push.width) return;
    int plane = push.rows * push.width, base = r * push.width + x;
    [[unroll]] for (int o = 0; o < OFFSETS; ++o) d[o] = texelFetch(dist, o * plane + base).r;
    // The k-th nearest key, found by k passes of "smallest key after the previous one".
    float lastD = -1.0;
    int lastRank = -2;
    for (int k = 0; k < push.knn; ++k) {
        float bestD = 0.0;
        int bestRank = OFFSETS;
        [[unroll]] for (int o = 0; o < OFFSETS; ++o) {
            bool after = d[o] >= 0.0 && Before(lastD, lastRank, d[o], Rank(o));
            if (after && (bestRank == OFFSETS || Before(d[o], Rank(o), bestD, bestRank))) {
                bestD = d[o];
                bestRank = Rank(o);
            }
        }
        if (bestRank == OFFSETS) break;  // fewer candidates than k
        lastD = bestD;
        lastRank = bestRank;
    }
    int y = push.rowBase + r;
    [[unroll]] for (int word = 0; word * 32 < OFFSETS; ++word) {
        uint bits = 0u;
        [[unroll]] for (int bit = 0; bit < 32; ++bit) {
            int o = word * 32 + bit;
            if (o < OFFSETS && d[o] >= 0.0 &&
                (d[o] < push.threshold || !Before(lastD, lastRank, d[o], Rank(o))))
                bits |= 1u << bit;
        }
        mask[(word * push.height + y) * push.width + x] = bits;
    }
}
