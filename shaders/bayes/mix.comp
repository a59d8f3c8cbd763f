#version 450
#extension GL_GOOGLE_include_directive : require

#include "bayes/mix.h"

// One invocation per pixel: x across, row y from the grid.
layout(local_size_x = BAYES_MIX_LOCAL_SIZE) in;
layout(std430, binding = BAYES_MIX_IMAGE) buffer Image { float image[]; };

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y);
    if (x >= push.width) return;
    int plane = push.width * push.height, at = y * push.width + x;
    vec3 v = vec3(image[at], image[at + plane], image[at + 2 * plane]);
    for (int i = 0; i < 3; ++i)
        image[at + i * plane] = push.m[3 * i] * v.x + push.m[3 * i + 1] * v.y + push.m[3 * i + 2] * v.z;
}
