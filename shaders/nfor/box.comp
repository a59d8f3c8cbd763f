#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "nfor/distance.h"

layout(local_size_x = NFOR_LOCAL_SIZE) in;
layout(binding = NFOR_BOX_IN) uniform samplerBuffer inputs;
layout(std430, binding = NFOR_BOX_OUT) writeonly buffer Out { float outputs[]; };

#include "nfor/offsets.glsl"

const int kBlock = NFOR_BOX_BLOCK, kReach = NFOR_MAX_PATCH, kSpan = kBlock + 2 * kReach;

// Patch positions t in [-f, f] with both x + t and x + t + o inside [0, n).
int along(int x, int o, int f, int n) {
    int lo = max(-f, max(-x, -x - o)), hi = min(f, min(n - 1 - x, n - 1 - x - o));
    return max(0, hi - lo + 1);
}

void main() {
    int j = int(gl_WorkGroupID.z), w = push.width, h = push.height, f = push.patchRadius;
    bool vertical = push.vertical != 0;
    // The block's first output, the axis it runs along, its length and its step.
    int x = int(gl_GlobalInvocationID.x) * (vertical ? 1 : kBlock);
    int y = int(gl_WorkGroupID.y) * (vertical ? kBlock : 1);
    if (x >= w || y >= h) return;
    int first = vertical ? y : x, n = vertical ? h : w, step = vertical ? w : 1;
    int base = j * w * h + y * w + x;
    // The values the block's patches read, loaded once for its outputs.
    float values[kSpan];
    [[unroll]] for (int i = 0; i < kSpan; ++i) {
        int t = i - kReach;
        values[i] = 0.0;
        if (t >= -f && t < kBlock + f && first + t >= 0 && first + t < n)
            values[i] = texelFetch(inputs, base + t * step).x;
    }
    ivec2 o = storedOffset(push.radius, j);
    [[unroll]] for (int k = 0; k < kBlock; ++k) {
        int at = first + k;
        if (at >= n) break;
        // The patch's positions inside, in the order of t.
        float sum = 0.0;
        [[unroll]] for (int t = -kReach; t <= kReach; ++t)
            if (t >= -f && t <= f && at + t >= 0 && at + t < n) sum += values[k + t + kReach];
        if (!vertical) {
            outputs[base + k] = sum;
            continue;
        }
        int count = along(x, o.x, f, w) * along(at, o.y, f, h);
        outputs[base + k * w] = count > 0 ? sum / float(count) : 0.0;
    }
}
