#version 450
#extension GL_GOOGLE_include_directive : require

#include "temporal/finish.h"

layout(local_size_x = TEMPORAL_LOCAL_SIZE) in;
layout(std430, binding = TEMPORAL_FINISH_MOMENTS) readonly buffer Moments { float moments[]; };
layout(std430, binding = TEMPORAL_FINISH_COUNTS) readonly buffer Counts { float counts[]; };
layout(std430, binding = TEMPORAL_FINISH_POOLED) readonly buffer Pooled { float pooled[]; };
layout(std430, binding = TEMPORAL_FINISH_RAW) readonly buffer Raw { float raw[]; };
layout(std430, binding = TEMPORAL_FINISH_SUM0) readonly buffer Sum0 { float sum0[]; };
layout(std430, binding = TEMPORAL_FINISH_COUNTS0) readonly buffer Counts0 { float counts0[]; };
layout(std430, binding = TEMPORAL_FINISH_SUM1) readonly buffer Sum1 { float sum1[]; };
layout(std430, binding = TEMPORAL_FINISH_COUNTS1) readonly buffer Counts1 { float counts1[]; };
layout(std430, binding = TEMPORAL_FINISH_OUTPUT) writeonly buffer Output { float outputs[]; };

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y), c = int(gl_WorkGroupID.z);
    int w = push.width, h = push.height;
    if (x >= w) return;
    int n = w * h;
    int i = y * w + x;
    int C = push.channels;
    int o = c * n + i;
    float weights = counts[i], frames = counts[n + i];
    float m = frames > 0.0 ? moments[o] : raw[o];
    outputs[o] = m;

    float v = 0.0;
    if (weights > 0.0) {
        if ((push.flags & TEMPORAL_FINISH_WITH_POOLED) != 0) {
            v = pooled[o] / (weights * weights);
        } else if (frames >= 2.0) {
            v = moments[(C + c) * n + i] / ((frames - 1.0) * weights);
        } else {
            // Rows, then columns within a row: the reference sums in the same order.
            int r = push.fillRadius;
            float sumB = 0.0, dof = 0.0;
            for (int yy = max(0, y - r); yy <= min(h - 1, y + r); ++yy)
                for (int xx = max(0, x - r); xx <= min(w - 1, x + r); ++xx) {
                    float f = counts[n + yy * w + xx];
                    if (f < 2.0) continue;
                    sumB += moments[(C + c) * n + yy * w + xx];
                    dof += f - 1.0;
                }
            v = dof > 0.0 ? sumB / dof / weights : 0.0;
        }
    }
    outputs[(C + c) * n + i] = v;

    if ((push.flags & TEMPORAL_FINISH_WITH_HALVES) != 0) {
        float w0 = counts0[i], w1 = counts1[i];
        outputs[(2 * C + c) * n + i] = w0 > 0.0 ? sum0[o] / w0 : m;
        outputs[(3 * C + c) * n + i] = w1 > 0.0 ? sum1[o] / w1 : m;
    }
}
