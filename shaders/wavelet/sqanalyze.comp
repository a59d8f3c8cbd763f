#version 450
#extension GL_GOOGLE_include_directive : require

#include "wavelet/wavelet.h"
#include "wavelet/sqanalyze.h"

layout(local_size_x = WAVELET_LOCAL_SIZE) in;
layout(std430, binding = WAVELET_SQANALYZE_SRC) readonly buffer Src { float src[]; };
layout(std430, binding = WAVELET_SQANALYZE_COEF) writeonly buffer Coef { float coef[]; };
layout(std430, binding = WAVELET_SQANALYZE_LOW) writeonly buffer Low { float low[]; };

#include "wavelet/lifting.glsl"

// Analysis filter taps of AWR appendix A, centre first (symmetric).
const float kLow97[5] = float[5](0.6029490182363579 * kSqrt2, 0.2668641184428723 * kSqrt2,
                                 -0.07822326652898785 * kSqrt2, -0.01686411844287495 * kSqrt2,
                                 0.02674875741080976 * kSqrt2);
const float kHigh97[4] = float[4](1.115087052456994 / kSqrt2, -0.5912717631142470 / kSqrt2,
                                  -0.05754352622849957 / kSqrt2, 0.09127176311424948 / kSqrt2);
const float kLow53[3] = float[3](0.75 * kSqrt2, 0.25 * kSqrt2, -0.125 * kSqrt2);
const float kHigh53[2] = float[2](-1.0 / kSqrt2, 0.5 / kSqrt2);

shared float rows[kExt * kExt];

float LowTapSq(int k) {
    if (WAVELET == MCD_WAVELET_CDF97) return k < 5 ? kLow97[k] * kLow97[k] : 0.0;
    if (WAVELET == MCD_WAVELET_LEGALL53) return k < 3 ? kLow53[k] * kLow53[k] : 0.0;
    return k < 1 ? 0.5 : 0.0;
}
float HighTapSq(int k) {
    if (WAVELET == MCD_WAVELET_CDF97) return k < 4 ? kHigh97[k] * kHigh97[k] : 0.0;
    if (WAVELET == MCD_WAVELET_LEGALL53) return k < 2 ? kHigh53[k] * kHigh53[k] : 0.0;
    return k < 1 ? 0.5 : 0.0;
}

// Factor that makes the squared taps sum to `target` (<= 0: leave them as they are).
float Renormalise(float target, bool lowPass) {
    if (target <= 0.0) return 1.0;
    float sum = 0.0;
    for (int k = 0; k <= WAVELET_HALO; ++k) {
        float t = lowPass ? LowTapSq(k) : HighTapSq(k);
        sum += k == 0 ? t : 2.0 * t;
    }
    // Haar has two taps of 1/2: the loop above counts one centre tap, so double it.
    if (WAVELET == MCD_WAVELET_HAAR) sum = 1.0;
    return target / sum;
}

// Squared-tap convolution of one position of parity p; `at` is its tile index and
// `step` the index distance between neighbours along the axis.
float Convolve(int at, int step, int parity, float lowScale, float highScale, bool fromRows) {
    if (WAVELET == MCD_WAVELET_HAAR) {
        // Pairs (2n, 2n+1); each sample of the pair gets weight 1/2.
        int pair = parity == 0 ? at + step : at - step;
        float a = fromRows ? rows[at] : tile[at];
        float b = fromRows ? rows[pair] : tile[pair];
        return 0.5 * (a + b) * (parity == 0 ? lowScale : highScale);
    }
    // Only the filter's own taps: a zero tap times a NaN neighbour would leak the NaN.
    int reach = parity == 0 ? (WAVELET == MCD_WAVELET_CDF97 ? 4 : 2)
                            : (WAVELET == MCD_WAVELET_CDF97 ? 3 : 1);
    float sum = 0.0;
    for (int k = -reach; k <= reach; ++k) {
        float t = parity == 0 ? LowTapSq(abs(k)) : HighTapSq(abs(k));
        float v = fromRows ? rows[at + k * step] : tile[at + k * step];
        sum += t * v;
    }
    return sum * (parity == 0 ? lowScale : highScale);
}

void main() {
    int lid = int(gl_LocalInvocationIndex);
    int channel = int(gl_WorkGroupID.z);
    ivec2 block = ivec2(gl_WorkGroupID.xy) * WAVELET_TILE;
    ivec2 origin = block - WAVELET_HALO;
    bool liftX = push.width > 1, liftY = push.height > 1;
    float lowScale = Renormalise(push.lowSum, true);
    float highScale = Renormalise(push.highSum, false);

    int srcBase = channel * push.srcPlane;
    for (int i = lid; i < kExt * kExt; i += kLocal) {
        int ty = i / kExt, tx = i - ty * kExt;
        int x = MirrorAnalysis(origin.x + tx, push.width);
        int y = MirrorAnalysis(origin.y + ty, push.height);
        tile[i] = src[srcBase + y * push.srcStride + x];
    }
    barrier();

    // Rows: every tile row, block columns, into `rows`.
    for (int i = lid; i < kExt * WAVELET_TILE; i += kLocal) {
        int ty = i / WAVELET_TILE, tx = WAVELET_HALO + i % WAVELET_TILE;
        int at = ty * kExt + tx;
        rows[at] = liftX ? Convolve(at, 1, tx & 1, lowScale, highScale, false) : tile[at];
    }
    barrier();

    // Columns of the block, then the write into the bands.
    for (int i = lid; i < WAVELET_TILE * WAVELET_TILE; i += kLocal) {
        int ly = i / WAVELET_TILE, lx = i - ly * WAVELET_TILE;
        int px = block.x + lx, py = block.y + ly;
        if (px >= push.width || py >= push.height) continue;
        int at = (ly + WAVELET_HALO) * kExt + lx + WAVELET_HALO;
        float v = liftY ? Convolve(at, kExt, py & 1, lowScale, highScale, true) : rows[at];
        bool lowX = !liftX || (px & 1) == 0, lowY = !liftY || (py & 1) == 0;
        int bx = BandIndex(px, push.width), by = BandIndex(py, push.height);
        if (lowX && lowY)
            low[channel * push.lowPlane + by * push.lowStride + bx] = v;
        else
            coef[channel * push.coefPlane + by * push.coefStride + bx] = v;
    }
}
