#version 450
#extension GL_GOOGLE_include_directive : require

#include "auto/noise.h"

layout(local_size_x = AUTO_LOCAL_SIZE) in;
layout(std430, binding = AUTO_NOISE_COLOR) readonly buffer Color { float color[]; };
layout(std430, binding = AUTO_NOISE_ALBEDO) readonly buffer Albedo { float albedo[]; };
layout(std430, binding = AUTO_NOISE_OUTPUT) writeonly buffer Output { float outputs[]; };

int w, h, c;

bool finite(float v) {
    return !(isnan(v) || isinf(v));
}

// Whether (x, y) is divided by its albedo (above the floor and finite).
bool dividedAt(int x, int y) {
    if (push.albedoChannels == 0) return false;
    int ac = min(c, push.albedoChannels - 1);
    float a = albedo[(ac * h + y) * w + x];
    return a > float(AUTO_NOISE_ALBEDO_FLOOR) && finite(a);
}

// The divisor at (x, y): the albedo where it is above the floor, else 1.
float scaleAt(int x, int y) {
    if (!dividedAt(x, y)) return 1.0;
    return albedo[(min(c, push.albedoChannels - 1) * h + y) * w + x];
}

float zAt(int x, int y) {
    return color[(c * h + y) * w + x] / scaleAt(x, y);
}

// The smallest squared second difference over the 4 directions at (u, v), over 1.5 and
// over its mean for unit Gaussian noise: all 4 fit inside the frame, or 1 on its border
// rows and columns (its mean 1); NaN where none fits (corners, 1x1).
float minSquared(int u, int v) {
    const ivec2 dirs[4] = ivec2[4](ivec2(1, 0), ivec2(0, 1), ivec2(1, 1), ivec2(1, -1));
    float best = uintBitsToFloat(0x7fc00000u);
    float z = zAt(u, v);
    int fits = 0;
    for (int d = 0; d < 4; ++d) {
        int u0 = u - dirs[d].x, v0 = v - dirs[d].y, u1 = u + dirs[d].x, v1 = v + dirs[d].y;
        if (u0 < 0 || u1 >= w || min(v0, v1) < 0 || max(v0, v1) >= h) continue;
        ++fits;
        float r = z - 0.5 * (zAt(u0, v0) + zAt(u1, v1));
        float q = r * r / 1.5;
        // NaN never wins, and the first finite one replaces the NaN start.
        if (isnan(best) || q < best) best = q;
    }
    return fits == 4 ? best / float(AUTO_NOISE_MIN_MEAN) : best;
}

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y);
    w = push.width;
    h = push.height;
    c = int(gl_WorkGroupID.z);
    if (x >= w) return;
    int r = push.radius;
    float s = scaleAt(x, y);
    bool divided = dividedAt(x, y);
    float ratio = float(AUTO_NOISE_DIVISOR_RATIO);
    float sum = 0.0;
    int count = 0;
    // Rows, then columns within a row: the reference sums in the same order. Only the
    // neighbours demodulated like this pixel: their values are in their own z's units.
    for (int v = max(0, y - r); v <= min(h - 1, y + r); ++v)
        for (int u = max(0, x - r); u <= min(w - 1, x + r); ++u) {
            if (dividedAt(u, v) != divided) continue;
            float su = scaleAt(u, v);
            if (su > s * ratio || su * ratio < s) continue;
            float q = minSquared(u, v);
            if (!finite(q)) continue;
            sum += q;
            ++count;
        }
    outputs[(c * h + y) * w + x] =
        count > 0 ? sum / float(count) * s * s : 0.0;
}
