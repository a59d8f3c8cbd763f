#version 450
#extension GL_GOOGLE_include_directive : require

#include "nfor/distance.h"

layout(local_size_x = NFOR_LOCAL_SIZE) in;
layout(constant_id = NFOR_SPEC_CHANNELS) const int channels = 3;
layout(std430, binding = NFOR_TERM_COLOR) readonly buffer Color { float color[]; };
layout(std430, binding = NFOR_TERM_VARIANCE) readonly buffer Variance { float variance[]; };
layout(std430, binding = NFOR_TERM_OUT) writeonly buffer Out { float terms[]; };
layout(std430, binding = NFOR_TERM_ALBEDO) readonly buffer Albedo { float albedo[]; };

#include "nfor/offsets.glsl"

int w, h;

// The colour and its variance at element i of plane c, divided by the albedo's channel
// where that is above the floor (the illumination, whose noise is the variance / a^2).
vec2 valueAt(int c, int x, int y) {
    int i = (c * h + y) * w + x;
    float value = color[i], v = variance[i];
    if (push.albedoChannels > 0) {
        float a = albedo[(min(c, push.albedoChannels - 1) * h + y) * w + x];
        if (a > float(NFOR_NOISE_ALBEDO_FLOOR)) return vec2(value / a, v / (a * a));
    }
    return vec2(value, v);
}

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y), j = int(gl_WorkGroupID.z);
    w = push.width;
    h = push.height;
    if (x >= w) return;
    ivec2 o = storedOffset(push.radius, j);
    int qx = x + o.x, qy = y + o.y;
    float term = 0.0;
    if (qx >= 0 && qy >= 0 && qx < w && qy < h) {
        for (int c = 0; c < channels; ++c) {
            vec2 p = valueAt(c, x, y), q = valueAt(c, qx, qy);
            float cp = p.x, cq = q.x, vp = p.y, vq = q.y;
            float diff = cp - cq;
            float s = push.minVariance != 0 ? 2.0 * min(vp, vq) : vp + vq;
            float t = (diff * diff - push.alpha * s) /
                      (s + float(NFOR_REL_EPS) * (cp * cp + cq * cq) + float(NFOR_TINY));
            term += min(t, float(NFOR_TERM_MAX));
        }
        term /= float(channels);
    }
    terms[(j * h + y) * w + x] = term;
}
