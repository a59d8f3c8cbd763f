#version 450
#extension GL_GOOGLE_include_directive : require

#include "bayes/exp.h"

layout(local_size_x = BAYES_EXP_LOCAL_SIZE) in;
layout(std430, binding = BAYES_EXP_LOG) readonly buffer LogImage { float logImage[]; };
layout(std430, binding = BAYES_EXP_ORIGINAL) readonly buffer Original { float original[]; };
layout(std430, binding = BAYES_EXP_OUT) writeonly buffer Out { float outColor[]; };

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y), c = int(gl_WorkGroupID.z);
    if (x >= push.width) return;
    int at = (c * push.height + y) * push.width + x;
    float v = original[at];
    bool finite = (floatBitsToUint(v) & 0x7f800000u) != 0x7f800000u;
    bool keep = finite && (v > 0.0 || (push.restoreZeros == 0 && v == 0.0));
    outColor[at] = keep ? exp(clamp(logImage[at], -87.0, 88.0)) : 0.0;
}
