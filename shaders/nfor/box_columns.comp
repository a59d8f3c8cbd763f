#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "nfor/distance.h"

// The column pass: vec4 groups in (the row pass's), one plane per stored offset out.
layout(local_size_x = NFOR_LOCAL_SIZE) in;
layout(binding = NFOR_BOX_IN) uniform samplerBuffer inputs;
layout(std430, binding = NFOR_BOX_OUT) writeonly buffer Out { float outputs[]; };

#include "nfor/offsets.glsl"

const int kBlock = NFOR_BOX_BLOCK, kReach = NFOR_MAX_PATCH, kSpan = kBlock + 2 * kReach;
const int kGroup = NFOR_TERM_OFFSETS;

// Patch positions t in [-f, f] with both x + t and x + t + o inside [0, n).
int along(int x, int o, int f, int n) {
    int lo = max(-f, max(-x, -x - o)), hi = min(f, min(n - 1 - x, n - 1 - x - o));
    return max(0, hi - lo + 1);
}

void main() {
    int group = int(gl_WorkGroupID.z), w = push.width, h = push.height, f = push.patchRadius;
    // The block's first output, down its column.
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y) * kBlock;
    if (x >= w) return;
    int base = group * w * h + y * w + x;
    // The groups the block's patches read, fetched once for its outputs.
    vec4 values[kSpan];
    [[unroll]] for (int i = 0; i < kSpan; ++i) {
        int t = i - kReach;
        values[i] = vec4(0.0);
        if (t >= -f && t < kBlock + f && y + t >= 0 && y + t < h)
            values[i] = texelFetch(inputs, base + t * w);
    }
    // The group's offsets and their patch positions along the row.
    ivec2 o[kGroup];
    int alongX[kGroup];
    [[unroll]] for (int c = 0; c < kGroup; ++c) {
        o[c] = storedOffset(push.radius, group * kGroup + c);
        alongX[c] = along(x, o[c].x, f, w);
    }
    [[unroll]] for (int k = 0; k < kBlock; ++k) {
        int at = y + k;
        if (at >= h) break;
        // The patch's positions inside, in the order of t.
        vec4 sum = vec4(0.0);
        [[unroll]] for (int t = -kReach; t <= kReach; ++t)
            if (t >= -f && t <= f && at + t >= 0 && at + t < h) sum += values[k + t + kReach];
        [[unroll]] for (int c = 0; c < kGroup; ++c) {
            int count = alongX[c] * along(at, o[c].y, f, h);
            outputs[(group * kGroup + c) * w * h + at * w + x] =
                count > 0 ? sum[c] / float(count) : 0.0;
        }
    }
}
