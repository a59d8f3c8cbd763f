#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "nfor/glint.h"

layout(local_size_x = NFOR_LOCAL_SIZE) in;
layout(constant_id = NFOR_SPEC_CHANNELS) const int channels = 3;
layout(std430, binding = NFOR_GLINT_NEAR) readonly buffer Near { float near[]; };
layout(std430, binding = NFOR_GLINT_COLOR) readonly buffer Color { float color[]; };
layout(std430, binding = NFOR_GLINT_TRUST) readonly buffer Trust { float trust[]; };
layout(std430, binding = NFOR_GLINT_VARIANCE) buffer Variance { float variance[]; };
layout(std430, binding = NFOR_GLINT_FLOORED) writeonly buffer Floored { float floored[]; };

const float inverses[NFOR_GLINT_INVERSE_COUNT] = float[](NFOR_GLINT_INVERSES);

float ColorAt(int c, int x, int y) {
    return color[(c * push.height + y) * push.width + x];
}

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y);
    int w = push.width, h = push.height;
    if (x >= w) return;
    // A glint within reach: the row marks of the column's pixels within reach.
    bool gated = false;
    int v1 = min(y + push.reach, h - 1);
    for (int v = max(y - push.reach, 0); v <= v1 && !gated; ++v) gated = near[v * w + x] > 0.5;
    bool raised = false;
    if (gated && trust[y * w + x] == 0.0) {
        int x0 = max(x - 1, 0), x1 = min(x + 1, w - 1);
        int y0 = max(y - 1, 0), y1 = min(y + 1, h - 1);
        // 1 / n as a product (bit for bit with the CPU twin on any device).
        float inverse = inverses[(x1 - x0 + 1) * (y1 - y0 + 1)];
        [[unroll]] for (int c = 0; c < channels; ++c) {
            // Exact arithmetic (no contraction): the CPU reference sums in the same order.
            precise float mean = 0.0;
            for (int v = y0; v <= y1; ++v)
                for (int u = x0; u <= x1; ++u) mean += ColorAt(c, u, v);
            mean *= inverse;
            precise float squares = 0.0;
            for (int v = y0; v <= y1; ++v)
                for (int u = x0; u <= x1; ++u) {
                    precise float d = ColorAt(c, u, v) - mean;
                    squares += d * d;
                }
            precise float bound = push.scale * (squares * inverse);
            int i = (c * h + y) * w + x;
            if (bound > variance[i]) {
                variance[i] = bound;
                raised = true;
            }
        }
    }
    floored[y * w + x] = raised ? 1.0 : 0.0;
}
