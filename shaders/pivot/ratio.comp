#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "pivot/ratio.h"

layout(local_size_x = PIVOT_LOCAL_SIZE) in;
layout(constant_id = PIVOT_SPEC_VARIANCE) const int hasVariance = 0;
layout(binding = PIVOT_RATIO_COLOR) uniform samplerBuffer color;
layout(binding = PIVOT_RATIO_PIVOT) uniform samplerBuffer pivot;
layout(binding = PIVOT_RATIO_VARIANCE) uniform samplerBuffer variance;
layout(std430, binding = PIVOT_RATIO_Z) writeonly buffer Z { float zOut[]; };
layout(std430, binding = PIVOT_RATIO_S) writeonly buffer S { float sOut[]; };
layout(std430, binding = PIVOT_RATIO_NU) writeonly buffer Nu { float nuOut[]; };
layout(std430, binding = PIVOT_RATIO_ZSN) writeonly buffer Zsn0 { vec4 zsn0[]; };
layout(std430, binding = PIVOT_RATIO_ZSN + 1) writeonly buffer Zsn1 { vec4 zsn1[]; };
layout(std430, binding = PIVOT_RATIO_ZSN + 2) writeonly buffer Zsn2 { vec4 zsn2[]; };
layout(std430, binding = PIVOT_RATIO_ZSN + 3) writeonly buffer Zsn3 { vec4 zsn3[]; };
layout(constant_id = PIVOT_SPEC_IDS) const int useIds = 0;
// 2: the packed input holds the edge test's level and noise; 1: z, s, nu alone.
layout(constant_id = PIVOT_SPEC_ZSN_TEXELS) const int zsnTexels = 2;
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

// Pixel i's (z, s, nu, level) and (noise, 0, 0, 0) into channel c's buffer, two texels a
// pixel (level: the 3x3 median of z; noise: the mean of s over the valid 3x3 neighbours);
// without the edge test's inputs (z, s, nu, 0), one texel.
void storeZsn(int c, int i, vec4 value, float noise) {
    vec4 extra = vec4(noise, 0.0, 0.0, 0.0);
    int at = zsnTexels * i;
    if (c == 0) {
        zsn0[at] = value;
        if (zsnTexels == 2) zsn0[at + 1] = extra;
    } else if (c == 1) {
        zsn1[at] = value;
        if (zsnTexels == 2) zsn1[at + 1] = extra;
    } else if (c == 2) {
        zsn2[at] = value;
        if (zsnTexels == 2) zsn2[at + 1] = extra;
    } else {
        zsn3[at] = value;
        if (zsnTexels == 2) zsn3[at + 1] = extra;
    }
}

// No z at `at` (pixel i of channel c): no data to the fits, and the input kept.
void noZ(int at, int c, int i) {
    zOut[at] = 0.0;
    sOut[at] = 0.0;
    nuOut[at] = -1.0;
    storeZsn(c, i, vec4(0.0, 0.0, -1.0, 0.0), 0.0);
}

const int kSide = (2 * PIVOT_SIDE_RADIUS + 1) * (2 * PIVOT_SIDE_RADIUS + 1);
// Above every z (at most PIVOT_Z_MAX) and every distance between two: an empty place.
const float kAbsent = 3.0e38;

#define PIVOT_SORT_PAIR(i, j)                  \
    {                                          \
        float lo = min(values[i], values[j]);  \
        values[j] = max(values[i], values[j]); \
        values[i] = lo;                        \
    }

// values in ascending order: Batcher's odd-even merge sort of 32 places without the
// comparators of the places past kSide (they would hold kAbsent and never move). Constant
// indices keep the values in registers, and every invocation runs the same instructions.
void sortSide(inout float values[kSide]) {
    PIVOT_SORT_PAIR(0, 1) PIVOT_SORT_PAIR(2, 3) PIVOT_SORT_PAIR(0, 2) PIVOT_SORT_PAIR(1, 3)
    PIVOT_SORT_PAIR(1, 2) PIVOT_SORT_PAIR(4, 5) PIVOT_SORT_PAIR(6, 7) PIVOT_SORT_PAIR(4, 6)
    PIVOT_SORT_PAIR(5, 7) PIVOT_SORT_PAIR(5, 6) PIVOT_SORT_PAIR(0, 4) PIVOT_SORT_PAIR(2, 6)
    PIVOT_SORT_PAIR(2, 4) PIVOT_SORT_PAIR(1, 5) PIVOT_SORT_PAIR(3, 7) PIVOT_SORT_PAIR(3, 5)
    PIVOT_SORT_PAIR(1, 2) PIVOT_SORT_PAIR(3, 4) PIVOT_SORT_PAIR(5, 6) PIVOT_SORT_PAIR(8, 9)
    PIVOT_SORT_PAIR(10, 11) PIVOT_SORT_PAIR(8, 10) PIVOT_SORT_PAIR(9, 11) PIVOT_SORT_PAIR(9, 10)
    PIVOT_SORT_PAIR(12, 13) PIVOT_SORT_PAIR(14, 15) PIVOT_SORT_PAIR(12, 14) PIVOT_SORT_PAIR(13, 15)
    PIVOT_SORT_PAIR(13, 14) PIVOT_SORT_PAIR(8, 12) PIVOT_SORT_PAIR(10, 14) PIVOT_SORT_PAIR(10, 12)
    PIVOT_SORT_PAIR(9, 13) PIVOT_SORT_PAIR(11, 15) PIVOT_SORT_PAIR(11, 13) PIVOT_SORT_PAIR(9, 10)
    PIVOT_SORT_PAIR(11, 12) PIVOT_SORT_PAIR(13, 14) PIVOT_SORT_PAIR(0, 8) PIVOT_SORT_PAIR(4, 12)
    PIVOT_SORT_PAIR(4, 8) PIVOT_SORT_PAIR(2, 10) PIVOT_SORT_PAIR(6, 14) PIVOT_SORT_PAIR(6, 10)
    PIVOT_SORT_PAIR(2, 4) PIVOT_SORT_PAIR(6, 8) PIVOT_SORT_PAIR(10, 12) PIVOT_SORT_PAIR(1, 9)
    PIVOT_SORT_PAIR(5, 13) PIVOT_SORT_PAIR(5, 9) PIVOT_SORT_PAIR(3, 11) PIVOT_SORT_PAIR(7, 15)
    PIVOT_SORT_PAIR(7, 11) PIVOT_SORT_PAIR(3, 5) PIVOT_SORT_PAIR(7, 9) PIVOT_SORT_PAIR(11, 13)
    PIVOT_SORT_PAIR(1, 2) PIVOT_SORT_PAIR(3, 4) PIVOT_SORT_PAIR(5, 6) PIVOT_SORT_PAIR(7, 8)
    PIVOT_SORT_PAIR(9, 10) PIVOT_SORT_PAIR(11, 12) PIVOT_SORT_PAIR(13, 14) PIVOT_SORT_PAIR(16, 17)
    PIVOT_SORT_PAIR(18, 19) PIVOT_SORT_PAIR(16, 18) PIVOT_SORT_PAIR(17, 19) PIVOT_SORT_PAIR(17, 18)
    PIVOT_SORT_PAIR(20, 21) PIVOT_SORT_PAIR(22, 23) PIVOT_SORT_PAIR(20, 22) PIVOT_SORT_PAIR(21, 23)
    PIVOT_SORT_PAIR(21, 22) PIVOT_SORT_PAIR(16, 20) PIVOT_SORT_PAIR(18, 22) PIVOT_SORT_PAIR(18, 20)
    PIVOT_SORT_PAIR(17, 21) PIVOT_SORT_PAIR(19, 23) PIVOT_SORT_PAIR(19, 21) PIVOT_SORT_PAIR(17, 18)
    PIVOT_SORT_PAIR(19, 20) PIVOT_SORT_PAIR(21, 22) PIVOT_SORT_PAIR(16, 24) PIVOT_SORT_PAIR(20, 24)
    PIVOT_SORT_PAIR(18, 20) PIVOT_SORT_PAIR(22, 24) PIVOT_SORT_PAIR(19, 21) PIVOT_SORT_PAIR(17, 18)
    PIVOT_SORT_PAIR(19, 20) PIVOT_SORT_PAIR(21, 22) PIVOT_SORT_PAIR(23, 24) PIVOT_SORT_PAIR(0, 16)
    PIVOT_SORT_PAIR(8, 24) PIVOT_SORT_PAIR(8, 16) PIVOT_SORT_PAIR(4, 20) PIVOT_SORT_PAIR(12, 20)
    PIVOT_SORT_PAIR(4, 8) PIVOT_SORT_PAIR(12, 16) PIVOT_SORT_PAIR(20, 24) PIVOT_SORT_PAIR(2, 18)
    PIVOT_SORT_PAIR(10, 18) PIVOT_SORT_PAIR(6, 22) PIVOT_SORT_PAIR(14, 22) PIVOT_SORT_PAIR(6, 10)
    PIVOT_SORT_PAIR(14, 18) PIVOT_SORT_PAIR(2, 4) PIVOT_SORT_PAIR(6, 8) PIVOT_SORT_PAIR(10, 12)
    PIVOT_SORT_PAIR(14, 16) PIVOT_SORT_PAIR(18, 20) PIVOT_SORT_PAIR(22, 24) PIVOT_SORT_PAIR(1, 17)
    PIVOT_SORT_PAIR(9, 17) PIVOT_SORT_PAIR(5, 21) PIVOT_SORT_PAIR(13, 21) PIVOT_SORT_PAIR(5, 9)
    PIVOT_SORT_PAIR(13, 17) PIVOT_SORT_PAIR(3, 19) PIVOT_SORT_PAIR(11, 19) PIVOT_SORT_PAIR(7, 23)
    PIVOT_SORT_PAIR(15, 23) PIVOT_SORT_PAIR(7, 11) PIVOT_SORT_PAIR(15, 19) PIVOT_SORT_PAIR(3, 5)
    PIVOT_SORT_PAIR(7, 9) PIVOT_SORT_PAIR(11, 13) PIVOT_SORT_PAIR(15, 17) PIVOT_SORT_PAIR(19, 21)
    PIVOT_SORT_PAIR(1, 2) PIVOT_SORT_PAIR(3, 4) PIVOT_SORT_PAIR(5, 6) PIVOT_SORT_PAIR(7, 8)
    PIVOT_SORT_PAIR(9, 10) PIVOT_SORT_PAIR(11, 12) PIVOT_SORT_PAIR(13, 14) PIVOT_SORT_PAIR(15, 16)
    PIVOT_SORT_PAIR(17, 18) PIVOT_SORT_PAIR(19, 20) PIVOT_SORT_PAIR(21, 22) PIVOT_SORT_PAIR(23, 24)
}

// values[k] for k in [0, kSide), by a select over the places (constant indices).
float valueAt(float values[kSide], int k) {
    float value = values[0];
    [[unroll]] for (int j = 1; j < kSide; ++j) value = j == k ? values[j] : value;
    return value;
}

// The upper median of the first n of the sorted values and the upper median of their
// distances to it; (0, 0) when n = 0.
vec2 medianAndSpread(inout float values[kSide], int n) {
    if (n == 0) return vec2(0.0);
    sortSide(values);
    float median = valueAt(values, n / 2);
    [[unroll]] for (int k = 0; k < kSide; ++k)
        values[k] = k < n ? abs(values[k] - median) : kAbsent;
    sortSide(values);
    return vec2(median, valueAt(values, n / 2));
}

// Over the pixels within PIVOT_SIDE_RADIUS of (x, y) that have a z, those of its ids (`own`,
// the pixel among them) and those of other ids: the upper median of each side's z and the
// upper median of their distances to it, and each side's count.
void sideMedians(int x, int y, int base, out vec2 own, out int nOwn, out vec2 other,
                 out int nOther) {
    const int R = PIVOT_SIDE_RADIUS, D = 2 * PIVOT_SIDE_RADIUS + 1;
    float ownValues[kSide], otherValues[kSide];
    int i0 = y * gw + x;
    nOwn = 0;
    nOther = 0;
    [[unroll]] for (int k = 0; k < kSide; ++k) {
        int u = x + k % D - R, v = y + k / D - R;
        float zq = 0.0;
        bool has = u >= 0 && u < gw && v >= 0 && v < gh && ratioAt(base + v * gw + u, zq);
        bool same = has && idTerm(v * gw + u, i0) != 0.0;
        ownValues[k] = has && same ? zq : kAbsent;
        otherValues[k] = has && !same ? zq : kAbsent;
        nOwn += has && same ? 1 : 0;
        nOther += has && !same ? 1 : 0;
    }
    own = medianAndSpread(ownValues, nOwn);
    other = medianAndSpread(otherValues, nOther);
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
        noZ(at, c, at - base);
        return;
    }
    // Mean of z over the valid 3x3 neighbours (the pixel is one), then their sample
    // variance about it (two passes: no cancellation). The same values sorted as they come
    // (an insertion sort of at most 9) give the edge test's level (pivot/edge.glsl): their
    // median (the upper one of an even count), which one bright sample does not lift and a
    // window straddling an edge takes from its larger side.
    // With a variance input the same loop sums the edge test's noise: the mean of the valid
    // neighbours' variances, which one pixel whose samples all missed (s = 0) does not take
    // to 0. Without the edge test the level is not sorted out and neither is stored.
    float sum = 0.0, noise = 0.0;
    float sorted[9];
    int n = 0;
    for (int v = max(0, y - 1); v <= min(h - 1, y + 1); ++v)
        for (int u = max(0, x - 1); u <= min(w - 1, x + 1); ++u) {
            float zq;
            if (!ratioAt(base + v * w + u, zq)) continue;
            sum += zq;
            int j = n++;
            if (zsnTexels == 1) continue;
            for (; j > 0 && sorted[j - 1] > zq; --j) sorted[j] = sorted[j - 1];
            sorted[j] = zq;
            if (hasVariance != 0) {
                float lq = texelFetch(pivot, base + v * w + u).r;
                noise += min(texelFetch(variance, base + v * w + u).r / lq / lq,
                             PIVOT_Z_MAX * PIVOT_Z_MAX);
            }
        }
    float zl = sum / float(n);
    float level = zsnTexels == 2 ? sorted[n / 2] : 0.0;
    float s;
    if (hasVariance != 0) {
        float la = texelFetch(pivot, at).r;
        s = texelFetch(variance, at).r / la / la;
        noise /= float(n);
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
    // Without a variance input s is the window's sample variance: the noise already.
    if (hasVariance == 0) noise = s;
    // Beside other ids: data like any other pixel, unless it mixes in another side far from
    // its own (a light's rim first seen as the wall, or a wall first seen as the light): the
    // sides' medians of z over PIVOT_SIDE_GAP of their spreads apart, and its z over
    // PIVOT_SIDE_TOWARD of its deviation toward the other. Then it is kept.
    if (boundaryTerm(x, y) == 0.0) {
        int nOwn, nOther;
        vec2 side, other;
        sideMedians(x, y, base, side, nOwn, other, nOther);
        float spread = PIVOT_SIDE_MAD_SIGMA * max(side.y, other.y);
        float sigma2 = max(s, spread * spread), gap = other.x - side.x;
        float toward = gap > 0.0 ? z - side.x : side.x - z;
        if (nOther > 0 && gap * gap > PIVOT_SIDE_GAP * PIVOT_SIDE_GAP * spread * spread &&
            toward > 0.0 && toward * toward > PIVOT_SIDE_TOWARD * PIVOT_SIDE_TOWARD * sigma2) {
            noZ(at, c, at - base);
            return;
        }
    }
    zOut[at] = z;
    sOut[at] = s;
    float nu = s / max(zl * zl, PIVOT_TINY);
    nuOut[at] = nu;
    storeZsn(c, at - base, vec4(z, s, nu, level), noise);
}
