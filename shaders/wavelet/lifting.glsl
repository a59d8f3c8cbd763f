// Line lifting for the wavelet kernels. Include after the kernel's header. A line holds
// positions origin + k, k in [0, WAVELET_TILE_EXT), with origin = segment start -
// WAVELET_HALO even, so the parity of k is the parity of the position (even = low-pass,
// odd = high-pass). The segment's positions are k in [WAVELET_HALO, WAVELET_HALO +
// WAVELET_TILE); the steps below leave them exact (the apron absorbs the edge effects).

layout(constant_id = WAVELET_SPEC_BASIS) const int WAVELET = MCD_WAVELET_CDF97;

const int kExt = WAVELET_TILE_EXT;

layout(constant_id = WAVELET_SPEC_PART) const int PART = WAVELET_PART_ALL;

// Interior segments along an axis of length n (tile.h), as the host counts them.
int InteriorSegments(int n) {
    return max(n - WAVELET_TILE - WAVELET_HALO, 0) / WAVELET_TILE;
}

// The segment that workgroup `group` of this part filters along an axis of length n.
int SegmentOfGroup(int group, int n) {
    if (PART == WAVELET_PART_INTERIOR) return group + 1;
    if (PART == WAVELET_PART_EDGES && group > 0) return InteriorSegments(n) + group;
    return group;
}

// CDF 9/7 lifting factorisation (Daubechies and Sweldens) and the scaling that gives the
// filter bank of AWR appendix A (low-pass sums to sqrt 2).
const float kAlpha = -1.586134342059924;
const float kBeta = -0.052980118572961;
const float kGamma = 0.882911075530934;
const float kDelta = 0.443506852043971;
const float kZeta = 1.149604398860241;
const float kSqrt2 = 1.4142135623730951;

#include "wavelet/fold.glsl"

// Scale of the low (even) and high (odd) outputs after the lifting steps.
float LowScale() {
    return WAVELET == MCD_WAVELET_CDF97 ? kZeta : kSqrt2;
}
float HighScale() {
    if (WAVELET == MCD_WAVELET_CDF97) return 1.0 / kZeta;
    // The paper's LeGall high-pass has the opposite sign to its 9/7 one.
    if (WAVELET == MCD_WAVELET_LEGALL53) return -1.0 / kSqrt2;
    return 1.0 / kSqrt2;
}

// Band index of a position along an axis of length n: low coefficients first, then high.
int BandIndex(int p, int n) {
    if (n == 1) return p;
    return (p & 1) == 0 ? (p >> 1) : ((n + 1) >> 1) + (p >> 1);
}

// The lifting runs as a wavefront: once line[k] is loaded, ForwardAt(k) applies step 1 at
// k-1, step 2 at k-2, step 3 at k-3 and step 4 at k-4, so position k - kDelay is final.
// The same operations on the same operands as step-by-step sweeps (bit-identical), but
// only a handful of values are live at once: a whole-line sweep keeps 64 floats per
// invocation live, which spills on lavapipe.
const int kDelay = WAVELET_HALO;

// Lifting over a line array L of type T, written once as a macro so another line type
// (say a vec4 of four lines) can share the schedule.
#define MCD_LINE_LIFTING(T, L, StepAtT, ForwardAtT, InverseAtT)          \
    T L[kExt];                                                           \
    void StepAtT(int k, int parity, float left, float right) {           \
        if (k >= 1 && k < kExt - 1 && (k & 1) == parity)                 \
            L[k] += left * L[k - 1] + right * L[k + 1];                  \
    }                                                                    \
    void ForwardAtT(int k) {                                             \
        if (WAVELET == MCD_WAVELET_CDF97) {                              \
            StepAtT(k - 1, 1, kAlpha, kAlpha);                           \
            StepAtT(k - 2, 0, kBeta, kBeta);                             \
            StepAtT(k - 3, 1, kGamma, kGamma);                           \
            StepAtT(k - 4, 0, kDelta, kDelta);                           \
        } else if (WAVELET == MCD_WAVELET_LEGALL53) {                    \
            StepAtT(k - 1, 1, -0.5, -0.5);                               \
            StepAtT(k - 2, 0, 0.25, 0.25);                               \
        } else {                                                         \
            StepAtT(k - 1, 1, -1.0, 0.0);                                \
            StepAtT(k - 2, 0, 0.0, 0.5);                                 \
        }                                                                \
    }                                                                    \
    /* The inverse steps in reverse order, as a wavefront of the same shape. */ \
    void InverseAtT(int k) {                                             \
        if (WAVELET == MCD_WAVELET_CDF97) {                              \
            StepAtT(k - 1, 0, -kDelta, -kDelta);                         \
            StepAtT(k - 2, 1, -kGamma, -kGamma);                         \
            StepAtT(k - 3, 0, -kBeta, -kBeta);                           \
            StepAtT(k - 4, 1, -kAlpha, -kAlpha);                         \
        } else if (WAVELET == MCD_WAVELET_LEGALL53) {                    \
            StepAtT(k - 1, 0, -0.25, -0.25);                             \
            StepAtT(k - 2, 1, 0.5, 0.5);                                 \
        } else {                                                         \
            StepAtT(k - 1, 0, 0.0, -0.5);                                \
            StepAtT(k - 2, 1, 1.0, 0.0);                                 \
        }                                                                \
    }

MCD_LINE_LIFTING(float, line, StepAt, ForwardAt, InverseAt)
