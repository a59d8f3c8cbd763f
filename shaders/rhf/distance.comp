#version 450
#extension GL_GOOGLE_include_directive : require

#include "rhf/distance.h"

// One invocation per (centre, window row dy): x across, strip row and dy from the grid;
// the lane walks the 2b+1 offsets of that row.
layout(local_size_x = RHF_DISTANCE_LOCAL_SIZE) in;
layout(constant_id = RHF_DISTANCE_SPEC_SEARCH_HALF) const int B = 6;
const int SIDE = 2 * B + 1;
layout(std430, binding = RHF_DISTANCE_SUM) readonly buffer TermSum { float termSum[]; };
layout(std430, binding = RHF_DISTANCE_COUNT) readonly buffer TermCount { float termCount[]; };
layout(std430, binding = RHF_DISTANCE_OUT) writeonly buffer Distance { float dist[]; };

void main() {
    int x = int(gl_GlobalInvocationID.x), r = int(gl_WorkGroupID.y), dy = int(gl_WorkGroupID.z);
    if (x >= push.width) return;
    int y = push.rowBase + r, qy = y + dy - B;
    int w0 = min(min(push.patchHalf, min(x, y)), min(push.width - 1 - x, push.height - 1 - y));
    bool rowOk = qy >= w0 && qy <= push.height - 1 - w0;
    for (int k = 0; k < SIDE; ++k) {
        int ox = k - B, oy = dy - B, qx = x + ox;
        float d = -1.0;
        if (rowOk && qx >= w0 && qx <= push.width - 1 - w0) {
            // Offsets with oy < 0: the terms of -o, stored at the candidate's pixels.
            bool mirrored = oy < 0;
            int plane = mirrored ? -oy * SIDE + 2 * B - k : oy * SIDE + k;
            int sx = x + (mirrored ? ox : 0), sy = y + (mirrored ? oy : 0) - push.termBase;
            float sum = 0.0, count = 0.0;
            for (int ty = -w0; ty <= w0; ++ty) {
                int row = (plane * push.termRows + sy + ty) * push.width + sx;
                for (int tx = -w0; tx <= w0; ++tx) {
                    sum += termSum[row + tx];
                    count += termCount[row + tx];
                }
            }
            d = sum / (count + 1e-4);
        }
        dist[((dy * SIDE + k) * push.rows + r) * push.width + x] = d;
    }
}
