#version 450
#extension GL_GOOGLE_include_directive : require

#include "bayes/log.h"

// One invocation per pixel: x across, row y and channel from the grid.
layout(local_size_x = BAYES_LOG_LOCAL_SIZE) in;
layout(std430, binding = BAYES_LOG_COLOR) readonly buffer Color { float color[]; };
layout(std430, binding = BAYES_LOG_FLOORS) readonly buffer Floors { float floors[]; };
layout(std430, binding = BAYES_LOG_OUT) writeonly buffer Out { float outLog[]; };

// Exponent bits all ones: NaN or Inf (a bit test survives fast-math compilers).
bool Finite(float v) {
    return (floatBitsToUint(v) & 0x7f800000u) != 0x7f800000u;
}

// Whether the pixel at (x, y), clamped to the frame, is dark: no channel finite and above its
// floor.
bool DarkAt(int x, int y) {
    x = clamp(x, 0, push.width - 1), y = clamp(y, 0, push.height - 1);
    for (int c = 0; c < int(gl_NumWorkGroups.z); ++c) {
        float v = color[(c * push.height + y) * push.width + x];
        if (Finite(v) && v > floors[c]) return false;
    }
    return true;
}

// Whether both neighbour pixels of (x, y) along a row, column or diagonal are dark.
bool OnDark(int x, int y) {
    const ivec2 lines[4] = ivec2[4](ivec2(1, 0), ivec2(0, 1), ivec2(1, 1), ivec2(1, -1));
    for (int i = 0; i < 4; ++i)
        if (DarkAt(x + lines[i].x, y + lines[i].y) && DarkAt(x - lines[i].x, y - lines[i].y))
            return true;
    return false;
}

// A dark pixel lone among lit pixels is a sample that missed the light: the mean log of its
// in-frame 3x3 neighbour pixels that are not dark (each value at least the floor; the same
// pixels for every channel, so that the colour is theirs) stands in for each channel in
// [0, floor], the floor when none is.
float MissedSampleLog(int x, int y, int c, float floorValue) {
    float sum = 0.0;
    int count = 0;
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
            int nx = x + dx, ny = y + dy;
            if ((dx == 0 && dy == 0) || nx < 0 || ny < 0 || nx >= push.width ||
                ny >= push.height)
                continue;
            if (DarkAt(nx, ny)) continue;
            float n = color[(c * push.height + ny) * push.width + nx];
            sum += log(Finite(n) && n > floorValue ? n : floorValue), ++count;
        }
    return count > 0 ? sum / float(count) : log(floorValue);
}

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y), c = int(gl_WorkGroupID.z);
    if (x >= push.width) return;
    int at = (c * push.height + y) * push.width + x;
    float v = color[at], floorValue = floors[c];
    if (push.fillMissed != 0 && Finite(v) && v >= 0.0 && DarkAt(x, y) && !OnDark(x, y))
        outLog[at] = MissedSampleLog(x, y, c, floorValue);
    else
        outLog[at] = log(Finite(v) && v > floorValue ? v : floorValue);
}
