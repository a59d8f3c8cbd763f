#version 450
#extension GL_GOOGLE_include_directive : require

#include "nfor/distance.h"

layout(local_size_x = NFOR_LOCAL_SIZE) in;
layout(std430, binding = NFOR_BOX_IN) readonly buffer In { float inputs[]; };
layout(std430, binding = NFOR_BOX_OUT) writeonly buffer Out { float outputs[]; };

#include "nfor/offsets.glsl"

// Patch positions t in [-f, f] with both x + t and x + t + o inside [0, n).
int along(int x, int o, int f, int n) {
    int lo = max(-f, max(-x, -x - o)), hi = min(f, min(n - 1 - x, n - 1 - x - o));
    return max(0, hi - lo + 1);
}

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y), j = int(gl_WorkGroupID.z);
    int w = push.width, h = push.height, f = push.patchRadius;
    if (x >= w) return;
    int base = j * w * h;
    float sum = 0.0;
    if (push.vertical == 0) {
        for (int t = max(-f, -x); t <= min(f, w - 1 - x); ++t) sum += inputs[base + y * w + x + t];
        outputs[base + y * w + x] = sum;
        return;
    }
    for (int t = max(-f, -y); t <= min(f, h - 1 - y); ++t) sum += inputs[base + (y + t) * w + x];
    ivec2 o = storedOffset(push.radius, j);
    int count = along(x, o.x, f, w) * along(y, o.y, f, h);
    outputs[base + y * w + x] = count > 0 ? sum / float(count) : 0.0;
}
