#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "nfor/fit.h"

layout(local_size_x = NFOR_LOCAL_SIZE) in;
layout(constant_id = NFOR_SPEC_CHANNELS) const int channels = 3;
layout(constant_id = NFOR_SPEC_FEATURES) const int featureCount = 7;
layout(constant_id = NFOR_SPEC_CANDIDATES) const int candidateCount = 1;
const int columnCount = featureCount + 3;
const int packedCount = columnCount * (columnCount + 1) / 2;
// Arrays at their largest size; the loops run to the specialised counts.
const int kMaxColumns = NFOR_MAX_FEATURES + 3;
const int kMaxPacked = kMaxColumns * (kMaxColumns + 1) / 2;
const int kMaxRight = kMaxColumns * NFOR_MAX_CHANNELS;
const int betaVec4s = NFOR_BETA_STRIDE(featureCount, channels) / 4;
layout(binding = NFOR_FIT_PACKED) uniform samplerBuffer packed;
layout(binding = NFOR_FIT_DISTANCE) uniform samplerBuffer distance;
// The coefficients as vec4s (the stride is a whole number of them): one store per vec4.
layout(std430, binding = NFOR_FIT_BETA) writeonly buffer Beta { vec4 beta[]; };
layout(std430, binding = NFOR_FIT_OUT) writeonly buffer Hat { float hat[]; };
layout(std430, binding = NFOR_FIT_SECOND_BETA) writeonly buffer SecondBeta {
    vec4 secondBeta[];
};

int w, h;

#define TRI(i, j) ((i) * ((i) + 1) / 2 + (j))
#define SEQ91(F) SEQ10(F, 0) SEQ10(F, 10) SEQ10(F, 20) SEQ10(F, 30) SEQ10(F, 40) SEQ10(F, 50) SEQ10(F, 60) SEQ10(F, 70) SEQ10(F, 80) F(90)
#define SEQ52(F) SEQ10(F, 0) SEQ10(F, 10) SEQ10(F, 20) SEQ10(F, 30) SEQ10(F, 40) F(50) F(51)
#define ZA(i) sa[i] = 0.0;
#define ZB(i) sb[i] = 0.0;
#define ZA2(i) sa2[i] = 0.0;
#define ZB2(i) sb2[i] = 0.0;
// Three steps at once (A, B, C: their columns colA.., colours cA.. and weights): each sum
// written once, its three terms added in the steps' order, as three single steps add them.
#define ACC3(SA, i, j) if ((j) <= (i)) SA[TRI(i, j)] = \
    ((SA[TRI(i, j)] + wxA * colA[j]) + wxB * colB[j]) + wxC * colC[j];
#define RIGHT3(SB, i, c, e) if (channels > (c)) SB[(c) * kMaxColumns + (i)] = \
    ((SB[(c) * kMaxColumns + (i)] + wxA * cA.e) + wxB * cB.e) + wxC * cC.e;
#define ROW3(SA, SB, WA, WB, WC, i) if ((i) < columnCount) { \
    float wxA = WA * colA[i], wxB = WB * colB[i], wxC = WC * colC[i]; \
    ACC3(SA, i, 0) ACC3(SA, i, 1) ACC3(SA, i, 2) ACC3(SA, i, 3) ACC3(SA, i, 4) ACC3(SA, i, 5) \
    ACC3(SA, i, 6) ACC3(SA, i, 7) ACC3(SA, i, 8) ACC3(SA, i, 9) ACC3(SA, i, 10) \
    ACC3(SA, i, 11) ACC3(SA, i, 12) \
    RIGHT3(SB, i, 0, x) RIGHT3(SB, i, 1, y) RIGHT3(SB, i, 2, z) RIGHT3(SB, i, 3, w) }
#define ACCUMULATE3(SA, SB, WA, WB, WC) ROW3(SA, SB, WA, WB, WC, 0) \
    ROW3(SA, SB, WA, WB, WC, 1) ROW3(SA, SB, WA, WB, WC, 2) ROW3(SA, SB, WA, WB, WC, 3) \
    ROW3(SA, SB, WA, WB, WC, 4) ROW3(SA, SB, WA, WB, WC, 5) ROW3(SA, SB, WA, WB, WC, 6) \
    ROW3(SA, SB, WA, WB, WC, 7) ROW3(SA, SB, WA, WB, WC, 8) ROW3(SA, SB, WA, WB, WC, 9) \
    ROW3(SA, SB, WA, WB, WC, 10) ROW3(SA, SB, WA, WB, WC, 11) ROW3(SA, SB, WA, WB, WC, 12)

#include "nfor/weight.glsl"

// Lower triangle packed by rows: element (i, j), j <= i.
int tri(int i, int j) {
    return i * (i + 1) / 2 + j;
}

// The pixel's colour (its packed vec4 past the features).
vec4 colorAt(int pixel) {
    return texelFetch(packed, pixel * packedVec4s + featureVec4s);
}

// Candidate k's fit, stored once at the end whichever way it went (lavapipe runs every
// storage store as a loop over the lanes, even where none takes it): its coefficients,
// column i and channel c from b[c * kMaxColumns + i], zeros in the padding, and its
// influence; a failed fit (an emitter, or a Cholesky without a positive pivot) writes the
// colour as the constant, no slope, influence 1.
void writeFit(int x, int y, int k, bool failed, vec4 color, float b[kMaxRight],
              float influence) {
    int base = (y * w + x) * betaVec4s;
    [[unroll]] for (int v = 0; v < betaVec4s; ++v) {
        vec4 value = vec4(0.0);
        [[unroll]] for (int e = 0; e < 4; ++e) {
            int index = 4 * v + e, i = index / channels, c = index % channels;
            if (i < columnCount)
                value[e] = failed ? (i == 0 ? color[c] : 0.0) : b[c * kMaxColumns + i];
        }
        if (k == 0)
            beta[base + v] = value;
        else
            secondBeta[base + v] = value;
    }
    hat[((push.outPlane + k) * h + y) * w + x] = failed ? 1.0 : influence;
}

// A candidate's normal equations (a: the lower triangle, b: the right sides, weights: the
// sum of its weights) with the ridge, solved by Cholesky: its coefficients and influence.
// A fit failed already (`failed`: an emitter) or failing on a pivot carries on to the end
// without a branch: its values are discarded there.
void solve(float a[kMaxPacked], float b[kMaxRight], float weights, int x, int y, int candidate,
           bool failed, vec4 color) {
    [[unroll]] for (int i = 1; i < columnCount; ++i) a[tri(i, i)] += push.ridge * weights;
    // Cholesky in place: A = L L^T.
    [[unroll]] for (int j = 0; j < columnCount; ++j) {
        float s = a[tri(j, j)];
        [[unroll]] for (int k = 0; k < j; ++k) s -= a[tri(j, k)] * a[tri(j, k)];
        failed = failed || !(s > 0.0);
        float l = sqrt(s);
        a[tri(j, j)] = l;
        [[unroll]] for (int i = j + 1; i < columnCount; ++i) {
            float t = a[tri(i, j)];
            [[unroll]] for (int k = 0; k < j; ++k) t -= a[tri(i, k)] * a[tri(j, k)];
            a[tri(i, j)] = t / l;
        }
    }
    [[unroll]] for (int c = 0; c < channels; ++c) {
        int o = c * kMaxColumns;
        [[unroll]] for (int i = 0; i < columnCount; ++i) {
            float t = b[o + i];
            [[unroll]] for (int k = 0; k < i; ++k) t -= a[tri(i, k)] * b[o + k];
            b[o + i] = t / a[tri(i, i)];
        }
        [[unroll]] for (int i = columnCount - 1; i >= 0; --i) {
            float t = b[o + i];
            [[unroll]] for (int k = i + 1; k < columnCount; ++k) t -= a[tri(k, i)] * b[o + k];
            b[o + i] = t / a[tri(i, i)];
        }
    }
    // (A^-1)_00 = |L^-1 e_0|^2.
    float z[kMaxColumns];
    float influence = 0.0;
    [[unroll]] for (int i = 0; i < columnCount; ++i) {
        float t = i == 0 ? 1.0 : 0.0;
        [[unroll]] for (int k = 0; k < i; ++k) t -= a[tri(i, k)] * z[k];
        z[i] = t / a[tri(i, i)];
        influence += z[i] * z[i];
    }
    writeFit(x, y, candidate, failed, color, b, influence);
}

// q = (u, v)'s step in p = (x, y)'s window without a branch (lavapipe runs a loop's body
// under a mask whichever way a lane goes): q's columns into col, its colour, its weight at
// the first bandwidth (returned) and at the second (secondWeight). Both weights are 0 where q
// is outside the frame, past the window's row (u > x + r: a last chunk's padding) or an
// emitter, 1 at q = p. Such a q reads the pixel of the frame and the window nearest to it,
// and p, or a step clamped onto p, reads the distance of offset (1, 0), which p stores (no
// plane holds p's distance to itself): values in range that the zero weight or the centre's
// 1 discards.
float stepWeight(int x, int y, int u, int v, out vec4 color) {
    int r = push.radius;
    bool inside = u >= 0 && v >= 0 && u < w && v < h && u <= x + r;
    bool centre = u == x && v == y;
    int qx = clamp(u, max(x - r, 0), min(x + r, w - 1)), qy = clamp(v, 0, h - 1);
    vec4 slots[3];
    LOAD_SLOTS(qy * w + qx)
    color = colorAt(qy * w + qx);
    col[0] = 1.0;
    col[1] = float(u - x) / float(r);
    col[2] = float(v - y) / float(r);
    float e = 0.0, sign = 1.0;
    SEQ10(COLUMN, 0)
    bool atP = qx == x && qy == y;
    float d = max(0.0, distanceOf(x, y, atP ? x + 1 : qx, qy));
    float second = 0.0;
    if (candidateCount > 1) {
        float e2 = e + d * push.secondInvBandwidth2;
        second = e2 > NFOR_EXP_CUT ? 0.0 : exp(-e2);
    }
    e += d * push.invBandwidth2;
    float first = e > NFOR_EXP_CUT ? 0.0 : exp(-e);
    bool valid = inside && slots[0].x != 0.0;
    secondWeight = valid ? (centre ? 1.0 : second) : 0.0;
    return valid ? (centre ? 1.0 : first) : 0.0;
}

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y);
    w = push.width;
    h = push.height;
    if (x >= w) return;
    // An emitter fits nothing: its sums stay zero and its fits fail, as constants.
    bool emitter = texelFetch(packed, (y * w + x) * packedVec4s).x == 0.0;
    vec4 color = colorAt(y * w + x);
    float sa[kMaxPacked], sb[kMaxRight], sa2[kMaxPacked], sb2[kMaxRight];
    SEQ91(ZA)
    SEQ52(ZB)
    if (candidateCount > 1) {
        SEQ91(ZA2)
        SEQ52(ZB2)
    }
    int r = push.radius;
    if (!emitter) {
        loadFixed(x, y);
        // Each row three steps at a time; a row whose length is no multiple of 3 ends in a
        // chunk whose steps past it weigh 0. A step adds its terms whatever its weight: a
        // zero weight times finite columns and colour (the front end keeps the inputs
        // finite) adds zeros, which leave the sums (from +0, never -0) unchanged. The
        // constant's sum sa[0] is the sum of the weights.
        for (int v = y - r; v <= y + r; ++v) {
            for (int u = x - r; u <= x + r; u += 3) {
                vec4 cA, cB, cC;
                float wA = stepWeight(x, y, u, v, cA), wA2 = secondWeight;
                float colA[kMaxColumns] = col;
                float wB = stepWeight(x, y, u + 1, v, cB), wB2 = secondWeight;
                float colB[kMaxColumns] = col;
                float wC = stepWeight(x, y, u + 2, v, cC), wC2 = secondWeight;
                float colC[kMaxColumns] = col;
                ACCUMULATE3(sa, sb, wA, wB, wC)
                if (candidateCount > 1) ACCUMULATE3(sa2, sb2, wA2, wB2, wC2)
            }
        }
    }
    solve(sa, sb, sa[0], x, y, 0, emitter, color);
    if (candidateCount > 1) solve(sa2, sb2, sa2[0], x, y, 1, emitter, color);
}
