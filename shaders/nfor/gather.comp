#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "nfor/fit.h"

layout(local_size_x = NFOR_LOCAL_SIZE) in;
layout(constant_id = NFOR_SPEC_CHANNELS) const int channels = 3;
layout(constant_id = NFOR_SPEC_FEATURES) const int featureCount = 7;
const int columnCount = featureCount + 3;
layout(std430, binding = NFOR_FIT_COLOR) readonly buffer Color { float color[]; };
layout(std430, binding = NFOR_FIT_FEATURES) readonly buffer Features { float features[]; };
layout(std430, binding = NFOR_FIT_MASK) readonly buffer Mask { float mask[]; };
layout(std430, binding = NFOR_FIT_DISTANCE) readonly buffer Distance { float distance[]; };
layout(std430, binding = NFOR_FIT_BETA) readonly buffer Beta { float beta[]; };
layout(std430, binding = NFOR_FIT_OUT) writeonly buffer Out { float outputs[]; };

int w, h;

#include "nfor/weight.glsl"

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y);
    w = push.width;
    h = push.height;
    if (x >= w) return;
    if (mask[y * w + x] == 0.0) {
        for (int c = 0; c < channels; ++c)
            outputs[((push.outPlane + c) * h + y) * w + x] = color[(c * h + y) * w + x];
        return;
    }
    float sum[NFOR_MAX_CHANNELS] = float[NFOR_MAX_CHANNELS](0.0, 0.0, 0.0, 0.0);
    float weights = 0.0;
    int r = push.gatherRadius;
    for (int v = y - r; v <= y + r; ++v)
        for (int u = x - r; u <= x + r; ++u) {
            if (u < 0 || v < 0 || u >= w || v >= h) continue;
            float wq = weightOf(u, v, x, y);
            if (wq == 0.0) continue;
            columnsOf(u, v, x, y);
            for (int c = 0; c < channels; ++c) {
                float value = 0.0;
                for (int i = 0; i < columnCount; ++i)
                    value += col[i] * beta[((i * channels + c) * h + v) * w + u];
                sum[c] += wq * value;
            }
            weights += wq;
        }
    for (int c = 0; c < channels; ++c)
        outputs[((push.outPlane + c) * h + y) * w + x] = sum[c] / weights;
}
