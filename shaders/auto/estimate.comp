#version 450
#extension GL_GOOGLE_include_directive : require

#include "auto/estimate.h"

layout(local_size_x = AUTO_LOCAL_SIZE) in;
layout(std430, binding = AUTO_ESTIMATE_COLOR) readonly buffer Color { float color[]; };
layout(std430, binding = AUTO_ESTIMATE_VARIANCE) readonly buffer Variance { float variance[]; };
layout(std430, binding = AUTO_ESTIMATE_PROBE) readonly buffer Probe { float probe[]; };
layout(std430, binding = AUTO_ESTIMATE_OUTPUT) readonly buffer Output { float outputs[]; };
layout(std430, binding = AUTO_ESTIMATE_PERTURBED) readonly buffer Perturbed { float perturbed[]; };
layout(std430, binding = AUTO_ESTIMATE_ERROR) writeonly buffer Error { float error[]; };
layout(std430, binding = AUTO_ESTIMATE_GUIDE) readonly buffer Guide { float guide[]; };
layout(std430, binding = AUTO_ESTIMATE_OFFSET) readonly buffer Offset { float offsets[]; };

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y);
    int w = push.width, h = push.height;
    if (x >= w) return;
    int plane = w * h, at = y * w + x;
    float sum = 0.0;
    for (int c = 0; c < push.channels; ++c) {
        int i = c * plane + at;
        float f = outputs[i], residual = f - color[i], v = variance[i];
        // The divergence term: the output's response to this value's own perturbation.
        float divergence = 2.0 * sqrt(max(v, 0.0)) * probe[i] * (perturbed[i] - f) / push.epsilon;
        float g = guide[i], d = g * g + AUTO_REL_OFFSET;
        // Comparisons, not max(): a NaN guide stays NaN (GLSL leaves max(NaN, x) open).
        float floorD = (v > 0.0 ? v : 0.0) / push.noiseCap;
        if (push.noiseCap > 0.0 && floorD > d) d = floorD;
        sum += (residual * residual - v + offsets[i] + divergence) / d;
    }
    error[at] = sum / float(push.channels);
}
