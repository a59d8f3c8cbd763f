#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "rhf/select.h"

// One invocation per centre: x across, strip row from the grid. The centre's distances
// are read once into registers; the nearest passes and the mask then never touch memory.
layout(local_size_x = RHF_SELECT_LOCAL_SIZE) in;
layout(constant_id = RHF_SELECT_SPEC_SEARCH_HALF) const int B = 6;
layout(constant_id = RHF_SELECT_SPEC_NEAREST) const int NEAREST = 1;
const int SIDE = 2 * B + 1, OFFSETS = SIDE * SIDE;
const float PICKED = -2.0;  // below every distance, apart from a veto's -1
layout(binding = RHF_SELECT_DISTANCE) uniform samplerBuffer dist;
layout(std430, binding = RHF_SELECT_MASK) writeonly buffer Mask { uint mask[]; };

float d[OFFSETS];
// Candidates the selection sort has moved: offset and new position.
int movedOffset[NEAREST], movedKey[NEAREST];

// The tool's array order: the window column by column.
int KeyOf(int o, int moves) {
    int key = (o % SIDE) * SIDE + o / SIDE;
    for (int m = 0; m < moves; ++m)
        if (movedOffset[m] == o) key = movedKey[m];
    return key;
}

void main() {
    int x = int(gl_GlobalInvocationID.x), r = int(gl_WorkGroupID.y);
    if (x >= push.width) return;
    int plane = push.rows * push.width, base = r * push.width + x;
    [[unroll]] for (int o = 0; o < OFFSETS; ++o) d[o] = texelFetch(dist, o * plane + base).r;
    // The tool's selection sort: each pass takes the first smallest candidate in array
    // order and swaps it with the candidate at the front of what is left.
    int moves = 0;
    // Nearest covering the window takes every candidate, in any order.
    if (push.nearest >= OFFSETS) {
        [[unroll]] for (int o = 0; o < OFFSETS; ++o) if (d[o] >= 0.0) d[o] = PICKED;
    }
    for (int k = 0; k < push.nearest && push.nearest < OFFSETS; ++k) {
        int best = -1, bestKey = 0, head = -1, headKey = 0;
        float bestD = 0.0;
        [[unroll]] for (int o = 0; o < OFFSETS; ++o) {
            if (d[o] < 0.0) continue;
            int key = KeyOf(o, moves);
            if (best < 0 || d[o] < bestD || (d[o] == bestD && key < bestKey)) {
                best = o;
                bestD = d[o];
                bestKey = key;
            }
            if (head < 0 || key < headKey) {
                head = o;
                headKey = key;
            }
        }
        if (best < 0) break;  // fewer candidates than nearest
        if (head != best) {
            int m = 0;
            while (m < moves && movedOffset[m] != head) ++m;
            movedOffset[m] = head;
            movedKey[m] = bestKey;
            moves = max(moves, m + 1);
        }
        [[unroll]] for (int o = 0; o < OFFSETS; ++o) if (o == best) d[o] = PICKED;
    }
    int y = push.rowBase + r;
    [[unroll]] for (int word = 0; word * 32 < OFFSETS; ++word) {
        uint bits = 0u;
        [[unroll]] for (int bit = 0; bit < 32; ++bit) {
            int o = word * 32 + bit;
            if (o < OFFSETS && (d[o] == PICKED || (d[o] >= 0.0 && d[o] < push.threshold)))
                bits |= 1u << bit;
        }
        mask[(word * push.height + y) * push.width + x] = bits;
    }
}
