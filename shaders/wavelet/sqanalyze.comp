#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "wavelet/wavelet.h"
#include "wavelet/sqanalyze.h"

layout(local_size_x = WAVELET_LOCAL_SIZE) in;
layout(std430, binding = WAVELET_SQANALYZE_SRC) readonly buffer Src { float src[]; };
layout(std430, binding = WAVELET_SQANALYZE_COEF) writeonly buffer Coef { float coef[]; };
layout(std430, binding = WAVELET_SQANALYZE_LOW) writeonly buffer Low { float low[]; };

#include "wavelet/lifting.glsl"

// Transpose between the row and column passes: [row][column] of the tile.
shared float tile[kExt * kExt];

// Analysis filter taps of AWR appendix A, centre first (symmetric).
const float kLow97[5] = float[5](0.6029490182363579 * kSqrt2, 0.2668641184428723 * kSqrt2,
                                 -0.07822326652898785 * kSqrt2, -0.01686411844287495 * kSqrt2,
                                 0.02674875741080976 * kSqrt2);
const float kHigh97[4] = float[4](1.115087052456994 / kSqrt2, -0.5912717631142470 / kSqrt2,
                                  -0.05754352622849957 / kSqrt2, 0.09127176311424948 / kSqrt2);
const float kLow53[3] = float[3](0.75 * kSqrt2, 0.25 * kSqrt2, -0.125 * kSqrt2);
const float kHigh53[2] = float[2](-1.0 / kSqrt2, 0.5 / kSqrt2);

float LowTapSq(int k) {
    if (WAVELET == MCD_WAVELET_CDF97) return kLow97[k] * kLow97[k];
    if (WAVELET == MCD_WAVELET_LEGALL53) return kLow53[k] * kLow53[k];
    return 0.5;
}
float HighTapSq(int k) {
    if (WAVELET == MCD_WAVELET_CDF97) return kHigh97[k] * kHigh97[k];
    if (WAVELET == MCD_WAVELET_LEGALL53) return kHigh53[k] * kHigh53[k];
    return 0.5;
}
// Half-lengths of the filters: taps at offsets -reach..reach.
const int kLowReach = WAVELET == MCD_WAVELET_CDF97 ? 4 : (WAVELET == MCD_WAVELET_LEGALL53 ? 2 : 0);
const int kHighReach = WAVELET == MCD_WAVELET_CDF97 ? 3 : (WAVELET == MCD_WAVELET_LEGALL53 ? 1 : 0);

// Factor that makes the squared taps sum to `target` (<= 0: leave them as they are).
float Renormalise(float target, bool lowPass) {
    if (target <= 0.0) return 1.0;
    // Haar: two taps of 1/2.
    if (WAVELET == MCD_WAVELET_HAAR) return target;
    int reach = lowPass ? kLowReach : kHighReach;
    float sum = 0.0;
    [[unroll]] for (int k = -reach; k <= reach; ++k) sum += lowPass ? LowTapSq(abs(k)) : HighTapSq(abs(k));
    return target / sum;
}

// Squared-tap convolution of the line at k (parity of k = parity of the position). Only
// the filter's own taps: a zero tap times a NaN neighbour would leak the NaN.
float Convolve(int k, float lowScale, float highScale) {
    if (WAVELET == MCD_WAVELET_HAAR) {
        // Pairs (2n, 2n+1); each sample of the pair weighs 1/2.
        int pair = (k & 1) == 0 ? k + 1 : k - 1;
        return 0.5 * (line[k] + line[pair]) * ((k & 1) == 0 ? lowScale : highScale);
    }
    float sum = 0.0;
    if ((k & 1) == 0) {
        [[unroll]] for (int j = -kLowReach; j <= kLowReach; ++j) sum += LowTapSq(abs(j)) * line[k + j];
        return sum * lowScale;
    }
    [[unroll]] for (int j = -kHighReach; j <= kHighReach; ++j) sum += HighTapSq(abs(j)) * line[k + j];
    return sum * highScale;
}

void main() {
    int lane = int(gl_LocalInvocationIndex);
    int channel = int(gl_WorkGroupID.z);
    ivec2 block = ivec2(gl_WorkGroupID.xy) * WAVELET_TILE;
    ivec2 origin = block - WAVELET_HALO;
    bool liftX = push.width > 1, liftY = push.height > 1;
    float lowScale = Renormalise(push.lowSum, true);
    float highScale = Renormalise(push.highSum, false);

    // Rows: invocation `lane` convolves tile row `lane` at the block's columns.
    int y = MirrorAnalysis(origin.y + lane, push.height);
    int rowBase = channel * push.srcPlane + y * push.srcStride;
    [[unroll]] for (int k = 0; k < kExt; ++k) line[k] = src[rowBase + MirrorAnalysis(origin.x + k, push.width)];
    [[unroll]] for (int k = WAVELET_HALO; k < WAVELET_HALO + WAVELET_TILE; ++k)
        tile[lane * kExt + k] = liftX ? Convolve(k, lowScale, highScale) : line[k];
    barrier();

    // Columns: invocation `lane` convolves block column `lane` and writes the bands.
    int px = block.x + lane;
    if (lane >= WAVELET_TILE || px >= push.width) return;
    [[unroll]] for (int k = 0; k < kExt; ++k) line[k] = tile[k * kExt + WAVELET_HALO + lane];
    bool lowX = !liftX || (px & 1) == 0;
    int bx = BandIndex(px, push.width);
    [[unroll]] for (int k = 0; k < WAVELET_TILE; ++k) {
        int py = block.y + k;
        if (py >= push.height) break;
        float v = liftY ? Convolve(WAVELET_HALO + k, lowScale, highScale) : line[WAVELET_HALO + k];
        bool lowY = !liftY || (py & 1) == 0;
        int by = BandIndex(py, push.height);
        if (lowX && lowY)
            low[channel * push.lowPlane + by * push.lowStride + bx] = v;
        else
            coef[channel * push.coefPlane + by * push.coefStride + bx] = v;
    }
}
