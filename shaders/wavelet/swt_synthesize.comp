#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

// One pass of one level of the stationary wavelet synthesis (layout and formula in
// swt.h), one invocation per output position, taps gathered through the texel view.
// Columns: (LL at srcLow, LH) -> row-low, (HL, HH) -> row-high, the details at srcBase +
// 0, 1, 2 planes, the outputs two planes at dstBase. Rows: row-low, row-high at srcBase ->
// one plane at dstBase.

#include "wavelet/wavelet.h"
#include "wavelet/swt.h"
#include "wavelet/swt_synthesize.h"

layout(local_size_x = WAVELET_SWT_SYNTHESIZE_LOCAL_SIZE) in;
layout(binding = WAVELET_SWT_SYNTHESIZE_SRC) uniform samplerBuffer src;
layout(std430, binding = WAVELET_SWT_SYNTHESIZE_DST) writeonly buffer Dst { float dst[]; };
layout(std430, binding = WAVELET_SWT_SYNTHESIZE_DST) writeonly buffer Dst4 { vec4 dst4[]; };

#include "wavelet/swt.glsl"

float Load(int at) {
    return texelFetch(src, at).r;
}

// x at position i of a line of n samples `stride` floats apart, from its low band at
// `low` and high band at `high`.
// `edge` false (a constant after inlining) when every tap lies inside the line.
float Synthesize(int low, int high, int i, int n, int stride, bool transform, bool edge) {
    if (!transform) return Load(low + i * stride);
    int s = push.step;
    if (WAVELET == MCD_WAVELET_HAAR) {
        // The pair at i (i its first sample), and the pair at i - s (i its second).
        float first = kHaar * Load(low + i * stride) - kHaar * Load(high + i * stride);
        if (i < s) return first;
        int j = (i - s) * stride;
        return 0.5 * (first + (kHaar * Load(low + j) + kHaar * Load(high + j)));
    }
    const int reach = kSynthLowReach > kSynthHighReach ? kSynthLowReach : kSynthHighReach;
    float sum = 0.0;
    [[unroll]] for (int k = -reach; k <= reach; ++k) {
        int p = i - k * s;
        if (edge) p = MirrorAnalysis(p, n);
        if (abs(k) <= kSynthLowReach) sum += SynthesisLow(abs(k)) * Load(low + p * stride);
        if (abs(k) <= kSynthHighReach) sum += SynthesisHigh(abs(k)) * Load(high + p * stride);
    }
    return 0.5 * sum;
}

// Whether every tap of positions first..last lies inside a line of n. Haar folds nothing
// (it reads back to i - step only when i >= step): always the one general loop, which
// measured faster for it than the split.
bool Inside(int first, int last, int n) {
    if (WAVELET == MCD_WAVELET_HAAR) return false;
    const int reach = kSynthLowReach > kSynthHighReach ? kSynthLowReach : kSynthHighReach;
    return first - reach * push.step >= 0 && last + reach * push.step < n;
}

// Store the outputs of positions x0 .. x0 + n - 1 from `at` (as swt_analyze.comp).
void Store(int at, vec4 v, int n) {
    if ((push.width & 3) == 0) {
        dst4[at >> 2] = v;
        return;
    }
    [[unroll]] for (int k = 0; k < 4; ++k)
        if (k < n) dst[at + k] = v[k];
}

// A lane computes 4 neighbouring positions of a row (vec4 stores).
void main() {
    int x0 = 4 * int(gl_GlobalInvocationID.x), y = int(gl_GlobalInvocationID.y);
    int c = int(gl_GlobalInvocationID.z);
    if (x0 >= push.width) return;
    int w = push.width, plane = w * push.height, at = y * w + x0, n = min(4, w - x0);
    int src0 = c * push.srcChannel, dst0 = c * push.dstChannel;
    if (AXIS == WAVELET_SWT_ROWS) {
        bool tx = (push.flags & WAVELET_SWT_TRANSFORM_X) != 0;
        int row = src0 + push.srcBase + y * w;
        vec4 v = vec4(0.0);
        if (Inside(x0, x0 + 3, w)) {
            [[unroll]] for (int k = 0; k < 4; ++k)
                v[k] = Synthesize(row, row + plane, x0 + k, w, 1, tx, false);
        } else {
            [[unroll]] for (int k = 0; k < 4; ++k)
                if (k < n) v[k] = Synthesize(row, row + plane, x0 + k, w, 1, tx, true);
        }
        Store(dst0 + push.dstBase + at, v, n);
    } else {
        bool ty = (push.flags & WAVELET_SWT_TRANSFORM_Y) != 0;
        int details = src0 + push.srcBase + x0;
        vec4 rowLow = vec4(0.0), rowHigh = vec4(0.0);
        // Statements, not ?: (glslang may evaluate both sides of a select).
        if (Inside(y, y, push.height)) {
            [[unroll]] for (int k = 0; k < 4; ++k) {
                if (k < n) {
                    int low = src0 + push.srcLow + x0 + k, d = details + k;
                    rowLow[k] = Synthesize(low, d + plane, y, push.height, w, ty, false);
                    rowHigh[k] = Synthesize(d, d + 2 * plane, y, push.height, w, ty, false);
                }
            }
        } else {
            [[unroll]] for (int k = 0; k < 4; ++k) {
                if (k < n) {
                    int low = src0 + push.srcLow + x0 + k, d = details + k;
                    rowLow[k] = Synthesize(low, d + plane, y, push.height, w, ty, true);
                    rowHigh[k] = Synthesize(d, d + 2 * plane, y, push.height, w, ty, true);
                }
            }
        }
        Store(dst0 + push.dstBase + at, rowLow, n);
        Store(dst0 + push.dstBase + plane + at, rowHigh, n);
    }
}
