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

// No z at `at`: no data to the fits, and the input kept.
void noZ(int at) {
    zOut[at] = 0.0;
    sOut[at] = 0.0;
    nuOut[at] = -1.0;
    zsnOut[at] = vec4(0.0, 0.0, -1.0, 0.0);
}

const int kSide = (2 * PIVOT_SIDE_RADIUS + 1) * (2 * PIVOT_SIDE_RADIUS + 1);

// values[0..n) with v inserted in order.
void insertSorted(inout float values[kSide], inout int n, float v) {
    int j = n++;
    for (; j > 0 && values[j - 1] > v; --j) values[j] = values[j - 1];
    values[j] = v;
}

// The upper median of z over the pixels of (x, y)'s ids (`own`, the pixel among them) or of
// other ids within PIVOT_SIDE_RADIUS that have one, and the upper median of their distances
// to it; n = 0: none.
vec2 sideMedians(int x, int y, int base, bool own, out int n) {
    const int R = PIVOT_SIDE_RADIUS;
    float values[kSide];
    int i0 = y * gw + x;
    n = 0;
    for (int v = max(0, y - R); v <= min(gh - 1, y + R); ++v)
        for (int u = max(0, x - R); u <= min(gw - 1, x + R); ++u) {
            float zq;
            if ((idTerm(v * gw + u, i0) != 0.0) == own && ratioAt(base + v * gw + u, zq))
                insertSorted(values, n, zq);
        }
    if (n == 0) return vec2(0.0);
    float median = values[n / 2];
    float distances[kSide];
    int m = 0;
    for (int k = 0; k < n; ++k) insertSorted(distances, m, abs(values[k] - median));
    return vec2(median, distances[n / 2]);
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
    if (!hasZ) {
        noZ(at);
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
    // Beside other ids: data like any other pixel, unless it mixes in another side far from
    // its own (a light's rim first seen as the wall, or a wall first seen as the light): the
    // sides' medians of z over PIVOT_SIDE_GAP of their spreads apart, and its z over
    // PIVOT_SIDE_TOWARD of its deviation toward the other. Then it is kept.
    if (boundaryTerm(x, y) == 0.0) {
        int nOwn, nOther;
        vec2 side = sideMedians(x, y, base, true, nOwn);
        vec2 other = sideMedians(x, y, base, false, nOther);
        float spread = PIVOT_SIDE_MAD_SIGMA * max(side.y, other.y);
        float sigma2 = max(s, spread * spread), gap = other.x - side.x;
        float toward = gap > 0.0 ? z - side.x : side.x - z;
        if (nOther > 0 && gap * gap > PIVOT_SIDE_GAP * PIVOT_SIDE_GAP * spread * spread &&
            toward > 0.0 && toward * toward > PIVOT_SIDE_TOWARD * PIVOT_SIDE_TOWARD * sigma2) {
            noZ(at);
            return;
        }
    }
    zOut[at] = z;
    sOut[at] = s;
    float nu = s / max(zl * zl, PIVOT_TINY);
    nuOut[at] = nu;
    zsnOut[at] = vec4(z, s, nu, 0.0);
}
