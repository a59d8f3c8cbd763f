#version 450
#extension GL_GOOGLE_include_directive : require

// The shrinkage of the stationary wavelet bands, in place: workgroup layer z is detail
// band z (its plane z + channel), every coefficient y through the band's table at |y|
// (linear in u = asinh(|y| / b)), with y's sign; past the last entry slope 1 (as
// shrink.comp). NO_NOISE and EMPTY bands are left alone; so is the low plane.

#include "bayes/bayes.h"
#include "bayes/swt.h"

layout(local_size_x = BAYES_SWT_SHRINK_LOCAL_SIZE) in;
layout(std430, binding = BAYES_SWT_COEF) buffer Coef { float coef[]; };
layout(std430, binding = BAYES_SWT_PARAMS) readonly buffer Params { float params[]; };
layout(std430, binding = BAYES_SWT_TABLE) readonly buffer Table { float table[]; };

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y), band = int(gl_WorkGroupID.z);
    if (x >= push.width) return;
    int fit = int(params[band * BAYES_PARAM_STRIDE + 4]);
    if (fit == BAYES_FIT_NO_NOISE || fit == BAYES_FIT_EMPTY) return;
    int channel = band / (3 * push.levels);
    int at = ((band + channel) * push.height + y) * push.width + x;
    float v = coef[at];
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
