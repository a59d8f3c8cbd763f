#version 450
#extension GL_GOOGLE_include_directive : require

#include "nfor/glint.h"

layout(local_size_x = NFOR_LOCAL_SIZE) in;
layout(std430, binding = NFOR_GLINT_ROWS_ALBEDO) readonly buffer Albedo { float albedo[]; };
layout(std430, binding = NFOR_GLINT_ROWS_NEAR) writeonly buffer Near { float near[]; };

// Whether (x, y) is a glint: some albedo channel above the gate (a NaN compares false).
bool Glint(int x, int y) {
    for (int c = 0; c < push.albedoChannels; ++c)
        if (albedo[(c * push.height + y) * push.width + x] > push.gate) return true;
    return false;
}

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y);
    if (x >= push.width) return;
    // The row's pixels within reach, inside the frame.
    bool any = false;
    int u1 = min(x + push.reach, push.width - 1);
    for (int u = max(x - push.reach, 0); u <= u1 && !any; ++u) any = Glint(u, y);
    near[y * push.width + x] = any ? 1.0 : 0.0;
}
