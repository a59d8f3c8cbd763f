#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

// One pass of one level of the stationary wavelet analysis (layout in swt.h), one
// invocation per output position, every tap gathered through the texel view. Rows: one
// plane per channel -> row-low, row-high (two planes at dstBase). Columns: the row-low and
// row-high planes at srcBase -> LL at dstLow, HL, LH, HH at dstBase + 0, 1, 2 planes.
// SQUARED: every tap squared (variance analysis; Haar: 1/2 (a + b) for both bands).

#include "wavelet/wavelet.h"
#include "wavelet/swt.h"
#include "wavelet/swt_analyze.h"

layout(local_size_x = WAVELET_SWT_ANALYZE_LOCAL_SIZE) in;
layout(constant_id = WAVELET_SWT_ANALYZE_SPEC_SQUARED) const int SQUARED = 0;
layout(binding = WAVELET_SWT_ANALYZE_SRC) uniform samplerBuffer src;
layout(std430, binding = WAVELET_SWT_ANALYZE_DST) writeonly buffer Dst { float dst[]; };
layout(std430, binding = WAVELET_SWT_ANALYZE_DST) writeonly buffer Dst4 { vec4 dst4[]; };

#include "wavelet/swt.glsl"

float Tap(float t) {
    return SQUARED != 0 ? t * t : t;
}

float Load(int at) {
    return texelFetch(src, at).r;
}

// Low and high outputs at position i of a line of n samples `stride` floats apart from
// `base`. Only the filters' own taps are read.
// `edge` false (a constant after inlining) when every tap lies inside the line.
vec2 Analyze(int base, int i, int n, int stride, bool transform, bool edge) {
    if (!transform) return vec2(Load(base + i * stride), 0.0);
    int s = push.step;
    if (WAVELET == MCD_WAVELET_HAAR) {
        float a = Load(base + i * stride), b = Load(base + MirrorAnalysis(i + s, n) * stride);
        if (SQUARED != 0) return vec2(0.5 * a + 0.5 * b);
        return vec2(kHaar * a + kHaar * b, -kHaar * a + kHaar * b);
    }
    float lo = 0.0, hi = 0.0;
    [[unroll]] for (int k = -kLowReach; k <= kLowReach; ++k) {
        int p = i + k * s;
        if (edge) p = MirrorAnalysis(p, n);
        float v = Load(base + p * stride);
        lo += Tap(AnalysisLow(abs(k))) * v;
        if (abs(k) <= kHighReach) hi += Tap(AnalysisHigh(abs(k))) * v;
    }
    return vec2(lo, hi);
}

// Whether every tap of positions first..last lies inside a line of n.
bool Inside(int first, int last, int n) {
    return first - kLowReach * push.step >= 0 && last + kLowReach * push.step < n;
}

// Store the outputs of positions x0 .. x0 + n - 1 from `at`: one vec4 when rows are whole
// vec4s (every offset is then a multiple of 4), else one float at a time.
void Store(int at, vec4 v, int n) {
    if ((push.width & 3) == 0) {
        dst4[at >> 2] = v;
        return;
    }
    [[unroll]] for (int k = 0; k < 4; ++k)
        if (k < n) dst[at + k] = v[k];
}

// Haar, rows and columns of a level at once (WAVELET_SWT_FUSED): the level's four bands
// at (x, y) from the 2 x 2 samples at x, x + step and y, y + step, with the arithmetic of
// the two separate passes (the same float results), and no temporary. Reads the level's
// input as the rows pass does, writes as the columns pass.
vec4 HaarPair(float a, float b, bool transform) {
    if (!transform) return vec4(a, 0.0, 0.0, 0.0);
    if (SQUARED != 0) return vec4(0.5 * a + 0.5 * b, 0.5 * a + 0.5 * b, 0.0, 0.0);
    return vec4(kHaar * a + kHaar * b, -kHaar * a + kHaar * b, 0.0, 0.0);
}

void FusedHaar(int x0, int y, int c) {
    int w = push.width, h = push.height, plane = w * h, n = min(4, w - x0), s = push.step;
    bool tx = (push.flags & WAVELET_SWT_TRANSFORM_X) != 0;
    bool ty = (push.flags & WAVELET_SWT_TRANSFORM_Y) != 0;
    int src = c * push.srcChannel + push.srcBase, dst0 = c * push.dstChannel;
    int row0 = src + y * w, row1 = src + (ty ? MirrorAnalysis(y + s, h) : y) * w;
    vec4 ll = vec4(0.0), lh = vec4(0.0), hl = vec4(0.0), hh = vec4(0.0);
    [[unroll]] for (int k = 0; k < 4; ++k) {
        if (k < n) {
            int x = x0 + k, x1 = tx ? MirrorAnalysis(x + s, w) : x;
            vec2 r0 = HaarPair(Load(row0 + x), Load(row0 + x1), tx).xy;
            vec2 r1 = HaarPair(Load(row1 + x), Load(row1 + x1), tx).xy;
            vec2 l = HaarPair(r0.x, r1.x, ty).xy, hi = HaarPair(r0.y, r1.y, ty).xy;
            ll[k] = l.x;
            lh[k] = l.y;
            hl[k] = hi.x;
            hh[k] = hi.y;
        }
    }
    int at = y * w + x0;
    Store(dst0 + push.dstLow + at, ll, n);
    Store(dst0 + push.dstBase + at, hl, n);
    Store(dst0 + push.dstBase + plane + at, lh, n);
    Store(dst0 + push.dstBase + 2 * plane + at, hh, n);
}

// A lane computes 4 neighbouring positions of a row: lavapipe stores storage buffers lane
// by lane, so a vec4 per store is what counts.
void main() {
    int x0 = 4 * int(gl_GlobalInvocationID.x), y = int(gl_GlobalInvocationID.y);
    int c = int(gl_GlobalInvocationID.z);
    if (x0 >= push.width) return;
    if (AXIS == WAVELET_SWT_FUSED) {
        FusedHaar(x0, y, c);
        return;
    }
    int w = push.width, plane = w * push.height, at = y * w + x0, n = min(4, w - x0);
    int src0 = c * push.srcChannel, dst0 = c * push.dstChannel;
    if (AXIS == WAVELET_SWT_ROWS) {
        bool tx = (push.flags & WAVELET_SWT_TRANSFORM_X) != 0;
        vec4 lo = vec4(0.0), hi = vec4(0.0);
        int row = src0 + push.srcBase + y * w;
        if (Inside(x0, x0 + 3, w)) {
            [[unroll]] for (int k = 0; k < 4; ++k) {
                vec2 r = Analyze(row, x0 + k, w, 1, tx, false);
                lo[k] = r.x;
                hi[k] = r.y;
            }
        } else {
            [[unroll]] for (int k = 0; k < 4; ++k) {
                if (k < n) {
                    vec2 r = Analyze(row, x0 + k, w, 1, tx, true);
                    lo[k] = r.x;
                    hi[k] = r.y;
                }
            }
        }
        Store(dst0 + push.dstBase + at, lo, n);
        Store(dst0 + push.dstBase + plane + at, hi, n);
    } else {
        bool ty = (push.flags & WAVELET_SWT_TRANSFORM_Y) != 0;
        vec4 ll = vec4(0.0), lh = vec4(0.0), hl = vec4(0.0), hh = vec4(0.0);
        // Statements, not ?: (glslang may evaluate both sides of a select).
        bool inside = Inside(y, y, push.height);
        [[unroll]] for (int k = 0; k < 4; ++k) {
            if (k < n) {
                int column = src0 + push.srcBase + x0 + k;
                vec2 l, h;
                if (inside) {
                    l = Analyze(column, y, push.height, w, ty, false);
                    h = Analyze(column + plane, y, push.height, w, ty, false);
                } else {
                    l = Analyze(column, y, push.height, w, ty, true);
                    h = Analyze(column + plane, y, push.height, w, ty, true);
                }
                ll[k] = l.x;
                lh[k] = l.y;
                hl[k] = h.x;
                hh[k] = h.y;
            }
        }
        Store(dst0 + push.dstLow + at, ll, n);
        Store(dst0 + push.dstBase + at, hl, n);
        Store(dst0 + push.dstBase + plane + at, lh, n);
        Store(dst0 + push.dstBase + 2 * plane + at, hh, n);
    }
}
