#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "nfor/trust.h"

layout(local_size_x = NFOR_LOCAL_SIZE) in;
layout(constant_id = NFOR_SPEC_CHANNELS) const int channels = 3;
layout(std430, binding = NFOR_TRUST_COLOR) readonly buffer Color { float color[]; };
layout(std430, binding = NFOR_TRUST_ALBEDO) readonly buffer Albedo { float albedo[]; };
layout(std430, binding = NFOR_TRUST_OUT) writeonly buffer Out { float trust[]; };

// The albedo of colour channel c at (x, y), at least the floor (NaN too: max's NaN is
// undefined, a comparison's false).
float AlbedoAt(int c, int x, int y) {
    float a = albedo[(min(c, push.albedoChannels - 1) * push.height + y) * push.width + x];
    return a > float(NFOR_NOISE_ALBEDO_FLOOR) ? a : float(NFOR_NOISE_ALBEDO_FLOOR);
}

float ColorAt(int c, int x, int y) {
    return color[(c * push.height + y) * push.width + x];
}

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y);
    int w = push.width, h = push.height;
    if (x >= w) return;
    int x0 = max(x - 1, 0), x1 = min(x + 1, w - 1), y0 = max(y - 1, 0), y1 = min(y + 1, h - 1);
    float n = float((x1 - x0 + 1) * (y1 - y0 + 1));
    // The window's means of the albedo, the colour and colour / albedo.
    vec4 meanA = vec4(0.0), meanC = vec4(0.0), meanZ = vec4(0.0);
    for (int v = y0; v <= y1; ++v)
        for (int u = x0; u <= x1; ++u)
            [[unroll]] for (int c = 0; c < channels; ++c) {
                float a = AlbedoAt(c, u, v), value = ColorAt(c, u, v);
                meanA[c] += a;
                meanC[c] += value;
                meanZ[c] += value / a;
            }
    meanA /= n;
    meanC /= n;
    meanZ /= n;
    // The squared deviations from those means.
    vec4 varA = vec4(0.0), varC = vec4(0.0), varZ = vec4(0.0);
    for (int v = y0; v <= y1; ++v)
        for (int u = x0; u <= x1; ++u)
            [[unroll]] for (int c = 0; c < channels; ++c) {
                float a = AlbedoAt(c, u, v), value = ColorAt(c, u, v);
                float da = a - meanA[c], dc = value - meanC[c], dz = value / a - meanZ[c];
                varA[c] += da * da;
                varC[c] += dc * dc;
                varZ[c] += dz * dz;
            }
    float roughA = 0.0, roughC = 0.0, roughZ = 0.0, squareA = 0.0, squareC = 0.0,
          squareZ = 0.0;
    [[unroll]] for (int c = 0; c < channels; ++c) {
        roughA += varA[c] / n;
        roughC += varC[c] / n;
        roughZ += varZ[c] / n;
        squareA += meanA[c] * meanA[c];
        squareC += meanC[c] * meanC[c];
        squareZ += meanZ[c] * meanZ[c];
    }
    bool rough = roughA > push.noise * squareA;
    bool roughens = roughZ * squareC > (1.0 + float(NFOR_TRUST_TIE)) * roughC * squareZ;
    trust[y * w + x] = rough && roughens ? 0.0 : 1.0;
}
