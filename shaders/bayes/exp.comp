#version 450
#extension GL_GOOGLE_include_directive : require

#include "bayes/exp.h"

layout(local_size_x = BAYES_EXP_LOCAL_SIZE) in;
layout(std430, binding = BAYES_EXP_LOG) readonly buffer LogImage { float logImage[]; };
layout(std430, binding = BAYES_EXP_ORIGINAL) readonly buffer Original { float original[]; };
layout(std430, binding = BAYES_EXP_OUT) writeonly buffer Out { float outColor[]; };

// Whether channel c of the pixel at (x, y), clamped to the frame, is black: not finite
// positive. Per channel, so that the zero channels of a primary colour stay 0.
bool BlackAt(int x, int y, int c) {
    x = clamp(x, 0, push.width - 1), y = clamp(y, 0, push.height - 1);
    float v = original[(c * push.height + y) * push.width + x];
    return !((floatBitsToUint(v) & 0x7f800000u) != 0x7f800000u && v > 0.0);
}

// Whether both neighbours of (x, y) along one of the four lines through it are black in
// channel c: a zero inside a black region or on a black line stays black; a lone zero among
// lit pixels is a sample that missed the light, and is denoised.
bool OnBlack(int x, int y, int c) {
    const ivec2 lines[4] = ivec2[4](ivec2(1, 0), ivec2(0, 1), ivec2(1, 1), ivec2(1, -1));
    for (int i = 0; i < 4; ++i)
        if (BlackAt(x + lines[i].x, y + lines[i].y, c) &&
            BlackAt(x - lines[i].x, y - lines[i].y, c))
            return true;
    return false;
}

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y), c = int(gl_WorkGroupID.z);
    if (x >= push.width) return;
    int at = (c * push.height + y) * push.width + x;
    float v = original[at];
    bool finite = (floatBitsToUint(v) & 0x7f800000u) != 0x7f800000u;
    bool restored = push.restoreZeros != 0 && v == 0.0 && OnBlack(x, y, c);
    bool keep = finite && (v > 0.0 || (v == 0.0 && !restored));
    outColor[at] = keep ? exp(clamp(logImage[at], -87.0, 88.0)) : 0.0;
}
