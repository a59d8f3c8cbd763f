#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "nfor/fit.h"

layout(local_size_x = NFOR_LOCAL_SIZE) in;
layout(constant_id = NFOR_SPEC_CHANNELS) const int channels = 3;
layout(constant_id = NFOR_SPEC_FEATURES) const int featureCount = 7;
const int columnCount = featureCount + 3, candidateCount = 1;
const int betaVec4s = NFOR_BETA_STRIDE(featureCount, channels) / 4;
layout(binding = NFOR_FIT_PACKED) uniform samplerBuffer packed;
layout(binding = NFOR_FIT_DISTANCE) uniform samplerBuffer distance;
layout(binding = NFOR_FIT_BETA) uniform samplerBuffer beta;
layout(std430, binding = NFOR_FIT_OUT) writeonly buffer Out { float outputs[]; };
layout(binding = NFOR_FIT_COLOR) uniform samplerBuffer color;

int w, h;

#include "nfor/weight.glsl"

// The fit of window (u, v) at this pixel, per channel, column by column, from its
// coefficients loaded four at a time.
#define LOAD_BETA(k) \
    if ((k) < betaVec4s) coefficients[k] = texelFetch(beta, base + (k));
#define BETA(i, c) coefficients[((i) * channels + (c)) / 4][((i) * channels + (c)) % 4]
#define PREDICT(i)                                                     \
    if ((i) < columnCount) {                                           \
        value0 += col[i] * BETA(i, 0);                                 \
        if (channels > 1) value1 += col[i] * BETA(i, 1);               \
        if (channels > 2) value2 += col[i] * BETA(i, 2);               \
        if (channels > 3) value3 += col[i] * BETA(i, 3);               \
    }

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y);
    w = push.width;
    h = push.height;
    if (x >= w) return;
    if (texelFetch(packed, (y * w + x) * packedVec4s).x == 0.0) {
        for (int c = 0; c < channels; ++c) {
            float value = texelFetch(color, (c * h + y) * w + x).x;
            outputs[((push.outPlane + c) * h + y) * w + x] = value;
        }
        return;
    }
    loadFixed(x, y);
    float sum0 = 0.0, sum1 = 0.0, sum2 = 0.0, sum3 = 0.0, weights = 0.0;
    int r = push.gatherRadius;
    for (int v = y - r; v <= y + r; ++v)
        for (int u = x - r; u <= x + r; ++u) {
            if (u < 0 || v < 0 || u >= w || v >= h) continue;
            float wq = weightOf(u, v, x, y, u, v, -1.0);
            if (wq == 0.0) continue;
            vec4 coefficients[13];
            int base = (v * w + u) * betaVec4s;
            SEQ13(LOAD_BETA)
            float value0 = 0.0, value1 = 0.0, value2 = 0.0, value3 = 0.0;
            SEQ13(PREDICT)
            sum0 += wq * value0;
            sum1 += wq * value1;
            sum2 += wq * value2;
            sum3 += wq * value3;
            weights += wq;
        }
    float sums[NFOR_MAX_CHANNELS] = float[NFOR_MAX_CHANNELS](sum0, sum1, sum2, sum3);
    for (int c = 0; c < channels; ++c)
        outputs[((push.outPlane + c) * h + y) * w + x] = sums[c] / weights;
}
