#version 450
#extension GL_GOOGLE_include_directive : require

#include "rhf/downsample.h"

// One invocation per result element: x across, row and plane from the grid.
layout(local_size_x = RHF_DOWNSAMPLE_LOCAL_SIZE) in;
layout(binding = RHF_DOWNSAMPLE_SRC) uniform samplerBuffer src;
layout(std430, binding = RHF_DOWNSAMPLE_DST) writeonly buffer Dst { float dst[]; };
layout(std430, binding = RHF_DOWNSAMPLE_WEIGHTS) readonly buffer Weights { float weights[]; };

// The tool's symmetric boundary: period 2n, the edge pixel repeated.
int Mirror(int i, int n) {
    int period = 2 * n;  // GLSL's % is undefined for negative operands
    i = i < 0 ? period - 1 - (-i - 1) % period : i % period;
    return i < n ? i : period - 1 - i;
}

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y), p = int(gl_WorkGroupID.z);
    if (x >= push.dstWidth) return;
    int srcPlane = p * push.srcWidth * push.srcHeight;
    float v = 0.0;
    // Taps start at floor((x + 0.5) step) - radius, as in the tool's sampler.
    int origin = (push.axis == 0 ? x : y) * push.step + push.step / 2 - push.radius;
    if (push.axis == 0) {
        int row = srcPlane + y * push.srcWidth;
        // Mirror only near the edges: its integer division is slow on CPU devices.
        if (origin >= 0 && origin + 2 * push.radius < push.srcWidth) {
            for (int i = 0; i <= 2 * push.radius; ++i)
                v += weights[i] * texelFetch(src, row + origin + i).r;
        } else {
            for (int i = 0; i <= 2 * push.radius; ++i)
                v += weights[i] * texelFetch(src, row + Mirror(origin + i, push.srcWidth)).r;
        }
    } else {
        bool inside = origin >= 0 && origin + 2 * push.radius < push.srcHeight;
        for (int i = 0; i <= 2 * push.radius; ++i) {
            int row = inside ? origin + i : Mirror(origin + i, push.srcHeight);
            v += weights[i] * texelFetch(src, srcPlane + row * push.srcWidth + x).r;
        }
    }
    dst[(p * push.dstHeight + y) * push.dstWidth + x] = v;
}
