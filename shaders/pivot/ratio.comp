#version 450
#extension GL_GOOGLE_include_directive : require

#include "pivot/ratio.h"

layout(local_size_x = PIVOT_LOCAL_SIZE) in;
layout(constant_id = PIVOT_SPEC_VARIANCE) const int hasVariance = 0;
layout(binding = PIVOT_RATIO_COLOR) uniform samplerBuffer color;
layout(binding = PIVOT_RATIO_PIVOT) uniform samplerBuffer pivot;
layout(binding = PIVOT_RATIO_VARIANCE) uniform samplerBuffer variance;
layout(std430, binding = PIVOT_RATIO_Z) writeonly buffer Z { float zOut[]; };
layout(std430, binding = PIVOT_RATIO_S) writeonly buffer S { float sOut[]; };
layout(std430, binding = PIVOT_RATIO_NU) writeonly buffer Nu { float nuOut[]; };
layout(std430, binding = PIVOT_RATIO_ZSN) writeonly buffer Zsn { vec4 zsnOut[]; };
layout(constant_id = PIVOT_SPEC_IDS) const int useIds = 0;
const int useNormals = 0;
layout(binding = PIVOT_RATIO_GUIDES) uniform samplerBuffer guides;

int planeSize, gw, gh;

#include "pivot/guides.glsl"

float threshold;

// z at `at` when the pixel has one.
bool ratioAt(int at, out float z) {
    float la = texelFetch(pivot, at).r;
    z = 0.0;
    if (!(la > threshold)) return false;
    z = texelFetch(color, at).r / la;
    return abs(z) <= PIVOT_Z_MAX;
}

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y), c = int(gl_WorkGroupID.z);
    int w = push.width, h = push.height;
    if (x >= w) return;
    threshold = c == 0 ? push.threshold0
                       : (c == 1 ? push.threshold1 : (c == 2 ? push.threshold2 : push.threshold3));
    planeSize = w * h;
    gw = w;
    gh = h;
    int base = c * w * h, at = base + y * w + x;
    float z;
    bool hasZ = ratioAt(at, z);
    if (!hasZ || boundaryTerm(x, y) == 0.0) {
        // A boundary pixel gives no data and keeps its input (it may mix both sides), but
        // where that is 0 (no sample reached light) the gather fills it from its own ids.
        float mark = hasZ && z == 0.0 ? PIVOT_BOUNDARY_NU : -1.0;
        zOut[at] = 0.0;
        sOut[at] = 0.0;
        nuOut[at] = mark;
        zsnOut[at] = vec4(0.0, 0.0, mark, 0.0);
        return;
    }
    // Mean of z over the valid 3x3 neighbours (the pixel is one), then their sample
    // variance about it (two passes: no cancellation).
    float sum = 0.0;
    int n = 0;
    for (int v = max(0, y - 1); v <= min(h - 1, y + 1); ++v)
        for (int u = max(0, x - 1); u <= min(w - 1, x + 1); ++u) {
            float zq;
            if (ratioAt(base + v * w + u, zq)) {
                sum += zq;
                ++n;
            }
        }
    float zl = sum / float(n);
    float s;
    if (hasVariance != 0) {
        float la = texelFetch(pivot, at).r;
        s = texelFetch(variance, at).r / la / la;
    } else {
        float sumSq = 0.0;
        for (int v = max(0, y - 1); v <= min(h - 1, y + 1); ++v)
            for (int u = max(0, x - 1); u <= min(w - 1, x + 1); ++u) {
                float zq;
                if (ratioAt(base + v * w + u, zq)) sumSq += (zq - zl) * (zq - zl);
            }
        s = n > 1 ? sumSq / float(n - 1) : 0.0;
    }
    s = min(s, PIVOT_Z_MAX * PIVOT_Z_MAX);
    zOut[at] = z;
    sOut[at] = s;
    float nu = s / max(zl * zl, PIVOT_TINY);
    nuOut[at] = nu;
    zsnOut[at] = vec4(z, s, nu, 0.0);
}
