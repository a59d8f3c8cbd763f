#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "rhf/blockmax.h"

// One invocation per (block, row, plane): block across, row and plane from the grid.
layout(local_size_x = RHF_BLOCKMAX_LOCAL_SIZE) in;
layout(binding = RHF_BLOCKMAX_HIST) uniform samplerBuffer hist;
layout(binding = RHF_BLOCKMAX_COUNT) uniform samplerBuffer counts;
layout(std430, binding = RHF_BLOCKMAX_OUT) writeonly buffer BlockMax { float blockMax[]; };

const int BLOCK = RHF_BLOCKMAX_WIDTH;

void main() {
    int block = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y),
        plane = int(gl_WorkGroupID.z);
    int blocks = (push.width + BLOCK - 1) / BLOCK;
    if (block >= blocks) return;
    int pixels = push.width * push.height, row = y * push.width;
    float largest = -3.40282347e38;
    [[unroll]] for (int j = 0; j < BLOCK; ++j) {
        // Past the image's right edge: the last pixel again (its value is in the block).
        int x = min(block * BLOCK + j, push.width - 1);
        float n = texelFetch(counts, push.countAt * pixels + row + x).r * push.histScale;
        float h = texelFetch(hist, plane * pixels + row + x).r * push.histScale;
        largest = max(largest, n != 0.0 ? h : -3.40282347e38);
    }
    blockMax[((push.firstPlane + plane) * push.height + y) * blocks + block] = largest;
}
