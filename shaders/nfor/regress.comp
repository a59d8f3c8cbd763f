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
const int betaStride = NFOR_BETA_STRIDE(featureCount, channels);
layout(binding = NFOR_FIT_PACKED) uniform samplerBuffer packed;
layout(binding = NFOR_FIT_DISTANCE) uniform samplerBuffer distance;
layout(std430, binding = NFOR_FIT_BETA) writeonly buffer Beta { float beta[]; };
layout(std430, binding = NFOR_FIT_OUT) writeonly buffer Hat { float hat[]; };
layout(std430, binding = NFOR_FIT_SECOND_BETA) writeonly buffer SecondBeta {
    float secondBeta[];
};

int w, h;

#define TRI(i, j) ((i) * ((i) + 1) / 2 + (j))
#define ACC(SA, i, j) if ((j) <= (i)) SA[TRI(i, j)] += wx * col[j];
#define ROW(SA, SB, WQ, i) if ((i) < columnCount) { float wx = WQ * col[i]; \
    ACC(SA, i, 0) ACC(SA, i, 1) ACC(SA, i, 2) ACC(SA, i, 3) ACC(SA, i, 4) ACC(SA, i, 5) \
    ACC(SA, i, 6) ACC(SA, i, 7) ACC(SA, i, 8) ACC(SA, i, 9) ACC(SA, i, 10) ACC(SA, i, 11) \
    ACC(SA, i, 12) \
    SB[i] += wx * c0; \
    if (channels > 1) SB[kMaxColumns + (i)] += wx * c1; \
    if (channels > 2) SB[2 * kMaxColumns + (i)] += wx * c2; \
    if (channels > 3) SB[3 * kMaxColumns + (i)] += wx * c3; }
#define SEQ91(F) SEQ10(F, 0) SEQ10(F, 10) SEQ10(F, 20) SEQ10(F, 30) SEQ10(F, 40) SEQ10(F, 50) SEQ10(F, 60) SEQ10(F, 70) SEQ10(F, 80) F(90)
#define SEQ52(F) SEQ10(F, 0) SEQ10(F, 10) SEQ10(F, 20) SEQ10(F, 30) SEQ10(F, 40) F(50) F(51)
#define ZA(i) sa[i] = 0.0;
#define ZB(i) sb[i] = 0.0;
#define ZA2(i) sa2[i] = 0.0;
#define ZB2(i) sb2[i] = 0.0;
#define ACCUMULATE(SA, SB, WQ) ROW(SA, SB, WQ, 0) ROW(SA, SB, WQ, 1) ROW(SA, SB, WQ, 2) \
    ROW(SA, SB, WQ, 3) ROW(SA, SB, WQ, 4) ROW(SA, SB, WQ, 5) ROW(SA, SB, WQ, 6) \
    ROW(SA, SB, WQ, 7) ROW(SA, SB, WQ, 8) ROW(SA, SB, WQ, 9) ROW(SA, SB, WQ, 10) \
    ROW(SA, SB, WQ, 11) ROW(SA, SB, WQ, 12)

#include "nfor/weight.glsl"

// Lower triangle packed by rows: element (i, j), j <= i.
int tri(int i, int j) {
    return i * (i + 1) / 2 + j;
}

// The pixel's colour (its packed vec4 past the features).
vec4 colorAt(int pixel) {
    return texelFetch(packed, pixel * packedVec4s + featureVec4s);
}

// Candidate k's coefficient `index`.
void writeBeta(int k, int index, float value) {
    if (k == 0)
        beta[index] = value;
    else
        secondBeta[index] = value;
}

// Candidate k's fit of the colour as a constant: no slope, influence 1.
void writeConstant(int x, int y, int k) {
    int base = (y * w + x) * betaStride;
    vec4 color = colorAt(y * w + x);
    [[unroll]] for (int c = 0; c < channels; ++c) {
        writeBeta(k, base + c, color[c]);
        [[unroll]] for (int i = 1; i < columnCount; ++i) writeBeta(k, base + i * channels + c, 0.0);
    }
    hat[((push.outPlane + k) * h + y) * w + x] = 1.0;
}

// A candidate's normal equations (a: the lower triangle, b: the right sides, weights: the
// sum of its weights) with the ridge, solved by Cholesky: its coefficients and influence.
void solve(float a[kMaxPacked], float b[kMaxRight], float weights, int x, int y,
           int candidate) {
    [[unroll]] for (int i = 1; i < columnCount; ++i) a[tri(i, i)] += push.ridge * weights;
    // Cholesky in place: A = L L^T.
    [[unroll]] for (int j = 0; j < columnCount; ++j) {
        float s = a[tri(j, j)];
        [[unroll]] for (int k = 0; k < j; ++k) s -= a[tri(j, k)] * a[tri(j, k)];
        if (!(s > 0.0)) {
            writeConstant(x, y, candidate);
            return;
        }
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
        [[unroll]] for (int i = 0; i < columnCount; ++i)
            writeBeta(candidate, (y * w + x) * betaStride + i * channels + c, b[o + i]);
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
    hat[((push.outPlane + candidate) * h + y) * w + x] = influence;
}

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y);
    w = push.width;
    h = push.height;
    if (x >= w) return;
    if (texelFetch(packed, (y * w + x) * packedVec4s).x == 0.0) {
        writeConstant(x, y, 0);
        if (candidateCount > 1) writeConstant(x, y, 1);
        return;
    }
    loadFixed(x, y);
    float sa[kMaxPacked], sb[kMaxRight], sa2[kMaxPacked], sb2[kMaxRight];
    SEQ91(ZA)
    SEQ52(ZB)
    if (candidateCount > 1) {
        SEQ91(ZA2)
        SEQ52(ZB2)
    }
    float weights = 0.0, secondWeights = 0.0;
    int r = push.radius;
    for (int v = y - r; v <= y + r; ++v)
        for (int u = x - r; u <= x + r; ++u) {
            if (u < 0 || v < 0 || u >= w || v >= h) continue;
            float wq = weightOf(x, y, u, v, u, v, 1.0);
            float wq2 = secondWeight;
            if (wq == 0.0 && (candidateCount == 1 || wq2 == 0.0)) continue;
            vec4 cq = colorAt(v * w + u);
            float c0 = cq.x, c1 = cq.y, c2 = cq.z, c3 = cq.w;
            if (wq != 0.0) {
                ACCUMULATE(sa, sb, wq)
                weights += wq;
            }
            if (candidateCount > 1 && wq2 != 0.0) {
                ACCUMULATE(sa2, sb2, wq2)
                secondWeights += wq2;
            }
        }
    solve(sa, sb, weights, x, y, 0);
    if (candidateCount > 1) solve(sa2, sb2, secondWeights, x, y, 1);
}
