#version 450
#extension GL_GOOGLE_include_directive : require

#include "auto/guided.h"

layout(local_size_x = AUTO_LOCAL_SIZE) in;
layout(std430, binding = AUTO_GUIDED_INPUT) readonly buffer Input {
    float inputs[];
};
layout(std430, binding = AUTO_GUIDED_GUIDE) readonly buffer Guide {
    float guide[];
};
layout(std430, binding = AUTO_GUIDED_OUTPUT) writeonly buffer Output {
    float outputs[];
};

// The guide's relative colour distance between the centre's colour and pixel `near` (a
// flat index).
float Distance(float centre[AUTO_GUIDED_MAX_GUIDE_CHANNELS], int near, int n) {
    float sum = 0.0;
    for (int c = 0; c < push.guideChannels; ++c) {
        float a = centre[c], b = guide[c * n + near];
        float d = (a - b) * (a - b) / (a * a + b * b + float(AUTO_REL_OFFSET));
        if (!isnan(d) && !isinf(d)) sum += d;
    }
    return sum / float(push.guideChannels);
}

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y);
    int w = push.width, h = push.height, r = push.radius, n = w * h;
    if (x >= w) return;
    float sum[AUTO_GUIDED_MAX_PLANES], count[AUTO_GUIDED_MAX_PLANES];
    for (int p = 0; p < push.planes; ++p) sum[p] = count[p] = 0.0;
    int at = y * w + x;
    // The centre's colour, read once for the whole window.
    float centre[AUTO_GUIDED_MAX_GUIDE_CHANNELS];
    for (int c = 0; c < push.guideChannels; ++c) centre[c] = guide[c * n + at];
    for (int v = max(0, y - r); v <= min(h - 1, y + r); ++v)
        for (int u = max(0, x - r); u <= min(w - 1, x + r); ++u) {
            int near = v * w + u;
            // The colour's factor is at least exp(-AUTO_GUIDED_MAX_EXPONENT): neither the
            // weight nor its product with an estimate flushes to 0, so a window is empty
            // only where its values are not finite.
            float exponent = min(Distance(centre, near, n) * push.inverseBandwidth2,
                                 float(AUTO_GUIDED_MAX_EXPONENT));
            float weight =
                float(r + 1 - abs(u - x)) * float(r + 1 - abs(v - y)) * exp(-exponent);
            for (int p = 0; p < push.planes; ++p) {
                float e = inputs[p * n + near];
                if (isnan(e) || isinf(e)) continue;
                sum[p] += weight * e;
                count[p] += weight;
            }
        }
    for (int p = 0; p < push.planes; ++p)
        outputs[p * n + at] = count[p] > 0.0 ? sum[p] / count[p] : uintBitsToFloat(0x7fc00000u);
}
