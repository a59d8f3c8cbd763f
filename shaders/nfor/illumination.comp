#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "nfor/distance.h"

layout(local_size_x = NFOR_LOCAL_SIZE) in;
layout(constant_id = NFOR_SPEC_CHANNELS) const int channels = 3;
layout(std430, binding = NFOR_ILLUMINATION_COLOR) readonly buffer Color { float color[]; };
layout(std430, binding = NFOR_ILLUMINATION_VARIANCE) readonly buffer Variance {
    float variance[];
};
layout(std430, binding = NFOR_ILLUMINATION_ALBEDO) readonly buffer Albedo { float albedo[]; };
layout(std430, binding = NFOR_ILLUMINATION_OUT) writeonly buffer Out { vec4 illumination[]; };
layout(std430, binding = NFOR_ILLUMINATION_TRUST) readonly buffer Trust { float trust[]; };

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y);
    int w = push.width, h = push.height;
    if (x >= w) return;
    vec4 value = vec4(0.0), noise = vec4(0.0), divisor = vec4(1.0);
    [[unroll]] for (int c = 0; c < channels; ++c) {
        int i = (c * h + y) * w + x;
        value[c] = color[i];
        noise[c] = variance[i];
        if (push.albedoChannels > 0) {
            // The channel's albedo above the floor divides out: texture and coverage.
            float a = albedo[(min(c, push.albedoChannels - 1) * h + y) * w + x];
            if (a > float(NFOR_NOISE_ALBEDO_FLOOR)) {
                value[c] = value[c] / a;
                noise[c] = noise[c] / (a * a);
                divisor[c] = a;
            }
        }
    }
    // An albedo not trusted: the divisor negated (a pair with such an end compares colours).
    if (push.trust != 0 && trust[y * w + x] == 0.0) divisor = -divisor;
    illumination[3 * (y * w + x)] = value;
    illumination[3 * (y * w + x) + 1] = noise;
    illumination[3 * (y * w + x) + 2] = divisor;
}
