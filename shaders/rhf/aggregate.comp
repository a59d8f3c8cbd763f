#version 450
#extension GL_GOOGLE_include_directive : require

#include "rhf/aggregate.h"

// One invocation per pixel: x across, row from the grid. Colour is 3 planes.
// out(p) = 1/E sum_c 1/n_c sum_{o in S_c} u(p + o) over the E covering patches c with
// n_c selected candidates S_c, computed as 1/E sum_o u(p + o) sum_{c: o in S_c} 1/n_c:
// each candidate colour is read once, at the same offset on every lane (contiguous).
layout(local_size_x = RHF_AGGREGATE_LOCAL_SIZE) in;
layout(constant_id = RHF_AGGREGATE_SPEC_SEARCH_HALF) const int B = 6;
layout(constant_id = RHF_AGGREGATE_SPEC_PATCH_HALF) const int PW = 1;
const int SIDE = 2 * B + 1, OFFSETS = SIDE * SIDE, PS = 2 * PW + 1, CENTRES = PS * PS;
layout(binding = RHF_AGGREGATE_COLOR) uniform samplerBuffer color;
layout(std430, binding = RHF_AGGREGATE_MASK) readonly buffer Mask { uint mask[]; };
layout(std430, binding = RHF_AGGREGATE_OUT) writeonly buffer Out { float outColor[]; };

float inverse[CENTRES];
int centre[CENTRES];
uint bits[CENTRES];

vec3 ColorAt(int at, int plane) {
    return vec3(texelFetch(color, at).r, texelFetch(color, at + plane).r,
                texelFetch(color, at + 2 * plane).r);
}

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y);
    if (x >= push.width) return;
    int W = push.width, H = push.height, plane = W * H, at = y * W + x;
    // The patches centred at c = p - t that cover p (their shrunk half-size reaches t) and
    // select something: 1 / their selection size.
    int estimates = 0;
    for (int t = 0; t < CENTRES; ++t) {
        int tx = t % PS - PW, ty = t / PS - PW, cx = x - tx, cy = y - ty;
        inverse[t] = 0.0;
        centre[t] = 0;
        if (cx < 0 || cx >= W || cy < 0 || cy >= H) continue;
        int w0 = min(min(PW, min(cx, cy)), min(W - 1 - cx, H - 1 - cy));
        if (max(abs(tx), abs(ty)) > w0) continue;
        centre[t] = cy * W + cx;
        int selected = 0;
        for (int word = 0; word < push.words; ++word)
            selected += bitCount(mask[word * plane + centre[t]]);
        if (selected > 0) {
            inverse[t] = 1.0 / float(selected);
            ++estimates;
        }
    }
    vec3 total = vec3(0.0);
    if (estimates > 0) {
        for (int word = 0; word < push.words; ++word) {
            for (int t = 0; t < CENTRES; ++t)
                bits[t] = inverse[t] != 0.0 ? mask[word * plane + centre[t]] : 0u;
            for (int bit = 0; bit < 32; ++bit) {
                int o = word * 32 + bit;
                if (o >= OFFSETS) break;
                float weight = 0.0;
                for (int t = 0; t < CENTRES; ++t)
                    if ((bits[t] & (1u << bit)) != 0u) weight += inverse[t];
                if (weight == 0.0) continue;
                int qx = x + o % SIDE - B, qy = y + o / SIDE - B;
                total += weight * ColorAt(qy * W + qx, plane);
            }
        }
    }
    vec3 v = estimates > 0 ? total / float(estimates) : ColorAt(at, plane);
    outColor[at] = v.x;
    outColor[at + plane] = v.y;
    outColor[at + 2 * plane] = v.z;
}
