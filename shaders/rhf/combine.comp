#version 450
#extension GL_GOOGLE_include_directive : require

#include "rhf/combine.h"

// One invocation per pixel and channel: x across, row and channel from the grid.
layout(local_size_x = RHF_COMBINE_LOCAL_SIZE) in;
layout(std430, binding = RHF_COMBINE_FILTERED) readonly buffer Filtered { float filtered[]; };
layout(std430, binding = RHF_COMBINE_LOW) readonly buffer Low { float low[]; };
layout(std430, binding = RHF_COMBINE_COARSE) readonly buffer Coarse { float coarse[]; };
layout(std430, binding = RHF_COMBINE_OUT) writeonly buffer Out { float outColor[]; };

// Keys' cubic convolution kernel with a = -0.5.
float Keys(float t) {
    const float a = -0.5;
    t = abs(t);
    if (t <= 1.0) return ((a + 2.0) * t - (a + 3.0)) * t * t + 1.0;
    if (t < 2.0) return ((a * t - 5.0 * a) * t + 8.0 * a) * t - 4.0 * a;
    return 0.0;
}

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y), c = int(gl_WorkGroupID.z);
    if (x >= push.width) return;
    int cw = push.coarseWidth, ch = push.coarseHeight, plane = c * cw * ch;
    float fx = 0.5 * float(x & 1), fy = 0.5 * float(y & 1);
    int ix = x >> 1, iy = y >> 1;
    float lowV = 0.0, coarseV = 0.0;
    for (int j = -1; j <= 2; ++j) {
        float wy = Keys(fy - float(j));
        int row = plane + clamp(iy + j, 0, ch - 1) * cw;
        for (int i = -1; i <= 2; ++i) {
            float w = wy * Keys(fx - float(i));
            int at = row + clamp(ix + i, 0, cw - 1);
            lowV += w * low[at];
            coarseV += w * coarse[at];
        }
    }
    int at = (c * push.height + y) * push.width + x;
    outColor[at] = filtered[at] - lowV + coarseV;
}
