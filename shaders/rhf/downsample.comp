#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "rhf/downsample.h"

// One invocation per PIX consecutive results along the pass's axis: along x, x blocks
// across and the row from the grid; along y, the column across and row blocks from the
// grid; the plane from z. The source values the lane's results share are read once (taps
// step apart overlap) and the taps are specialization constants, so the loops unroll and
// the arrays stay in registers; each result sums its taps in tap order, as one per
// invocation did.
layout(local_size_x = RHF_DOWNSAMPLE_LOCAL_SIZE) in;
layout(constant_id = RHF_DOWNSAMPLE_SPEC_RADIUS) const int R = 3;
layout(constant_id = RHF_DOWNSAMPLE_SPEC_STEP) const int STEP = 2;
const int TAPS = 2 * R + 1;
const int PIX = RHF_DOWNSAMPLE_PIXELS_PER_LANE;
const int SPAN = (PIX - 1) * STEP + TAPS;
layout(binding = RHF_DOWNSAMPLE_SRC) uniform samplerBuffer src;
layout(std430, binding = RHF_DOWNSAMPLE_DST) writeonly buffer Dst { float dst[]; };
// A texel buffer too: lavapipe loads a storage buffer lane by lane.
layout(binding = RHF_DOWNSAMPLE_WEIGHTS) uniform samplerBuffer weights;

float w[TAPS], s[SPAN];

// The tool's symmetric boundary: period 2n, the edge pixel repeated.
int Mirror(int i, int n) {
    int period = 2 * n;  // GLSL's % is undefined for negative operands
    i = i < 0 ? period - 1 - (-i - 1) % period : i % period;
    return i < n ? i : period - 1 - i;
}

// The SPAN source values from `first` along the axis, `stride` apart from `base`, mirrored
// at 0 and n. Mirror only near the edges, in a branch: its integer division is slow on CPU
// devices, and lavapipe flattens a small conditional into both sides.
void Load(int base, int first, int stride, int n) {
    if (first >= 0 && first + SPAN <= n) {
        [[unroll]] for (int m = 0; m < SPAN; ++m)
            s[m] = texelFetch(src, base + (first + m) * stride).r;
    } else {
        [[unroll]] for (int m = 0; m < SPAN; ++m)
            s[m] = texelFetch(src, base + Mirror(first + m, n) * stride).r;
    }
}

void main() {
    const bool alongX = push.axis == 0;
    int lane = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y),
        p = int(gl_WorkGroupID.z);
    // The lane's first result along the axis, and the fixed coordinate across it.
    int first = (alongX ? lane : y) * PIX, across = alongX ? y : lane;
    int results = alongX ? push.dstWidth : push.dstHeight;
    if (first >= results || (!alongX && across >= push.dstWidth)) return;
    [[unroll]] for (int i = 0; i < TAPS; ++i) w[i] = texelFetch(weights, i).r;
    int srcPlane = p * push.srcWidth * push.srcHeight;
    // Taps start at floor((x + 0.5) step) - radius, as in the tool's sampler.
    int origin = first * STEP + STEP / 2 - R;
    if (alongX)
        Load(srcPlane + across * push.srcWidth, origin, 1, push.srcWidth);
    else
        Load(srcPlane + across, origin, push.srcWidth, push.srcHeight);
    [[unroll]] for (int j = 0; j < PIX; ++j) {
        if (first + j >= results) break;
        float v = 0.0;
        [[unroll]] for (int i = 0; i < TAPS; ++i) v += w[i] * s[j * STEP + i];
        int x = alongX ? first + j : across, row = alongX ? y : first + j;
        dst[(p * push.dstHeight + row) * push.dstWidth + x] = v;
    }
}
