#version 450
#extension GL_GOOGLE_include_directive : require

#include "bayes/shrink.h"
#include "bayes/model.glsl"

layout(local_size_x = BAYES_SHRINK_LOCAL_SIZE) in;
layout(std430, binding = BAYES_SHRINK_COEF) buffer Coef { float coef[]; };
layout(std430, binding = BAYES_SHRINK_PARAMS) readonly buffer Params { float params[]; };
layout(std430, binding = BAYES_SHRINK_TABLE) readonly buffer Table { float table[]; };

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y), c = int(gl_WorkGroupID.z);
    if (x >= push.width) return;
    int inChannel = BayesBandOf(x, y, push.width, push.height, push.levels);
    if (inChannel < 0) return;
    int band = c * 3 * push.levels + inChannel;
    int at = (c * push.height + y) * push.width + x;
    float v = coef[at];
    int fit = int(params[band * BAYES_PARAM_STRIDE + 4]);
    if (fit == BAYES_FIT_NO_NOISE) return;
    float b = params[band * BAYES_PARAM_STRIDE + 6], du = params[band * BAYES_PARAM_STRIDE + 7];
    float a = abs(v), value = 0.0;
    int base = band * BAYES_TABLE_SIZE;
    if (du > 0.0) {
        float t = asinh(a / b) / du;
        const int last = BAYES_TABLE_SIZE - 1;
        if (t >= float(last)) {
            value = table[base + last] + (a - b * sinh(float(last) * du));
        } else {
            int i = int(t);
            float f = t - float(i);
            value = mix(table[base + i], table[base + i + 1], f);
        }
    }
    coef[at] = v < 0.0 ? -value : value;
}
