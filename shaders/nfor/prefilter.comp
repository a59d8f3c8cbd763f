#version 450
#extension GL_GOOGLE_include_directive : require

#include "nfor/prefilter.h"

layout(local_size_x = NFOR_LOCAL_SIZE) in;
layout(std430, binding = NFOR_PREFILTER_FEATURES) readonly buffer Features { float features[]; };
layout(std430, binding = NFOR_PREFILTER_VARIANCE) readonly buffer Variance { float variance[]; };
layout(std430, binding = NFOR_PREFILTER_OUT) writeonly buffer Out { float outputs[]; };

int w, h;

bool inside(int x, int y) {
    return x >= 0 && y >= 0 && x < w && y < h;
}

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y), j = int(gl_WorkGroupID.z);
    w = push.width;
    h = push.height;
    if (x >= w) return;
    int base = j * w * h, r = push.radius, f = push.patchRadius;
    float scale = 1.0 / (push.bandwidth * push.bandwidth);
    float sum = 0.0, weights = 0.0;
    for (int v = y - r; v <= y + r; ++v)
        for (int u = x - r; u <= x + r; ++u) {
            if (!inside(u, v)) continue;
            float distance = 0.0;
            int count = 0;
            for (int ty = -f; ty <= f; ++ty)
                for (int tx = -f; tx <= f; ++tx) {
                    int px = x + tx, py = y + ty, qx = u + tx, qy = v + ty;
                    if (!inside(px, py) || !inside(qx, qy)) continue;
                    float fp = features[base + py * w + px], fq = features[base + qy * w + qx];
                    float vp = variance[base + py * w + px], vq = variance[base + qy * w + qx];
                    float diff = fp - fq;
                    float term = (diff * diff - (vp + vq)) /
                                 (vp + vq + float(NFOR_REL_EPS) * (fp * fp + fq * fq) +
                                  float(NFOR_TINY));
                    distance += min(term, float(NFOR_TERM_MAX));
                    ++count;
                }
            float e = max(0.0, distance / float(count)) * scale;
            float wq = (u == x && v == y) ? 1.0 : (e > NFOR_EXP_CUT ? 0.0 : exp(-e));
            sum += wq * features[base + v * w + u];
            weights += wq;
        }
    outputs[base + y * w + x] = sum / weights;
}
