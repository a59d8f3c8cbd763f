#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "rhf/distance.h"

// One invocation per (centre, offset): x across, strip row and offset from the grid.
layout(local_size_x = RHF_DISTANCE_LOCAL_SIZE) in;
layout(constant_id = RHF_DISTANCE_SPEC_SEARCH_HALF) const int B = 6;
layout(constant_id = RHF_DISTANCE_SPEC_PATCH_HALF) const int PW = 1;
const int SIDE = 2 * B + 1;
layout(binding = RHF_DISTANCE_SUM) uniform samplerBuffer termSum;
layout(binding = RHF_DISTANCE_COUNT) uniform samplerBuffer termCount;
layout(std430, binding = RHF_DISTANCE_OUT) writeonly buffer Distance { float dist[]; };

void main() {
    int x = int(gl_GlobalInvocationID.x), r = int(gl_WorkGroupID.y), o = int(gl_WorkGroupID.z);
    if (x >= push.width) return;
    int ox = o % SIDE - B, oy = o / SIDE - B, k = o % SIDE;
    int y = push.rowBase + r, qx = x + ox, qy = y + oy;
    int w0 = min(min(PW, min(x, y)), min(push.width - 1 - x, push.height - 1 - y));
    float d = -1.0;
    if (qx >= w0 && qx <= push.width - 1 - w0 && qy >= w0 && qy <= push.height - 1 - w0) {
        // Offsets with oy < 0: the terms of -o, stored at the candidate's pixels.
        bool mirrored = oy < 0;
        int plane = mirrored ? -oy * SIDE + 2 * B - k : oy * SIDE + k;
        int sx = x + (mirrored ? ox : 0), sy = y + (mirrored ? oy : 0) - push.termBase;
        int centre = (plane * push.termRows + sy) * push.width + sx;
        float sum = 0.0, count = 0.0;
        bool vetoed = false;  // a pixel pair marked by terms.comp (count -1)
        if (w0 == PW) {
            [[unroll]] for (int ty = -PW; ty <= PW; ++ty)
                [[unroll]] for (int tx = -PW; tx <= PW; ++tx) {
                float c = texelFetch(termCount, centre + ty * push.width + tx).r;
                sum += texelFetch(termSum, centre + ty * push.width + tx).r;
                count += c;
                vetoed = vetoed || c < 0.0;
            }
        } else {
            // Near the border: the shrunk patch.
            for (int ty = -w0; ty <= w0; ++ty)
                for (int tx = -w0; tx <= w0; ++tx) {
                    float c = texelFetch(termCount, centre + ty * push.width + tx).r;
                    sum += texelFetch(termSum, centre + ty * push.width + tx).r;
                    count += c;
                    vetoed = vetoed || c < 0.0;
                }
        }
        d = vetoed ? -1.0 : sum / (count + 1e-4);
    }
    dist[(o * push.rows + r) * push.width + x] = d;
}
