#version 450
#extension GL_GOOGLE_include_directive : require

#include "bayes/moments.h"
#include "bayes/model.glsl"

layout(local_size_x = BAYES_MOMENTS_LOCAL_SIZE) in;
layout(std430, binding = BAYES_MOMENTS_COEF) readonly buffer Coef { float coef[]; };
layout(std430, binding = BAYES_MOMENTS_OUT) writeonly buffer Moments { float moments[]; };

shared float sum2[BAYES_MOMENTS_LOCAL_SIZE], sum4[BAYES_MOMENTS_LOCAL_SIZE],
    maxAbs[BAYES_MOMENTS_LOCAL_SIZE];

void main() {
    int band = int(gl_WorkGroupID.x), lane = int(gl_LocalInvocationID.x);
    int channel = band / (3 * push.levels), inChannel = band % (3 * push.levels);
    ivec4 r = BayesBandRect(push.width, push.height, inChannel / 3, inChannel % 3);
    int bandWidth = r.z - r.x, count = bandWidth * (r.w - r.y);
    float s2 = 0.0, s4 = 0.0, m = 0.0;
    for (int i = lane; i < count; i += BAYES_MOMENTS_LOCAL_SIZE) {
        int x = r.x + i % bandWidth, y = r.y + i / bandWidth;
        float v = coef[(channel * push.height + y) * push.width + x];
        float v2 = v * v;
        s2 += v2;
        s4 += v2 * v2;
        m = max(m, abs(v));
    }
    sum2[lane] = s2;
    sum4[lane] = s4;
    maxAbs[lane] = m;
    barrier();
    for (int half_ = BAYES_MOMENTS_LOCAL_SIZE / 2; half_ > 0; half_ /= 2) {
        if (lane < half_) {
            sum2[lane] += sum2[lane + half_];
            sum4[lane] += sum4[lane + half_];
            maxAbs[lane] = max(maxAbs[lane], maxAbs[lane + half_]);
        }
        barrier();
    }
    if (lane == 0) {
        float n = float(count);
        int at = band * BAYES_MOMENT_STRIDE;
        moments[at + 0] = count > 0 ? sum2[0] / n : 0.0;
        moments[at + 1] = count > 0 ? sum4[0] / n : 0.0;
        moments[at + 2] = maxAbs[0];
        moments[at + 3] = n;
    }
}
