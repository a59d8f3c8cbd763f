#version 450
#extension GL_GOOGLE_include_directive : require

#include "rhf/distance.h"

// One invocation per (centre, offset): x across, strip row and offset from the grid.
layout(local_size_x = RHF_DISTANCE_LOCAL_SIZE) in;
layout(std430, binding = RHF_DISTANCE_SUM) readonly buffer TermSum { float termSum[]; };
layout(std430, binding = RHF_DISTANCE_COUNT) readonly buffer TermCount { float termCount[]; };
layout(std430, binding = RHF_DISTANCE_OUT) writeonly buffer Distance { float dist[]; };

void main() {
    int x = int(gl_GlobalInvocationID.x), r = int(gl_WorkGroupID.y), o = int(gl_WorkGroupID.z);
    if (x >= push.width) return;
    int side = 2 * push.searchHalf + 1;
    int y = push.rowBase + r, qx = x + o % side - push.searchHalf,
        qy = y + o / side - push.searchHalf;
    int w0 = min(min(push.patchHalf, min(x, y)), min(push.width - 1 - x, push.height - 1 - y));
    float d = -1.0;
    if (qx >= w0 && qx <= push.width - 1 - w0 && qy >= w0 && qy <= push.height - 1 - w0) {
        float sum = 0.0, count = 0.0;
        for (int ty = -w0; ty <= w0; ++ty) {
            int row = (o * push.termRows + y + ty - push.termBase) * push.width + x;
            for (int tx = -w0; tx <= w0; ++tx) {
                sum += termSum[row + tx];
                count += termCount[row + tx];
            }
        }
        d = sum / (count + 1e-4);
    }
    dist[(o * push.rows + r) * push.width + x] = d;
}
