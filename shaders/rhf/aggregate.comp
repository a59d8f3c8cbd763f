#version 450
#extension GL_GOOGLE_include_directive : require

#include "rhf/aggregate.h"

// One invocation per pixel: x across, row from the grid. Colour is 3 planes.
layout(local_size_x = RHF_AGGREGATE_LOCAL_SIZE) in;
layout(std430, binding = RHF_AGGREGATE_COLOR) readonly buffer Color { float color[]; };
layout(std430, binding = RHF_AGGREGATE_MASK) readonly buffer Mask { uint mask[]; };
layout(std430, binding = RHF_AGGREGATE_OUT) writeonly buffer Out { float outColor[]; };

vec3 ColorAt(int at, int plane) {
    return vec3(color[at], color[at + plane], color[at + 2 * plane]);
}

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y);
    if (x >= push.width) return;
    int W = push.width, H = push.height, plane = W * H, at = y * W + x;
    int side = 2 * push.searchHalf + 1;
    vec3 total = vec3(0.0);
    int estimates = 0;
    for (int ty = -push.patchHalf; ty <= push.patchHalf; ++ty)
        for (int tx = -push.patchHalf; tx <= push.patchHalf; ++tx) {
            // The patch centred at c = p - t covers p if its shrunk half-size reaches t.
            int cx = x - tx, cy = y - ty;
            if (cx < 0 || cx >= W || cy < 0 || cy >= H) continue;
            int w0 = min(min(push.patchHalf, min(cx, cy)), min(W - 1 - cx, H - 1 - cy));
            if (max(abs(tx), abs(ty)) > w0) continue;
            vec3 sum = vec3(0.0);
            int selected = 0;
            for (int word = 0; word < push.words; ++word) {
                uint bits = mask[(word * H + cy) * W + cx];
                selected += bitCount(bits);
                // The same offset on every lane: the candidates' reads are contiguous.
                int first = word * 32, last = min(first + 32, side * side);
                for (int o = first; o < last; ++o) {
                    if ((bits & (1u << (o - first))) == 0u) continue;
                    // Candidate c + o, at this pixel's place in the patch: p + o.
                    int qx = x + o % side - push.searchHalf, qy = y + o / side - push.searchHalf;
                    sum += ColorAt(qy * W + qx, plane);
                }
            }
            if (selected > 0) {
                total += sum / float(selected);
                ++estimates;
            }
        }
    vec3 v = estimates > 0 ? total / float(estimates) : ColorAt(at, plane);
    outColor[at] = v.x;
    outColor[at + plane] = v.y;
    outColor[at + 2 * plane] = v.z;
}
