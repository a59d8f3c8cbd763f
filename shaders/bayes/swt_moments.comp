#version 450
#extension GL_GOOGLE_include_directive : require

// Per-band moments of the stationary wavelet bands: one workgroup per band, lane l sums
// elements l, l + LOCAL, ... of the band's plane in float, then a fixed tree in shared
// memory (deterministic, no atomics). Writes E[y^2], E[y^4], max |y|, count (bayes.h).

#include "bayes/bayes.h"
#include "bayes/swt_moments.h"

layout(local_size_x = BAYES_SWT_MOMENTS_LOCAL_SIZE) in;
layout(binding = BAYES_SWT_MOMENTS_COEF) uniform samplerBuffer coef;
layout(std430, binding = BAYES_SWT_MOMENTS_OUT) writeonly buffer Moments { float moments[]; };

shared float sum2[BAYES_SWT_MOMENTS_LOCAL_SIZE], sum4[BAYES_SWT_MOMENTS_LOCAL_SIZE],
    maxAbs[BAYES_SWT_MOMENTS_LOCAL_SIZE];

void main() {
    int band = int(gl_WorkGroupID.x), lane = int(gl_LocalInvocationID.x);
    int perChannel = 3 * push.levels, channel = band / perChannel;
    int count = BayesSwtBandUsed(band % perChannel) ? push.width * push.height : 0;
    int base = (band + channel) * push.width * push.height;
    float s2 = 0.0, s4 = 0.0, m = 0.0;
    for (int i = lane; i < count; i += BAYES_SWT_MOMENTS_LOCAL_SIZE) {
        float v = texelFetch(coef, base + i).r;
        float v2 = v * v;
        s2 += v2;
        s4 += v2 * v2;
        m = max(m, abs(v));
    }
    sum2[lane] = s2;
    sum4[lane] = s4;
    maxAbs[lane] = m;
    barrier();
    for (int half_ = BAYES_SWT_MOMENTS_LOCAL_SIZE / 2; half_ > 0; half_ /= 2) {
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
