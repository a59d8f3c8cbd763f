#version 450
#extension GL_GOOGLE_include_directive : require

#include "bayes/log.h"

// One invocation per pixel: x across, row y and channel from the grid.
layout(local_size_x = BAYES_LOG_LOCAL_SIZE) in;
layout(std430, binding = BAYES_LOG_COLOR) readonly buffer Color { float color[]; };
layout(std430, binding = BAYES_LOG_FLOORS) readonly buffer Floors { float floors[]; };
layout(std430, binding = BAYES_LOG_OUT) writeonly buffer Out { float outLog[]; };

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y), c = int(gl_WorkGroupID.z);
    if (x >= push.width) return;
    int at = (c * push.height + y) * push.width + x;
    float v = color[at], floorValue = floors[c];
    // Exponent bits all ones: NaN or Inf (a bit test survives fast-math compilers).
    bool finite = (floatBitsToUint(v) & 0x7f800000u) != 0x7f800000u;
    outLog[at] = log(finite && v > floorValue ? v : floorValue);
}
