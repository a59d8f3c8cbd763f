#version 450
#extension GL_GOOGLE_include_directive : require

#include "rhf/terms.h"

// One invocation per (pixel, offset): x across, strip row and offset from the grid.
layout(local_size_x = RHF_TERMS_LOCAL_SIZE) in;
layout(std430, binding = 0) readonly buffer Hist0 { float hist0[]; };
layout(std430, binding = 1) readonly buffer Hist1 { float hist1[]; };
layout(std430, binding = 2) readonly buffer Hist2 { float hist2[]; };
layout(std430, binding = 3) readonly buffer Hist3 { float hist3[]; };
layout(std430, binding = 4) readonly buffer Hist4 { float hist4[]; };
layout(std430, binding = 5) readonly buffer Hist5 { float hist5[]; };
layout(std430, binding = RHF_TERMS_SUM) writeonly buffer TermSum { float termSum[]; };
layout(std430, binding = RHF_TERMS_COUNT) writeonly buffer TermCount { float termCount[]; };

// Bin `plane` of pixel `pixel`, from the buffer that holds that plane.
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

void main() {
    int x = int(gl_GlobalInvocationID.x), r = int(gl_WorkGroupID.y), o = int(gl_WorkGroupID.z);
    if (x >= push.width) return;
    int side = 2 * push.searchHalf + 1;
    int y = push.rowBase + r, qx = x + o % side - push.searchHalf,
        qy = y + o / side - push.searchHalf;
    float sum = 0.0, count = 0.0;
    if (qx >= 0 && qx < push.width && qy >= 0 && qy < push.height) {
        int p = y * push.width + x, q = qy * push.width + qx;
        float np = Hist(push.binPlanes, p) * push.histScale;
        float nq = Hist(push.binPlanes, q) * push.histScale;
        if (np != 0.0 && nq != 0.0) {
            for (int i = 0; i < push.binPlanes; ++i) {
                float hp = Hist(i, p) * push.histScale, hq = Hist(i, q) * push.histScale;
                float both = hp + hq;
                if (both > 1.0) {
                    float d = nq * hp - np * hq;
                    sum += d * d / (np * nq * both);
                    count += 1.0;
                }
            }
        }
    }
    int at = (o * push.rows + r) * push.width + x;
    termSum[at] = sum;
    termCount[at] = count;
}
