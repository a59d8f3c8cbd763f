#version 450
#extension GL_GOOGLE_include_directive : require

#include "rhf/terms.h"

// One invocation per (pixel, window row dy >= 0): x across, strip row and dy from the
// grid; the rows dy < 0 are the same terms seen from the candidate (distance.comp). A
// lane keeps the 2b+1 offsets of its window row in registers, reads each of its own bins
// once, and the lanes of a group read the candidates' bins contiguously.
layout(local_size_x = RHF_TERMS_LOCAL_SIZE) in;
layout(constant_id = RHF_TERMS_SPEC_SEARCH_HALF) const int B = 6;
const int SIDE = 2 * B + 1;
layout(std430, binding = 0) readonly buffer Hist0 { float hist0[]; };
layout(std430, binding = 1) readonly buffer Hist1 { float hist1[]; };
layout(std430, binding = 2) readonly buffer Hist2 { float hist2[]; };
layout(std430, binding = 3) readonly buffer Hist3 { float hist3[]; };
layout(std430, binding = 4) readonly buffer Hist4 { float hist4[]; };
layout(std430, binding = 5) readonly buffer Hist5 { float hist5[]; };
layout(std430, binding = RHF_TERMS_SUM) writeonly buffer TermSum { float termSum[]; };
layout(std430, binding = RHF_TERMS_COUNT) writeonly buffer TermCount { float termCount[]; };

// Plane `plane` of pixel `pixel`, from the buffer that holds that plane.
float Hist(int plane, int pixel) {
    int slot = plane / push.planesPerSlot;
    int at = (plane - slot * push.planesPerSlot) * (push.width * push.height) + pixel;
    switch (slot) {
    case 0: return hist0[at];
    case 1: return hist1[at];
    case 2: return hist2[at];
    case 3: return hist3[at];
    case 4: return hist4[at];
    default: return hist5[at];
    }
}

float sum[SIDE], count[SIDE], nq[SIDE];

// Add the terms of the bin planes buffer `h` (slot `slot`) holds.
#define ACCUMULATE(h, slot)                                                              \
    {                                                                                    \
        int first = slot * push.planesPerSlot;                                           \
        int last = min(first + push.planesPerSlot, push.binPlanes);                      \
        for (int plane = first; plane < last; ++plane) {                                 \
            int base = (plane - first) * pixels;                                         \
            float hp = h[base + p] * push.histScale;                                     \
            for (int k = 0; k < SIDE; ++k) {                                             \
                float hq = h[base + qRow + clamp(x + k - B, 0, push.width - 1)] *        \
                           push.histScale;                                               \
                float both = hp + hq;                                                    \
                if (both > 1.0 && nq[k] != 0.0) {                                        \
                    float d = nq[k] * hp - np * hq;                                      \
                    sum[k] += d * d / (np * nq[k] * both);                               \
                    count[k] += 1.0;                                                     \
                }                                                                        \
            }                                                                            \
        }                                                                                \
    }

void main() {
    int x = int(gl_GlobalInvocationID.x), r = int(gl_WorkGroupID.y), dy = int(gl_WorkGroupID.z);
    if (x >= push.width) return;
    int y = push.rowBase + r, qy = y + dy, pixels = push.width * push.height;
    for (int k = 0; k < SIDE; ++k) {
        sum[k] = 0.0;
        count[k] = 0.0;
        nq[k] = 0.0;
    }
    if (qy >= 0 && qy < push.height) {
        int p = y * push.width + x, qRow = qy * push.width;
        float np = Hist(push.binPlanes, p) * push.histScale;
        for (int k = 0; k < SIDE; ++k) {
            int qx = x + k - B;
            if (qx >= 0 && qx < push.width)
                nq[k] = Hist(push.binPlanes, qRow + qx) * push.histScale;
        }
        if (np != 0.0) {
            int slots = (push.binPlanes + push.planesPerSlot - 1) / push.planesPerSlot;
            ACCUMULATE(hist0, 0)
            if (slots > 1) ACCUMULATE(hist1, 1)
            if (slots > 2) ACCUMULATE(hist2, 2)
            if (slots > 3) ACCUMULATE(hist3, 3)
            if (slots > 4) ACCUMULATE(hist4, 4)
            if (slots > 5) ACCUMULATE(hist5, 5)
        }
    }
    for (int k = 0; k < SIDE; ++k) {
        int at = ((dy * SIDE + k) * push.rows + r) * push.width + x;
        termSum[at] = sum[k];
        termCount[at] = count[k];
    }
}
