#version 450
#extension GL_GOOGLE_include_directive : require

// The shrinkage of the stationary wavelet bands, in place: workgroup layer z is detail
// band z (its plane z + channel); every coefficient y through the band's table at |y|
// (linear in u = asinh(|y| / b)), with y's sign; past the last entry slope 1 (as
// shrink.comp). NO_NOISE and EMPTY bands are left alone; so is the low plane. A lane takes
// 4 neighbours along a row, as one vec4 when rows are whole vec4s (lavapipe loads storage
// buffers lane by lane, so 4 floats per load matter); the table is read through its texel
// view (gathered as vectors).

#include "bayes/bayes.h"
#include "bayes/swt_shrink.h"

layout(local_size_x = BAYES_SWT_SHRINK_LOCAL_SIZE) in;
layout(std430, binding = BAYES_SWT_SHRINK_COEF) buffer Coef { float coef[]; };
layout(std430, binding = BAYES_SWT_SHRINK_COEF) buffer Coef4 { vec4 coef4[]; };
layout(std430, binding = BAYES_SWT_SHRINK_PARAMS) readonly buffer Params { float params[]; };
layout(binding = BAYES_SWT_SHRINK_TABLE) uniform samplerBuffer table;

float Shrink(float v, float b, float du, int base) {
    float a = abs(v), value = 0.0;
    if (du > 0.0) {
        float t = asinh(a / b) / du;
        const int last = BAYES_TABLE_SIZE - 1;
        if (t >= float(last)) {
            value = texelFetch(table, base + last).r + (a - b * sinh(float(last) * du));
        } else {
            int i = int(t);
            float f = t - float(i);
            value = mix(texelFetch(table, base + i).r, texelFetch(table, base + i + 1).r, f);
        }
    }
    return v < 0.0 ? -value : value;
}

void main() {
    int x = 4 * int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y);
    int band = int(gl_WorkGroupID.z);
    if (x >= push.width) return;
    int fit = int(params[band * BAYES_PARAM_STRIDE + 4]);
    if (fit == BAYES_FIT_NO_NOISE || fit == BAYES_FIT_EMPTY) return;
    int channel = band / (3 * push.levels);
    int at = ((band + channel) * push.height + y) * push.width + x;
    float b = params[band * BAYES_PARAM_STRIDE + 6], du = params[band * BAYES_PARAM_STRIDE + 7];
    int base = band * BAYES_TABLE_SIZE;
    if ((push.width & 3) == 0) {
        vec4 v = coef4[at >> 2];
        coef4[at >> 2] = vec4(Shrink(v.x, b, du, base), Shrink(v.y, b, du, base),
                              Shrink(v.z, b, du, base), Shrink(v.w, b, du, base));
    } else {
        for (int k = 0; k < 4 && x + k < push.width; ++k)
            coef[at + k] = Shrink(coef[at + k], b, du, base);
    }
}
