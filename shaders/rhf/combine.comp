#version 450
#extension GL_GOOGLE_include_directive : require

#include "rhf/combine.h"

// One invocation per pixel and channel: x across, row and channel from the grid.
layout(local_size_x = RHF_COMBINE_LOCAL_SIZE) in;
// Texel buffers: lavapipe gathers a texel fetch as one vector, a storage load lane by lane.
layout(binding = RHF_COMBINE_FILTERED) uniform samplerBuffer filtered;
layout(binding = RHF_COMBINE_LOW) uniform samplerBuffer low;
layout(binding = RHF_COMBINE_COARSE) uniform samplerBuffer coarse;
layout(std430, binding = RHF_COMBINE_OUT) writeonly buffer Out { float outColor[]; };

// Keys' cubic convolution kernel with a = -0.5.
float Keys(float t) {
    const float a = -0.5;
    t = abs(t);
    if (t <= 1.0) return ((a + 2.0) * t - (a + 3.0)) * t * t + 1.0;
    if (t < 2.0) return ((a * t - 5.0 * a) * t + 8.0 * a) * t - 4.0 * a;
    return 0.0;
}

// The tool's symmetric boundary: period 2n, the edge pixel repeated.
int Mirror(int i, int n) {
    int period = 2 * n;  // GLSL's % is undefined for negative operands
    i = i < 0 ? period - 1 - (-i - 1) % period : i % period;
    return i < n ? i : period - 1 - i;
}

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y), c = int(gl_WorkGroupID.z);
    if (x >= push.width) return;
    int cw = push.coarseWidth, ch = push.coarseHeight, plane = c * cw * ch;
    int fcw = push.frameCoarseWidth, fch = push.frameCoarseHeight;
    // Pixel centres aligned: fine x sits at coarse (x + 0.5) cw / width - 0.5, in the whole
    // frame's coordinates; the window's coarse origin is half its fine one.
    int cx0 = push.originX / 2, cy0 = push.originY / 2;
    float tx = (float(x + push.originX) + 0.5) * float(fcw) / float(push.frameWidth) - 0.5;
    float ty = (float(y + push.originY) + 0.5) * float(fch) / float(push.frameHeight) - 0.5;
    int ix = int(floor(tx)), iy = int(floor(ty));
    float fx = tx - float(ix), fy = ty - float(iy);
    // Mirror only near the frame's edges: its integer division is slow on CPU devices, and
    // lavapipe flattens a small conditional into both sides, so the four taps' indices are
    // found in one branch per axis. A tap outside the window (only in a halo's outer pixels,
    // which no tile keeps) clamps. The columns' weights are found once for the four rows.
    int rows[4], columns[4];
    if (ix >= 1 && ix + 2 < fcw) {
        for (int i = 0; i < 4; ++i) columns[i] = clamp(ix + i - 1 - cx0, 0, cw - 1);
    } else {
        for (int i = 0; i < 4; ++i) columns[i] = clamp(Mirror(ix + i - 1, fcw) - cx0, 0, cw - 1);
    }
    if (iy >= 1 && iy + 2 < fch) {
        for (int j = 0; j < 4; ++j) rows[j] = plane + clamp(iy + j - 1 - cy0, 0, ch - 1) * cw;
    } else {
        for (int j = 0; j < 4; ++j)
            rows[j] = plane + clamp(Mirror(iy + j - 1, fch) - cy0, 0, ch - 1) * cw;
    }
    float wx[4];
    for (int i = 0; i < 4; ++i) wx[i] = Keys(fx - float(i - 1));
    float lowV = 0.0, coarseV = 0.0;
    for (int j = 0; j < 4; ++j) {
        float wy = Keys(fy - float(j - 1));
        for (int i = 0; i < 4; ++i) {
            float w = wy * wx[i];
            lowV += w * texelFetch(low, rows[j] + columns[i]).r;
            coarseV += w * texelFetch(coarse, rows[j] + columns[i]).r;
        }
    }
    int at = (c * push.height + y) * push.width + x;
    outColor[at] = texelFetch(filtered, at).r - lowV + coarseV;
}
