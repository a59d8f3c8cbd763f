#version 450
#extension GL_GOOGLE_include_directive : require

#include "rhf/downsample.h"

// One invocation per result element: x across, row and plane from the grid.
layout(local_size_x = RHF_DOWNSAMPLE_LOCAL_SIZE) in;
layout(binding = RHF_DOWNSAMPLE_SRC) uniform samplerBuffer src;
layout(std430, binding = RHF_DOWNSAMPLE_DST) writeonly buffer Dst { float dst[]; };
layout(std430, binding = RHF_DOWNSAMPLE_WEIGHTS) readonly buffer Weights { float weights[]; };

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y), p = int(gl_WorkGroupID.z);
    if (x >= push.dstWidth) return;
    int srcPlane = p * push.srcWidth * push.srcHeight;
    float v = 0.0;
    if (push.axis == 0) {
        int row = srcPlane + y * push.srcWidth;
        for (int i = -push.radius; i <= push.radius; ++i)
            v += weights[i + push.radius] *
                 texelFetch(src, row + clamp(push.step * x + i, 0, push.srcWidth - 1)).r;
    } else {
        for (int i = -push.radius; i <= push.radius; ++i) {
            int row = clamp(push.step * y + i, 0, push.srcHeight - 1);
            v += weights[i + push.radius] *
                 texelFetch(src, srcPlane + row * push.srcWidth + x).r;
        }
    }
    dst[(p * push.dstHeight + y) * push.dstWidth + x] = v;
}
