#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "nfor/distance.h"

// The row pass: vec4 groups in, vec4 groups out (nfor/distance.h).
layout(local_size_x = NFOR_LOCAL_SIZE) in;
layout(binding = NFOR_BOX_IN) uniform samplerBuffer inputs;
layout(std430, binding = NFOR_BOX_OUT) writeonly buffer Out { vec4 outputs[]; };

const int kBlock = NFOR_BOX_BLOCK, kReach = NFOR_MAX_PATCH, kSpan = kBlock + 2 * kReach;

void main() {
    int group = int(gl_WorkGroupID.z), w = push.width, h = push.height, f = push.patchRadius;
    // The block's first output.
    int x = int(gl_GlobalInvocationID.x) * kBlock, y = int(gl_WorkGroupID.y);
    if (x >= w) return;
    int base = group * w * h + y * w + x;
    // The groups the block's patches read, fetched once for its outputs.
    vec4 values[kSpan];
    [[unroll]] for (int i = 0; i < kSpan; ++i) {
        int t = i - kReach;
        values[i] = vec4(0.0);
        if (t >= -f && t < kBlock + f && x + t >= 0 && x + t < w)
            values[i] = texelFetch(inputs, base + t);
    }
    [[unroll]] for (int k = 0; k < kBlock; ++k) {
        int at = x + k;
        if (at >= w) break;
        // The patch's positions inside, in the order of t; the group's offsets side by side.
        vec4 sum = vec4(0.0);
        [[unroll]] for (int t = -kReach; t <= kReach; ++t)
            if (t >= -f && t <= f && at + t >= 0 && at + t < w) sum += values[k + t + kReach];
        outputs[base + k] = sum;
    }
}
