#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "wavelet/wavelet.h"
#include "wavelet/analyze.h"

layout(local_size_x = WAVELET_LOCAL_SIZE) in;
layout(constant_id = WAVELET_SPEC_AXIS) const int AXIS = WAVELET_AXIS_ROWS;
layout(constant_id = WAVELET_SPEC_VEC4) const int VEC4 = 0;
// Scalar and vec4 views of the same buffers (vec4 only with strides that are multiples of 4).
layout(std430, binding = WAVELET_LINES_SRC) readonly buffer Src { float src[]; };
layout(std430, binding = WAVELET_LINES_SRC) readonly buffer Src4 { vec4 src4[]; };
layout(std430, binding = WAVELET_LINES_DST) writeonly buffer Dst { float dst[]; };
layout(std430, binding = WAVELET_LINES_DST) writeonly buffer Dst4 { vec4 dst4[]; };

#include "wavelet/lifting.glsl"

// Output scale of line position k (whose parity is its position's).
float Scale(int k, bool lift) {
    if (!lift) return 1.0;
    return (k & 1) == 0 ? LowScale() : HighScale();
}

// Lift one row segment: `fast` when the whole apron lies inside the row and the views
// are vec4-aligned (a constant after inlining). The x scaling is applied here.
void RowSegment(bool fast, int srcRow, int dstRow, int x0) {
    int origin = x0 - WAVELET_HALO;
    bool lift = push.width > 1;
    [[unroll]] for (int k = 0; k < kExt + kDelay; ++k) {
        if (k < kExt) {
            if (!fast) {
                line[k] = src[srcRow + MirrorAnalysis(origin + k, push.width)];
            } else if ((k & 3) == 0) {
                vec4 v = src4[(srcRow + origin + k) >> 2];
                line[k] = v.x, line[k + 1] = v.y, line[k + 2] = v.z, line[k + 3] = v.w;
            }
        }
        if (lift) ForwardAt(k);
        int p = k - kDelay, j = p - WAVELET_HALO;
        if (j < 0 || j >= WAVELET_TILE) continue;
        // Scale on the way out, not in the line: step 4 of a later position still reads
        // an odd position after it is final.
        if (!fast) {
            if (x0 + j < push.width) dst[dstRow + x0 + j] = line[p] * Scale(p, lift);
        } else if ((j & 3) == 3) {
            dst4[(dstRow + x0 + j - 3) >> 2] =
                vec4(line[p - 3] * Scale(p - 3, lift), line[p - 2] * Scale(p - 2, lift),
                     line[p - 1] * Scale(p - 1, lift), line[p] * Scale(p, lift));
        }
    }
}

// Invocation `lane` lifts a segment of row y.
void Rows(int lane, int channel) {
    int y = int(gl_WorkGroupID.y) * WAVELET_LOCAL_SIZE + lane;
    if (y >= push.height) return;
    int x0 = int(gl_WorkGroupID.x) * WAVELET_TILE;
    int srcRow = channel * push.srcPlane + y * push.srcStride;
    int dstRow = channel * push.dstPlane + y * push.dstStride;
    if (VEC4 != 0 && x0 >= WAVELET_HALO && x0 + WAVELET_TILE + WAVELET_HALO <= push.width)
        RowSegment(true, srcRow, dstRow, x0);
    else
        RowSegment(false, srcRow, dstRow, x0);
}

// Lift one column segment and write it into the bands; `interior` when no position of
// the apron needs folding (a constant after inlining). One column per invocation: on
// lavapipe vec4 accesses across invocations cost more than they save.
void ColumnSegment(bool interior, int srcBase, int dstBase, int y0) {
    int origin = y0 - WAVELET_HALO;
    bool lift = push.height > 1;
    [[unroll]] for (int k = 0; k < kExt + kDelay; ++k) {
        if (k < kExt) {
            int y = interior ? origin + k : MirrorAnalysis(origin + k, push.height);
            line[k] = src[srcBase + y * push.srcStride];
        }
        if (lift) ForwardAt(k);
        int p = k - kDelay, y = y0 + p - WAVELET_HALO;
        if (p < WAVELET_HALO || p >= WAVELET_HALO + WAVELET_TILE || y >= push.height) continue;
        dst[dstBase + BandIndex(y, push.height) * push.dstStride] = line[p] * Scale(p, lift);
    }
}

// Invocation `lane` lifts a segment of column x and writes it into the bands.
void Columns(int lane, int channel) {
    int x = int(gl_WorkGroupID.x) * WAVELET_LOCAL_SIZE + lane;
    if (x >= push.width) return;
    int y0 = int(gl_WorkGroupID.y) * WAVELET_TILE;
    int srcBase = channel * push.srcPlane + x;
    int dstBase = channel * push.dstPlane + BandIndex(x, push.width);
    if (y0 >= WAVELET_HALO && y0 + WAVELET_TILE + WAVELET_HALO <= push.height)
        ColumnSegment(true, srcBase, dstBase, y0);
    else
        ColumnSegment(false, srcBase, dstBase, y0);
}

void main() {
    int lane = int(gl_LocalInvocationIndex), channel = int(gl_WorkGroupID.z);
    if (AXIS == WAVELET_AXIS_ROWS)
        Rows(lane, channel);
    else
        Columns(lane, channel);
}
