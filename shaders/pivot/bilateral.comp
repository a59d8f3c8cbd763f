#version 450
#extension GL_GOOGLE_include_directive : require

#include "pivot/bilateral.h"

layout(local_size_x = PIVOT_LOCAL_SIZE) in;
layout(constant_id = PIVOT_SPEC_NORMALS) const int useNormals = 0;
layout(constant_id = PIVOT_SPEC_IDS) const int useIds = 0;
layout(binding = PIVOT_BILATERAL_COLOR) uniform samplerBuffer color;
layout(binding = PIVOT_BILATERAL_PIVOT) uniform samplerBuffer pivot;
layout(binding = PIVOT_BILATERAL_Z) uniform samplerBuffer zIn;
layout(binding = PIVOT_BILATERAL_NU) uniform samplerBuffer nuIn;
layout(binding = PIVOT_BILATERAL_GUIDES) uniform samplerBuffer guides;
layout(std430, binding = PIVOT_BILATERAL_OUT) writeonly buffer Out { float outImage[]; };

int planeSize, gw, gh;

#include "pivot/fitted.glsl"
#include "pivot/guides.glsl"

// The pivot's channel mean: the range guide, shared by the channels.
float luma(int i) {
    float sum = 0.0;
    for (int c = 0; c < push.channels; ++c) sum += texelFetch(pivot, c * planeSize + i).r;
    return sum / float(push.channels);
}

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y), c = int(gl_WorkGroupID.z);
    int w = push.width, h = push.height, r = push.radius;
    if (x >= w) return;
    planeSize = w * h;
    gw = w;
    gh = h;
    int i = y * w + x, at = c * planeSize + i, base = c * planeSize;
    if (texelFetch(nuIn, at).r < 0.0) {
        outImage[at] = texelFetch(color, at).r;
        return;
    }
    float g = luma(i), sumW = 0.0, sumWz = 0.0;
    Surface here = surfaceAt(i);
    float spatial = 1.0 / (2.0 * push.sigmaS * push.sigmaS);
    float range = 1.0 / (2.0 * push.sigmaRange * push.sigmaRange);
    for (int v = max(0, y - r); v <= min(h - 1, y + r); ++v)
        for (int u = max(0, x - r); u <= min(w - 1, x + r); ++u) {
            int q = v * w + u;
            float nu = texelFetch(nuIn, base + q).r;
            if (nu < 0.0 || nu > push.goodNu) continue;
            float gq = luma(q);
            float rel = (gq - g) / max(max(abs(g), abs(gq)), PIVOT_TINY);
            float d2 = float((u - x) * (u - x) + (v - y) * (v - y));
            float e = d2 * spatial + rel * rel * range;
            if (e > PIVOT_EXP_CUT) continue;
            float weight = exp(-e) * geometricTerm(surfaceAt(q), here);
            sumW += weight;
            sumWz += weight * texelFetch(zIn, base + q).r;
        }
    float inputValue = texelFetch(color, at).r;
    outImage[at] =
        sumW > 0.0 ? FilteredValue(texelFetch(pivot, at).r * (sumWz / sumW), inputValue)
                   : inputValue;
}
