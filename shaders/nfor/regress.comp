#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "nfor/fit.h"

layout(local_size_x = NFOR_LOCAL_SIZE) in;
layout(constant_id = NFOR_SPEC_CHANNELS) const int channels = 3;
layout(constant_id = NFOR_SPEC_FEATURES) const int featureCount = 7;
const int columnCount = featureCount + 3;
const int packedCount = columnCount * (columnCount + 1) / 2;
// Arrays at their largest size; the loops run to the specialised counts.
const int kMaxColumns = NFOR_MAX_FEATURES + 3;
layout(std430, binding = NFOR_FIT_COLOR) readonly buffer Color { float color[]; };
layout(std430, binding = NFOR_FIT_FEATURES) readonly buffer Features { float features[]; };
layout(std430, binding = NFOR_FIT_MASK) readonly buffer Mask { float mask[]; };
layout(std430, binding = NFOR_FIT_DISTANCE) readonly buffer Distance { float distance[]; };
layout(std430, binding = NFOR_FIT_BETA) writeonly buffer Beta { float beta[]; };
layout(std430, binding = NFOR_FIT_OUT) writeonly buffer Hat { float hat[]; };

int w, h;

#include "nfor/weight.glsl"

// Lower triangle packed by rows: element (i, j), j <= i.
int tri(int i, int j) {
    return i * (i + 1) / 2 + j;
}

void writeConstant(int x, int y) {
    for (int c = 0; c < channels; ++c) {
        beta[(c * h + y) * w + x] = color[(c * h + y) * w + x];
        for (int i = 1; i < columnCount; ++i) beta[((i * channels + c) * h + y) * w + x] = 0.0;
    }
    hat[(push.outPlane * h + y) * w + x] = 1.0;
}

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y);
    w = push.width;
    h = push.height;
    if (x >= w) return;
    if (mask[y * w + x] == 0.0) {
        writeConstant(x, y);
        return;
    }
    float a[kMaxColumns * (kMaxColumns + 1) / 2], b[kMaxColumns * NFOR_MAX_CHANNELS];
    for (int i = 0; i < packedCount; ++i) a[i] = 0.0;
    for (int i = 0; i < kMaxColumns * NFOR_MAX_CHANNELS; ++i) b[i] = 0.0;
    float weights = 0.0;
    int r = push.radius;
    for (int v = y - r; v <= y + r; ++v)
        for (int u = x - r; u <= x + r; ++u) {
            float wq = weightOf(x, y, u, v);
            if (wq == 0.0) continue;
            columnsOf(x, y, u, v);
            for (int i = 0; i < columnCount; ++i) {
                float wx = wq * col[i];
                for (int j = 0; j <= i; ++j) a[tri(i, j)] += wx * col[j];
                for (int c = 0; c < channels; ++c)
                    b[c * kMaxColumns + i] += wx * color[(c * h + v) * w + u];
            }
            weights += wq;
        }
    for (int i = 1; i < columnCount; ++i) a[tri(i, i)] += push.ridge * weights;
    // Cholesky in place: A = L L^T.
    for (int j = 0; j < columnCount; ++j) {
        float s = a[tri(j, j)];
        for (int k = 0; k < j; ++k) s -= a[tri(j, k)] * a[tri(j, k)];
        if (!(s > 0.0)) {
            writeConstant(x, y);
            return;
        }
        float l = sqrt(s);
        a[tri(j, j)] = l;
        for (int i = j + 1; i < columnCount; ++i) {
            float t = a[tri(i, j)];
            for (int k = 0; k < j; ++k) t -= a[tri(i, k)] * a[tri(j, k)];
            a[tri(i, j)] = t / l;
        }
    }
    for (int c = 0; c < channels; ++c) {
        int o = c * kMaxColumns;
        for (int i = 0; i < columnCount; ++i) {
            float t = b[o + i];
            for (int k = 0; k < i; ++k) t -= a[tri(i, k)] * b[o + k];
            b[o + i] = t / a[tri(i, i)];
        }
        for (int i = columnCount - 1; i >= 0; --i) {
            float t = b[o + i];
            for (int k = i + 1; k < columnCount; ++k) t -= a[tri(k, i)] * b[o + k];
            b[o + i] = t / a[tri(i, i)];
        }
        for (int i = 0; i < columnCount; ++i) beta[((i * channels + c) * h + y) * w + x] = b[o + i];
    }
    // (A^-1)_00 = |L^-1 e_0|^2.
    float z[kMaxColumns];
    float influence = 0.0;
    for (int i = 0; i < columnCount; ++i) {
        float t = i == 0 ? 1.0 : 0.0;
        for (int k = 0; k < i; ++k) t -= a[tri(i, k)] * z[k];
        z[i] = t / a[tri(i, i)];
        influence += z[i] * z[i];
    }
    hat[(push.outPlane * h + y) * w + x] = influence;
}
