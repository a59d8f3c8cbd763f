// One level of the forward DWT as direct separable convolutions with the filter bank of
// AWR appendix A (measured faster than the lifting steps on lavapipe), shared by analyze.comp
// (plain taps) and sqanalyze.comp (squared taps, renormalised to lowSum / highSum). The
// including kernel defines WAVELET_SQUARED (0 or 1) and its bindings, then includes this.
// Laid out like the line kernels: a rows pass from `src` into an interleaved temporary, a
// columns pass from it into the four bands of `dst` (Mallat layout).

#include "wavelet/lifting.glsl"

// Analysis filter taps of AWR appendix A, centre first (symmetric).
const float kLow97[5] = float[5](0.6029490182363579 * kSqrt2, 0.2668641184428723 * kSqrt2,
                                 -0.07822326652898785 * kSqrt2, -0.01686411844287495 * kSqrt2,
                                 0.02674875741080976 * kSqrt2);
const float kHigh97[4] = float[4](1.115087052456994 / kSqrt2, -0.5912717631142470 / kSqrt2,
                                  -0.05754352622849957 / kSqrt2, 0.09127176311424948 / kSqrt2);
const float kLow53[3] = float[3](0.75 * kSqrt2, 0.25 * kSqrt2, -0.125 * kSqrt2);
const float kHigh53[2] = float[2](-1.0 / kSqrt2, 0.5 / kSqrt2);

float Tap(float t) {
    return WAVELET_SQUARED != 0 ? t * t : t;
}
float LowTapSq(int k) {
    if (WAVELET == MCD_WAVELET_CDF97) return Tap(kLow97[k]);
    if (WAVELET == MCD_WAVELET_LEGALL53) return Tap(kLow53[k]);
    return 0.5;
}
float HighTapSq(int k) {
    if (WAVELET == MCD_WAVELET_CDF97) return Tap(kHigh97[k]);
    if (WAVELET == MCD_WAVELET_LEGALL53) return Tap(kHigh53[k]);
    return 0.5;
}
// Half-lengths of the filters: taps at offsets -reach..reach.
const int kLowReach = WAVELET == MCD_WAVELET_CDF97 ? 4 : (WAVELET == MCD_WAVELET_LEGALL53 ? 2 : 0);
const int kHighReach = WAVELET == MCD_WAVELET_CDF97 ? 3 : (WAVELET == MCD_WAVELET_LEGALL53 ? 1 : 0);

// Factor that makes the squared taps sum to `target` (<= 0: leave them as they are).
float Renormalise(float target, bool lowPass) {
    if (WAVELET_SQUARED == 0 || target <= 0.0) return 1.0;
    // Haar: two taps of 1/2.
    if (WAVELET == MCD_WAVELET_HAAR) return target;
    int reach = lowPass ? kLowReach : kHighReach;
    float sum = 0.0;
    for (int k = -reach; k <= reach; ++k) sum += lowPass ? LowTapSq(abs(k)) : HighTapSq(abs(k));
    return target / sum;
}

// Squared-tap convolution of the line at k (parity of k = parity of the position), or
// the sample itself along an axis that is not transformed. Only the filter's own taps: a
// zero tap times a NaN neighbour would leak the NaN.
float Convolve(int k, bool transform) {
    if (!transform) return line[k];
    if (WAVELET == MCD_WAVELET_HAAR && WAVELET_SQUARED == 0) {
        // Pairs (2n, 2n+1): (a + b) / sqrt 2 and (b - a) / sqrt 2.
        if ((k & 1) == 0) return (line[k] + line[k + 1]) * (1.0 / kSqrt2);
        return (line[k] - line[k - 1]) * (1.0 / kSqrt2);
    }
    if (WAVELET == MCD_WAVELET_HAAR) {
        // Pairs (2n, 2n+1); each sample of the pair weighs 1/2.
        int pair = (k & 1) == 0 ? k + 1 : k - 1;
        return 0.5 * (line[k] + line[pair]) *
               Renormalise((k & 1) == 0 ? WAVELET_LOW_SUM : WAVELET_HIGH_SUM, (k & 1) == 0);
    }
    float sum = 0.0;
    if ((k & 1) == 0) {
        [[unroll]] for (int j = -kLowReach; j <= kLowReach; ++j)
            sum += LowTapSq(abs(j)) * line[k + j];
        return sum * Renormalise(WAVELET_LOW_SUM, true);
    }
    [[unroll]] for (int j = -kHighReach; j <= kHighReach; ++j)
        sum += HighTapSq(abs(j)) * line[k + j];
    return sum * Renormalise(WAVELET_HIGH_SUM, false);
}

// Convolve one row segment into the temporary; `fast` when the whole apron lies inside
// the row and the views are vec4-aligned (a constant after inlining). Position p is
// ready once line[p + kDelay] is loaded.
void RowSegment(bool fast, int srcRow, int dstRow, int x0) {
    int origin = x0 - WAVELET_HALO;
    bool transform = push.width > 1;
    [[unroll]] for (int k = 0; k < kExt + kDelay; ++k) {
        if (k < kExt) {
            if (!fast) {
                line[k] = src[srcRow + MirrorAnalysis(origin + k, push.width)];
            } else if ((k & 3) == 0) {
                vec4 v = src4[(srcRow + origin + k) >> 2];
                line[k] = v.x, line[k + 1] = v.y, line[k + 2] = v.z, line[k + 3] = v.w;
            }
        }
        int p = k - kDelay, j = p - WAVELET_HALO;
        if (j < 0 || j >= WAVELET_TILE) continue;
        if (!fast) {
            if (x0 + j < push.width) dst[dstRow + x0 + j] = Convolve(p, transform);
        } else if ((j & 3) == 3) {
            dst4[(dstRow + x0 + j - 3) >> 2] =
                vec4(Convolve(p - 3, transform), Convolve(p - 2, transform),
                     Convolve(p - 1, transform), Convolve(p, transform));
        }
    }
}

void Rows(int lane, int channel) {
    int y = int(gl_WorkGroupID.y) * WAVELET_LOCAL_SIZE + lane;
    if (y >= push.height) return;
    int x0 = SegmentOfGroup(int(gl_WorkGroupID.x), push.width) * WAVELET_TILE;
    int srcRow = channel * push.srcPlane + y * push.srcStride;
    int dstRow = channel * push.dstPlane + y * push.dstStride;
    // The parts run one path only (constants); all segments test which they need.
    if (PART == WAVELET_PART_INTERIOR)
        RowSegment(true, srcRow, dstRow, x0);
    else if (PART == WAVELET_PART_EDGES)
        RowSegment(false, srcRow, dstRow, x0);
    else if (VEC4 != 0 && x0 >= WAVELET_HALO && x0 + WAVELET_TILE + WAVELET_HALO <= push.width)
        RowSegment(true, srcRow, dstRow, x0);
    else
        RowSegment(false, srcRow, dstRow, x0);
}

// Convolve one column segment and write it into the bands; `interior` when no position
// of the apron needs folding (a constant after inlining).
void ColumnSegment(bool interior, int srcBase, int dstBase, int y0) {
    int origin = y0 - WAVELET_HALO;
    bool transform = push.height > 1;
    [[unroll]] for (int k = 0; k < kExt + kDelay; ++k) {
        if (k < kExt) {
            int y = interior ? origin + k : MirrorAnalysis(origin + k, push.height);
            line[k] = src[srcBase + y * push.srcStride];
        }
        int p = k - kDelay, y = y0 + p - WAVELET_HALO;
        if (p < WAVELET_HALO || p >= WAVELET_HALO + WAVELET_TILE || y >= push.height) continue;
        dst[dstBase + BandIndex(y, push.height) * push.dstStride] = Convolve(p, transform);
    }
}

void Columns(int lane, int channel) {
    int x = int(gl_WorkGroupID.x) * WAVELET_LOCAL_SIZE + lane;
    if (x >= push.width) return;
    int y0 = SegmentOfGroup(int(gl_WorkGroupID.y), push.height) * WAVELET_TILE;
    int srcBase = channel * push.srcPlane + x;
    int dstBase = channel * push.dstPlane + BandIndex(x, push.width);
    if (PART == WAVELET_PART_INTERIOR)
        ColumnSegment(true, srcBase, dstBase, y0);
    else if (PART == WAVELET_PART_EDGES)
        ColumnSegment(false, srcBase, dstBase, y0);
    else if (y0 >= WAVELET_HALO && y0 + WAVELET_TILE + WAVELET_HALO <= push.height)
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
