#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "nfor/prefilter.h"

layout(local_size_x = NFOR_LOCAL_SIZE) in;
layout(binding = NFOR_PREFILTER_FEATURES) uniform samplerBuffer features;
layout(binding = NFOR_PREFILTER_VARIANCE) uniform samplerBuffer variance;
layout(std430, binding = NFOR_PREFILTER_OUT) writeonly buffer Out { float outputs[]; };

int w, h;

bool inside(int x, int y) {
    return x >= 0 && y >= 0 && x < w && y < h;
}

// The weighted mean at radius 1 with 3x3 patches (the default), unrolled: the features and
// variances of the 5x5 pixels the patches read loaded once into registers, the terms added
// in the loop's order.
float prefilter1(int x, int y, int base, float scale) {
    float fs[25], vs[25];
    bool ins[25];
    [[unroll]] for (int j = 0; j < 5; ++j)
        [[unroll]] for (int i = 0; i < 5; ++i) {
            int u = x - 2 + i, v = y - 2 + j, k = j * 5 + i;
            ins[k] = inside(u, v);
            fs[k] = 0.0;
            vs[k] = 0.0;
            if (ins[k]) {
                fs[k] = texelFetch(features, base + v * w + u).x;
                vs[k] = texelFetch(variance, base + v * w + u).x;
            }
        }
    float sum = 0.0, weights = 0.0;
    [[unroll]] for (int dv = -1; dv <= 1; ++dv)
        [[unroll]] for (int du = -1; du <= 1; ++du) {
            int kq = (dv + 2) * 5 + du + 2;
            if (!ins[kq]) continue;
            float distance = 0.0;
            int count = 0;
            [[unroll]] for (int ty = -1; ty <= 1; ++ty)
                [[unroll]] for (int tx = -1; tx <= 1; ++tx) {
                    int ip = (ty + 2) * 5 + tx + 2, iq = (dv + ty + 2) * 5 + du + tx + 2;
                    if (!ins[ip] || !ins[iq]) continue;
                    float fp = fs[ip], fq = fs[iq], vp = vs[ip], vq = vs[iq];
                    float diff = fp - fq;
                    float term = (diff * diff - (vp + vq)) /
                                 (vp + vq + float(NFOR_REL_EPS) * (fp * fp + fq * fq) +
                                  float(NFOR_TINY));
                    distance += min(term, float(NFOR_TERM_MAX));
                    ++count;
                }
            float e = max(0.0, distance / float(count)) * scale;
            float wq = (du == 0 && dv == 0) ? 1.0 : (e > NFOR_EXP_CUT ? 0.0 : exp(-e));
            sum += wq * fs[kq];
            weights += wq;
        }
    return sum / weights;
}

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y), j = int(gl_WorkGroupID.z);
    w = push.width;
    h = push.height;
    if (x >= w) return;
    int base = j * w * h, r = push.radius, f = push.patchRadius;
    float scale = 1.0 / (push.bandwidth * push.bandwidth);
    if (r == 1 && f == 1) {
        outputs[base + y * w + x] = prefilter1(x, y, base, scale);
        return;
    }
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
                    int ip = base + py * w + px, iq = base + qy * w + qx;
                    float fp = texelFetch(features, ip).x, fq = texelFetch(features, iq).x;
                    float vp = texelFetch(variance, ip).x, vq = texelFetch(variance, iq).x;
                    float diff = fp - fq;
                    float term = (diff * diff - (vp + vq)) /
                                 (vp + vq + float(NFOR_REL_EPS) * (fp * fp + fq * fq) +
                                  float(NFOR_TINY));
                    distance += min(term, float(NFOR_TERM_MAX));
                    ++count;
                }
            float e = max(0.0, distance / float(count)) * scale;
            float wq = (u == x && v == y) ? 1.0 : (e > NFOR_EXP_CUT ? 0.0 : exp(-e));
            sum += wq * texelFetch(features, base + v * w + u).x;
            weights += wq;
        }
    outputs[base + y * w + x] = sum / weights;
}
