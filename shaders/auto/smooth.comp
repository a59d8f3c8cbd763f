#version 450
#extension GL_GOOGLE_include_directive : require

#include "auto/smooth.h"

layout(local_size_x = AUTO_LOCAL_SIZE) in;
layout(constant_id = AUTO_SMOOTH_SPEC_PASS) const int PASS = AUTO_SMOOTH_PASS_ROWS;
layout(std430, binding = AUTO_SMOOTH_INPUT) readonly buffer Input { float inputs[]; };
layout(std430, binding = AUTO_SMOOTH_SCRATCH) buffer Scratch { float scratch[]; };
layout(std430, binding = AUTO_SMOOTH_OUTPUT) writeonly buffer Output { float outputs[]; };

// Rows: the tent-weighted sum of the finite values of row y over [x - r, x + r] and the
// sum of their weights r + 1 - |u - x|, into planes 2p and 2p + 1 of the scratch.
void rows(int x, int y, int p, int w, int h, int r) {
    int base = p * w * h + y * w;
    float sum = 0.0, n = 0.0;
    for (int u = max(0, x - r); u <= min(w - 1, x + r); ++u) {
        float e = inputs[base + u];
        if (isnan(e) || isinf(e)) continue;
        float weight = float(r + 1 - abs(u - x));
        sum += weight * e;
        n += weight;
    }
    int at = y * w + x;
    scratch[2 * p * w * h + at] = sum;
    scratch[(2 * p + 1) * w * h + at] = n;
}

// Columns: the row sums and weights over [y - r, y + r], each weighted by r + 1 - |v - y|,
// and their quotient (NaN where the window has no finite value).
void columns(int x, int y, int p, int w, int h, int r) {
    int sums = 2 * p * w * h, counts = (2 * p + 1) * w * h;
    float sum = 0.0, n = 0.0;
    for (int v = max(0, y - r); v <= min(h - 1, y + r); ++v) {
        float weight = float(r + 1 - abs(v - y));
        sum += weight * scratch[sums + v * w + x];
        n += weight * scratch[counts + v * w + x];
    }
    outputs[p * w * h + y * w + x] = n > 0.0 ? sum / n : uintBitsToFloat(0x7fc00000u);
}

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y), p = int(gl_WorkGroupID.z);
    int w = push.width, h = push.height, r = push.radius;
    if (x >= w) return;
    if (PASS == AUTO_SMOOTH_PASS_ROWS)
        rows(x, y, p, w, h, r);
    else
        columns(x, y, p, w, h, r);
}
