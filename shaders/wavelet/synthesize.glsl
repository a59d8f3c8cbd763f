// The body of the inverse DWT kernels (synthesize.comp and synthesize_shrink.comp): include
// after the bindings and push constants. With WAVELET_SYNTHESIZE_SHRINK defined the
// columns pass soft-thresholds the detail coefficients as it reads them (binding
// `variance`, push field `cs`).
layout(local_size_x = WAVELET_LOCAL_SIZE) in;
layout(constant_id = WAVELET_SPEC_AXIS) const int AXIS = WAVELET_AXIS_COLUMNS;
layout(constant_id = WAVELET_SPEC_VEC4) const int VEC4 = 0;
layout(std430, binding = WAVELET_LINES_SRC) readonly buffer Src { float src[]; };
layout(std430, binding = WAVELET_LINES_SRC) readonly buffer Src4 { vec4 src4[]; };
layout(std430, binding = WAVELET_LINES_DST) writeonly buffer Dst { float dst[]; };
layout(std430, binding = WAVELET_LINES_DST) writeonly buffer Dst4 { vec4 dst4[]; };

#include "wavelet/lifting.glsl"

// Coefficient position that position p of an axis of length n reads, folded like the
// forward transform's signal; -1 for Haar's phantom detail past an odd end (it is zero).
int MirrorSynthesis(int p, int n) {
    if (WAVELET == MCD_WAVELET_HAAR && n > 1 && (p < 0 || p >= n)) return -1;
    return MirrorAnalysis(p, n);
}

float Unscale(int p, int n) {
    if (n == 1) return 1.0;
    return (p & 1) == 0 ? 1.0 / LowScale() : 1.0 / HighScale();
}

// The inverse lifting as direct convolutions: sample p of the interleaved line of
// unscaled coefficients (low at even, high at odd positions) is a symmetric combination of
// its neighbours, the impulse responses of the inverse lifting steps (measured faster than
// the lifting wavefront on lavapipe, like the analysis). Only the filters' own taps: a zero
// tap times a NaN neighbour would leak the NaN. Taps centre first.
const float kEven97[4] = float[4](0.9064465330579812, -0.3282893280391283,
                                  -0.046776733471009406, 0.020745801810627237);
const float kOdd97[5] = float[5](0.7417322688176877, 0.48064071642573425,
                                 -0.09622823688575127, -0.07419418336775194,
                                 0.03290562870540482);
const float kEven53[2] = float[2](1.0, -0.25);
const float kOdd53[3] = float[3](0.75, 0.5, -0.125);

float Synth(int p, bool lift) {
    if (!lift) return line[p];
    if (WAVELET == MCD_WAVELET_HAAR)
        return (p & 1) == 0 ? line[p] - 0.5 * line[p + 1] : line[p - 1] + 0.5 * line[p];
    float sum = 0.0;
    if (WAVELET == MCD_WAVELET_CDF97) {
        if ((p & 1) == 0) {
            [[unroll]] for (int j = -3; j <= 3; ++j) sum += kEven97[abs(j)] * line[p + j];
        } else {
            [[unroll]] for (int j = -4; j <= 4; ++j) sum += kOdd97[abs(j)] * line[p + j];
        }
    } else {
        if ((p & 1) == 0) {
            [[unroll]] for (int j = -1; j <= 1; ++j) sum += kEven53[abs(j)] * line[p + j];
        } else {
            [[unroll]] for (int j = -2; j <= 2; ++j) sum += kOdd53[abs(j)] * line[p + j];
        }
    }
    return sum;
}

// The coefficient at `at` of the bands; with WAVELET_SYNTHESIZE_SHRINK a `detail`
// coefficient is soft-thresholded first (AWR eq. 11, the same arithmetic as
// shaders/awr/shrink.comp), the low-low band passes through.
float Coefficient(int at, bool detail) {
    float w = src[at];
#ifdef WAVELET_SYNTHESIZE_SHRINK
    if (detail) {
        float threshold = push.cs * sqrt(variance[at]);
        w = sign(w) * max(abs(w) - threshold, 0.0);
    }
#endif
    return w;
}

// Gather one segment of interleaved column x from the bands, undo both scalings and the
// column transform; `interior` when no position of the apron needs folding.
void ColumnSegment(bool interior, int x, int srcBase, int dstBase, int y0) {
    int origin = y0 - WAVELET_HALO;
    bool lift = push.height > 1;
    float scaleX = Unscale(x, push.width);
    // Column x holds high-pass coefficients along x (an axis of length 1 has none).
    bool xHigh = (x & 1) == 1;
    // Interior: rows alternate between the low and the high band.
    int lowAt = srcBase + (origin >> 1) * push.srcStride;
    int highAt = srcBase + (((push.height + 1) >> 1) + (origin >> 1)) * push.srcStride;
    [[unroll]] for (int k = 0; k < kExt + kDelay; ++k) {
        if (k < kExt) {
            if (interior) {
                line[k] = (k & 1) == 0
                              ? Coefficient(lowAt + (k >> 1) * push.srcStride, xHigh) * (scaleX / LowScale())
                              : Coefficient(highAt + (k >> 1) * push.srcStride, true) * (scaleX / HighScale());
            } else {
                int y = MirrorSynthesis(origin + k, push.height);
                line[k] = y < 0 ? 0.0
                                : Coefficient(srcBase + BandIndex(y, push.height) * push.srcStride,
                                              xHigh || (y & 1) == 1) *
                                      (scaleX * Unscale(y, push.height));
            }
        }
        int p = k - kDelay, y = y0 + p - WAVELET_HALO;
        if (p < WAVELET_HALO || p >= WAVELET_HALO + WAVELET_TILE || y >= push.height) continue;
        dst[dstBase + y * push.dstStride] = Synth(p, lift);
    }
}

// Invocation `lane` undoes the column transform of a segment of interleaved column x.
void Columns(int lane, int channel) {
    int x = int(gl_WorkGroupID.x) * WAVELET_LOCAL_SIZE + lane;
    if (x >= push.width) return;
    int y0 = SegmentOfGroup(int(gl_WorkGroupID.y), push.height) * WAVELET_TILE;
    int srcBase = channel * push.srcPlane + BandIndex(x, push.width);
    int dstBase = channel * push.dstPlane + x;
    // The parts run one path only (constants); all segments test which they need.
    if (PART == WAVELET_PART_INTERIOR)
        ColumnSegment(true, x, srcBase, dstBase, y0);
    else if (PART == WAVELET_PART_EDGES)
        ColumnSegment(false, x, srcBase, dstBase, y0);
    else if (push.height > 1 && y0 >= WAVELET_HALO && y0 + WAVELET_TILE + WAVELET_HALO <= push.height)
        ColumnSegment(true, x, srcBase, dstBase, y0);
    else
        ColumnSegment(false, x, srcBase, dstBase, y0);
}

// Undo the row transform of one row segment; `fast` as in the analysis rows pass.
void RowSegment(bool fast, int srcRow, int dstRow, int x0) {
    int origin = x0 - WAVELET_HALO;
    bool lift = push.width > 1;
    [[unroll]] for (int k = 0; k < kExt + kDelay; ++k) {
        if (k < kExt) {
            if (!fast) {
                int x = MirrorSynthesis(origin + k, push.width);
                line[k] = x < 0 ? 0.0 : src[srcRow + x];
            } else if ((k & 3) == 0) {
                vec4 v = src4[(srcRow + origin + k) >> 2];
                line[k] = v.x, line[k + 1] = v.y, line[k + 2] = v.z, line[k + 3] = v.w;
            }
        }
        int p = k - kDelay, j = p - WAVELET_HALO;
        if (j < 0 || j >= WAVELET_TILE) continue;
        if (!fast) {
            if (x0 + j < push.width) dst[dstRow + x0 + j] = Synth(p, lift);
        } else if ((j & 3) == 3) {
            dst4[(dstRow + x0 + j - 3) >> 2] =
                vec4(Synth(p - 3, lift), Synth(p - 2, lift), Synth(p - 1, lift), Synth(p, lift));
        }
    }
}

// Invocation `lane` undoes the row transform of a segment of row y.
void Rows(int lane, int channel) {
    int y = int(gl_WorkGroupID.y) * WAVELET_LOCAL_SIZE + lane;
    if (y >= push.height) return;
    int x0 = SegmentOfGroup(int(gl_WorkGroupID.x), push.width) * WAVELET_TILE;
    int srcRow = channel * push.srcPlane + y * push.srcStride;
    int dstRow = channel * push.dstPlane + y * push.dstStride;
    if (PART == WAVELET_PART_INTERIOR)
        RowSegment(true, srcRow, dstRow, x0);
    else if (PART == WAVELET_PART_EDGES)
        RowSegment(false, srcRow, dstRow, x0);
    else if (VEC4 != 0 && x0 >= WAVELET_HALO && x0 + WAVELET_TILE + WAVELET_HALO <= push.width)
        RowSegment(true, srcRow, dstRow, x0);
    else
        RowSegment(false, srcRow, dstRow, x0);
}

void main() {
    int lane = int(gl_LocalInvocationIndex), channel = int(gl_WorkGroupID.z);
    if (AXIS == WAVELET_AXIS_ROWS)
        Rows(lane, channel);
    else
        Columns(lane, channel);
}
