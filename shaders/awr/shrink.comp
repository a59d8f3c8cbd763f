#version 450
#extension GL_GOOGLE_include_directive : require

#include "awr/shrink.h"

// One invocation per coefficient: x across, row y and channel from the grid.
layout(local_size_x = AWR_SHRINK_LOCAL_SIZE) in;
layout(std430, binding = AWR_SHRINK_COEF) buffer Coef { float coef[]; };
layout(std430, binding = AWR_SHRINK_VARIANCE) readonly buffer Variance { float variance[]; };

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y), c = int(gl_WorkGroupID.z);
    if (x >= push.width || (x < push.lowWidth && y < push.lowHeight)) return;
    int at = (c * push.height + y) * push.width + x;
    float w = coef[at];
    float threshold = push.cs * sqrt(variance[at]);
    coef[at] = sign(w) * max(abs(w) - threshold, 0.0);
}
