#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "nfor/distance.h"

layout(local_size_x = NFOR_LOCAL_SIZE) in;
layout(constant_id = NFOR_SPEC_CHANNELS) const int channels = 3;
layout(binding = NFOR_TERM_ILLUMINATION) uniform samplerBuffer illumination;
layout(std430, binding = NFOR_TERM_OUT) writeonly buffer Out { vec4 terms[]; };

#include "nfor/offsets.glsl"

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y);
    int group = int(gl_WorkGroupID.z), first = group * NFOR_TERM_OFFSETS;
    int w = push.width, h = push.height;
    if (x >= w) return;
    // p's values are fetched once for its NFOR_TERM_OFFSETS offsets.
    int p = 3 * (y * w + x);
    vec4 valueP = texelFetch(illumination, p), noiseP = texelFetch(illumination, p + 1);
    vec4 divisorP = texelFetch(illumination, p + 2);
    vec4 groupTerms;
    [[unroll]] for (int k = 0; k < NFOR_TERM_OFFSETS; ++k) {
        ivec2 o = storedOffset(push.radius, first + k);
        int qx = x + o.x, qy = y + o.y;
        float term = 0.0;
        if (qx >= 0 && qy >= 0 && qx < w && qy < h) {
            int q = 3 * (qy * w + qx);
            vec4 valueQ = texelFetch(illumination, q), noiseQ = texelFetch(illumination, q + 1);
            vec4 divisorQ = texelFetch(illumination, q + 2);
            // Both albedos trusted: colour / albedo; else the colours themselves.
            bool divided = divisorP.x > 0.0 && divisorQ.x > 0.0;
            [[unroll]] for (int c = 0; c < channels; ++c) {
                float cp = valueP[c], cq = valueQ[c], vp = noiseP[c], vq = noiseQ[c];
                if (!divided) {
                    float dp = abs(divisorP[c]), dq = abs(divisorQ[c]);
                    cp *= dp;
                    cq *= dq;
                    // A square that overflows (an albedo past about 1.8e19) multiplies in
                    // two steps: a variance of 0 stays 0, not NaN.
                    float dp2 = dp * dp, dq2 = dq * dq;
                    vp = isinf(dp2) ? vp * dp * dp : vp * dp2;
                    vq = isinf(dq2) ? vq * dq * dq : vq * dq2;
                }
                float diff = cp - cq;
                float s = push.minVariance != 0 ? 2.0 * min(vp, vq) : vp + vq;
                float t = (diff * diff - push.alpha * s) /
                          (s + float(NFOR_REL_EPS) * (cp * cp + cq * cq) + float(NFOR_TINY));
                term += min(t, float(NFOR_TERM_MAX));
            }
            term /= float(channels);
        }
        groupTerms[k] = term;
    }
    // The group's terms in one store (lavapipe stores lane by lane, a vec4 as one).
    terms[group * w * h + y * w + x] = groupTerms;
}
