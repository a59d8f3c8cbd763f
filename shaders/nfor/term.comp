#version 450
#extension GL_GOOGLE_include_directive : require

#include "nfor/distance.h"

layout(local_size_x = NFOR_LOCAL_SIZE) in;
layout(constant_id = NFOR_SPEC_CHANNELS) const int channels = 3;
layout(std430, binding = NFOR_TERM_COLOR) readonly buffer Color { float color[]; };
layout(std430, binding = NFOR_TERM_VARIANCE) readonly buffer Variance { float variance[]; };
layout(std430, binding = NFOR_TERM_OUT) writeonly buffer Out { float terms[]; };

#include "nfor/offsets.glsl"

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y), j = int(gl_WorkGroupID.z);
    int w = push.width, h = push.height;
    if (x >= w) return;
    ivec2 o = storedOffset(push.radius, j);
    int qx = x + o.x, qy = y + o.y;
    float term = 0.0;
    if (qx >= 0 && qy >= 0 && qx < w && qy < h) {
        for (int c = 0; c < channels; ++c) {
            int p = (c * h + y) * w + x, q = (c * h + qy) * w + qx;
            float cp = color[p], cq = color[q], vp = variance[p], vq = variance[q];
            float diff = cp - cq;
            float t = (diff * diff - push.alpha * (vp + vq)) /
                      (vp + vq + float(NFOR_REL_EPS) * (cp * cp + cq * cq) + float(NFOR_TINY));
            term += min(t, float(NFOR_TERM_MAX));
        }
        term /= float(channels);
    }
    terms[(j * h + y) * w + x] = term;
}
