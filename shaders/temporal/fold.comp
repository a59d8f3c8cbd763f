#version 450
#extension GL_GOOGLE_include_directive : require

#include "temporal/fold.h"

layout(local_size_x = TEMPORAL_LOCAL_SIZE) in;
layout(std430, binding = TEMPORAL_FOLD_VALUE) readonly buffer Value { float value[]; };
layout(std430, binding = TEMPORAL_FOLD_POSITION) readonly buffer Position { float position[]; };
layout(std430, binding = TEMPORAL_FOLD_WEIGHT) readonly buffer Weight { float weight[]; };
layout(std430, binding = TEMPORAL_FOLD_TOTAL) readonly buffer Total { float total[]; };
layout(std430, binding = TEMPORAL_FOLD_STATE) buffer State { float state[]; };

bool finite(float v) {
    return !(isnan(v) || isinf(v));
}

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y), c = int(gl_WorkGroupID.z);
    int w = push.width, h = push.height;
    if (x >= w) return;
    int n = w * h;
    int i = y * w + x;
    int o = c * n + i, ob = (push.channels + c) * n + i;
    float wt = weight[i];
    bool first = (push.flags & TEMPORAL_FOLD_FIRST) != 0;
    int mode = push.mode;

    // The frame's value: at the pixel itself, or where its position falls. A weight > 0
    // comes with a position inside the frame (stage 1); MIN/MAX's first fold reads the
    // pixel itself.
    float v = 0.0;
    bool centres = (push.flags & TEMPORAL_FOLD_CENTRES) != 0;
    if (mode != TEMPORAL_FOLD_COUNT) {
        if (centres) {
            v = value[o];
        } else if (wt > 0.0) {
            int k = int(floor(position[n + i])) * w + int(floor(position[i]));
            v = value[c * n + k];
        }
    }

    if (mode == TEMPORAL_FOLD_MIN || mode == TEMPORAL_FOLD_MAX) {
        if (first) {
            state[o] = v;
            return;
        }
        if (!(wt > 0.0) || !finite(v)) return;
        float a = state[o];
        bool better = mode == TEMPORAL_FOLD_MIN ? v < a : v > a;
        if (!finite(a) || better) state[o] = v;
        return;
    }
    if (!(wt > 0.0)) {
        if (first) {
            state[o] = 0.0;
            if (mode == TEMPORAL_FOLD_MOMENTS || mode == TEMPORAL_FOLD_COUNT) state[ob] = 0.0;
        }
        return;
    }
    if (mode == TEMPORAL_FOLD_MOMENTS) {
        if (first) {
            state[o] = v;
            state[ob] = 0.0;
            return;
        }
        float a = state[o];
        float total1 = total[i] + wt;
        float d = v - a;
        float a1 = a + d * (wt / total1);
        state[o] = a1;
        state[ob] = state[ob] + wt * d * (v - a1);
    } else if (mode == TEMPORAL_FOLD_SUM) {
        float f = push.power == 0 ? 1.0 : (push.power == 1 ? wt : wt * wt);
        state[o] = (first ? 0.0 : state[o]) + f * v;
    } else {
        state[o] = (first ? 0.0 : state[o]) + wt;
        state[ob] = (first ? 0.0 : state[ob]) + 1.0;
    }
}
