// Filter taps and boundary folding of the stationary wavelet kernels (swt_analyze.comp,
// swt_synthesize.comp), written for the GPU from AWR appendix A (the CPU reference has its
// own copy in double). Include after the kernel's layout declarations.
#ifndef MCD_SHADERS_WAVELET_SWT_GLSL
#define MCD_SHADERS_WAVELET_SWT_GLSL

layout(constant_id = WAVELET_SWT_SPEC_BASIS) const int WAVELET = MCD_WAVELET_CDF97;
layout(constant_id = WAVELET_SWT_SPEC_AXIS) const int AXIS = WAVELET_SWT_ROWS;

const float kSqrt2 = 1.4142135623730951;
const float kHaar = 0.70710678118654752;  // 1 / sqrt 2

// CDF 9/7 with DC gain 1 (centre first); the bank scales them by sqrt 2 and 1 / sqrt 2.
const float kCdfLow[5] = float[5](0.60294901823636035, 0.26686411844287495,
                                  -0.078223266528990263, -0.016864118442874954,
                                  0.026748757410810088);
const float kCdfHigh[4] = float[4](1.1150870524570004, -0.59127176311425009,
                                   -0.057543526228500182, 0.091271763114250091);

// Reaches (half lengths) of the analysis and synthesis filters.
const int kLowReach = WAVELET == MCD_WAVELET_CDF97 ? 4 : (WAVELET == MCD_WAVELET_LEGALL53 ? 2 : 0);
const int kHighReach = WAVELET == MCD_WAVELET_CDF97 ? 3 : (WAVELET == MCD_WAVELET_LEGALL53 ? 1 : 0);
const int kSynthLowReach = kHighReach;
const int kSynthHighReach = kLowReach;

// Tap k >= 0 of the analysis low and high filters, synthesis low and high filters.
float AnalysisLow(int k) {
    if (WAVELET == MCD_WAVELET_CDF97) return kSqrt2 * kCdfLow[k];
    return kSqrt2 * (k == 0 ? 0.75 : (k == 1 ? 0.25 : -0.125));
}
float AnalysisHigh(int k) {
    if (WAVELET == MCD_WAVELET_CDF97) return kHaar * kCdfHigh[k];
    return kHaar * (k == 0 ? -1.0 : 0.5);
}
float SynthesisLow(int k) {
    if (WAVELET == MCD_WAVELET_CDF97) return kHaar * ((k & 1) == 0 ? kCdfHigh[k] : -kCdfHigh[k]);
    return kHaar * (k == 0 ? 1.0 : 0.5);
}
float SynthesisHigh(int k) {
    if (WAVELET == MCD_WAVELET_CDF97) return kSqrt2 * ((k & 1) == 0 ? kCdfLow[k] : -kCdfLow[k]);
    return kSqrt2 * (k == 0 ? -0.75 : (k == 1 ? 0.25 : 0.125));
}

// Fold: MirrorAnalysis, whole-sample symmetric for 5/3 and 9/7, half-sample for Haar.
#include "wavelet/fold.glsl"

#endif
