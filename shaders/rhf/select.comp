#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "rhf/select.h"

// One invocation per centre: x across, strip row from the grid. The centre's distances
// are read once into registers and never written, so the unrolled loops stay straight
// lines the compiler handles at any window size.
layout(local_size_x = RHF_SELECT_LOCAL_SIZE) in;
layout(constant_id = RHF_SELECT_SPEC_SEARCH_HALF) const int B = 6;
// The pooled veto's code compiled out when it is off: lavapipe runs a branch no lane takes.
layout(constant_id = RHF_SELECT_SPEC_POOL) const int usePool = 1;
const int SIDE = 2 * B + 1, OFFSETS = SIDE * SIDE, WORDS = (OFFSETS + 31) / 32;
const float NONE = 3.0e38;  // above every distance
layout(binding = RHF_SELECT_DISTANCE) uniform samplerBuffer dist;
layout(std430, binding = RHF_SELECT_MASK) writeonly buffer Mask {
    uint mask[];
};
layout(binding = RHF_SELECT_POOL) uniform samplerBuffer pool;

float d[OFFSETS];

// Pixels in the pool's box around (x, y), cut at the image's edges.
int BoxArea(int x, int y) {
    int w = push.patchHalf;
    return (min(push.width - 1, x + w) - max(0, x - w) + 1) *
           (min(push.height - 1, y + w) - max(0, y - w) + 1);
}

// Offset o's distance, -1 (no candidate) where the pooled bright samples of the two patch
// boxes differ beyond poolBound: a highlight's line whose pixels hold one bright sample each
// adds no term to the distance, so without this the dark patches around it take it in. Both
// ways (the veto is symmetric in P, Q), so the energy the filter moves stays with the
// patches that share it. The counts are compared as rates over their boxes' pixels, so a
// box cut at the frame's edge is not taken for a darker one: (P/aP - Q/aQ)^2 >
// poolBound (P/aP^2 + Q/aQ^2), here times aP^2 aQ^2.
float Candidate(int o, int base, int plane, int x, int y, float own, float ownArea) {
    float at = texelFetch(dist, o * plane + base).r;
    if (usePool == 0 || push.poolBound <= 0.0 || at < 0.0) return at;
    int qx = x + o % SIDE - B, qy = y + o / SIDE - B;
    float other = texelFetch(pool, qy * push.width + qx).r, area = float(BoxArea(qx, qy));
    // Unfused, as the CPU reference computes it.
    precise float diff = own * area - other * ownArea, square = diff * diff,
                  bound = push.poolBound * (own * area * area + other * ownArea * ownArea);
    return square > bound ? -1.0 : at;
}

void main() {
    int x = int(gl_GlobalInvocationID.x), r = int(gl_WorkGroupID.y);
    if (x >= push.width) return;
    int plane = push.rows * push.width, base = r * push.width + x, y = push.rowBase + r;
    float own = 0.0, ownArea = 0.0;
    if (usePool != 0 && push.poolBound > 0.0) {
        own = texelFetch(pool, y * push.width + x).r;
        ownArea = float(BoxArea(x, y));
    }
    [[unroll]] for (int o = 0; o < OFFSETS; ++o) d[o] =
        Candidate(o, base, plane, x, y, own, ownArea);
    // The cut: the distance t of the nearest-th nearest candidate, by passes of "smallest
    // distance above the last" that count its copies. Vetoed candidates are negative.
    // A nearest covering the window takes every candidate.
    float t = push.nearest >= OFFSETS ? NONE : -1.0;
    int upToT = 0;  // candidates at most t
    for (int k = 0; k < push.nearest && upToT < push.nearest && t < NONE; ++k) {
        float next = NONE;
        int copies = 0;
        [[unroll]] for (int o = 0; o < OFFSETS; ++o) {
            if (d[o] >= 0.0 && d[o] > t) {
                if (d[o] < next) {
                    next = d[o];
                    copies = 1;
                } else if (d[o] == next) {
                    ++copies;
                }
            }
        }
        if (copies == 0) break;  // fewer candidates than nearest: all are taken
        t = next;
        upToT += copies;
    }
    uint picks[WORDS];  // the replay's picks, when it runs
    [[unroll]] for (int w = 0; w < WORDS; ++w) picks[w] = 0u;
    // More candidates at t than places left, and the threshold does not take them all:
    // which ones go depends on the tool's selection sort (each pass swaps the first
    // smallest of the rest, in the window's column-by-column order, to the front).
    // Replay it on the valid candidates and take its picks instead of the cut; rare, so a
    // loop over memory is fine here.
    if (upToT > push.nearest && !(t < push.threshold)) {
        int n = 0, order[OFFSETS];
        for (int key = 0; key < OFFSETS; ++key) {
            int o = (key % SIDE) * SIDE + key / SIDE;
            if (Candidate(o, base, plane, x, y, own, ownArea) >= 0.0) order[n++] = o;
        }
        for (int k = 0; k < push.nearest; ++k) {
            int best = k;
            float bestD = Candidate(order[k], base, plane, x, y, own, ownArea);
            // Every lane runs the same count: on lavapipe (Mesa 22.3) stores after a loop
            // whose lanes leave at different counts were lost.
            for (int j = 1; j < OFFSETS; ++j) {
                if (j <= k || j >= n) continue;
                float dj = Candidate(order[j], base, plane, x, y, own, ownArea);
                if (dj < bestD) {
                    best = j;
                    bestD = dj;
                }
            }
            int picked = order[best];
            order[best] = order[k];
            order[k] = picked;
            picks[picked / 32] |= 1u << (picked % 32);
        }
        t = -1.0;
    }
    // The candidates up to the cut (or the replay's picks) and every one under the threshold.
    [[unroll]] for (int word = 0; word < WORDS; ++word) {
        uint bits = picks[word];
        [[unroll]] for (int bit = 0; bit < 32; ++bit) {
            int o = word * 32 + bit;
            if (o < OFFSETS && d[o] >= 0.0 && (d[o] <= t || d[o] < push.threshold))
                bits |= 1u << bit;
        }
        mask[(word * push.height + y) * push.width + x] = bits;
    }
}
