#version 450
#extension GL_GOOGLE_include_directive : require

#include "auto/smooth.h"

layout(local_size_x = AUTO_LOCAL_SIZE) in;
layout(std430, binding = AUTO_SMOOTH_INPUT) readonly buffer Input { float inputs[]; };
layout(std430, binding = AUTO_SMOOTH_OUTPUT) writeonly buffer Output { float outputs[]; };

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y), p = int(gl_WorkGroupID.z);
    int w = push.width, h = push.height, r = push.radius;
    if (x >= w) return;
    int base = p * w * h;
    float sum = 0.0;
    int n = 0;
    // Rows, then columns within a row: the reference sums in the same order.
    for (int v = max(0, y - r); v <= min(h - 1, y + r); ++v)
        for (int u = max(0, x - r); u <= min(w - 1, x + r); ++u) {
            float e = inputs[base + v * w + u];
            if (isnan(e) || isinf(e)) continue;
            sum += e;
            ++n;
        }
    outputs[base + y * w + x] = n > 0 ? sum / float(n) : uintBitsToFloat(0x7fc00000u);
}
