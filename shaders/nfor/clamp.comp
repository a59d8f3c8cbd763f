#version 450
#extension GL_GOOGLE_include_directive : require

#include "nfor/clamp.h"

layout(local_size_x = NFOR_LOCAL_SIZE) in;
layout(std430, binding = NFOR_CLAMP_COLOR) readonly buffer Color { float color[]; };
layout(std430, binding = NFOR_CLAMP_VARIANCE) readonly buffer Variance { float variance[]; };
layout(std430, binding = NFOR_CLAMP_ALBEDO) readonly buffer Albedo { float albedo[]; };
layout(std430, binding = NFOR_CLAMP_OUT) writeonly buffer Out { float outColor[]; };
layout(std430, binding = NFOR_CLAMP_MASK) writeonly buffer Mask { float mask[]; };

int w, h, c;

bool emitterAt(int x, int y) {
    float most = 0.0;
    for (int k = 0; k < push.albedoChannels; ++k) most = max(most, albedo[(k * h + y) * w + x]);
    return most > push.emitterAlbedo;
}

float divisorAt(int x, int y) {
    if (push.albedoChannels == 0) return 1.0;
    float a = albedo[(min(c, push.albedoChannels - 1) * h + y) * w + x];
    return a > float(NFOR_NOISE_ALBEDO_FLOOR) ? a : 1.0;
}

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y);
    w = push.width;
    h = push.height;
    c = int(gl_WorkGroupID.z);
    if (x >= w) return;
    int at = (c * h + y) * w + x;
    float value = color[at];
    bool emitter = emitterAt(x, y);
    if (c == 0) mask[y * w + x] = emitter ? 0.0 : 1.0;
    outColor[at] = value;
    if (emitter || push.threshold <= 0.0) return;
    // The neighbours' z, sorted as they come.
    float z[8];
    int n = 0;
    for (int v = y - 1; v <= y + 1; ++v)
        for (int u = x - 1; u <= x + 1; ++u) {
            if ((u == x && v == y) || u < 0 || v < 0 || u >= w || v >= h || emitterAt(u, v))
                continue;
            float zq = color[(c * h + v) * w + u] / divisorAt(u, v);
            int i = n++;
            while (i > 0 && z[i - 1] > zq) {
                z[i] = z[i - 1];
                --i;
            }
            z[i] = zq;
        }
    if (n == 0) return;
    float a = divisorAt(x, y);
    float limit = z[(n - 1) / 2] + push.threshold * sqrt(variance[at]) / a;
    if (value / a > limit) outColor[at] = limit * a;
}
