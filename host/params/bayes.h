// Bayesian wavelet shrinkage's parameters (Xu & Pattanaik, section 4), as the GPU pipeline
// (host/methods/bayes.h), the front end (host/api/method_bayes.cpp) and the CPU reference
// (cpu_reference/bayes_denoise.h) read them: a layout, like a kernel's push-constant
// header. The initializers are the defaults the command line shows; the paper's own
// pipeline (the DWT, a fixed s_n) is tests/harness/bayes_paper.h.
#pragma once

#include "host/wavelet.h"

namespace mcd {

// The wavelet transform the shrinkage runs in: the foundation's decimated DWT (Mallat
// layout), or the stationary (undecimated, "a trous") transform of host/wavelet/swt.h:
// shift-invariant, 3 levels + 1 full-size planes per channel.
enum class BayesTransform { Dwt, Swt };

// Where every band's noise s comes from.
enum class BayesNoise {
    // The variance layer when the run is given one (Variance), else the data (Mad). It beat
    // the paper's fixed s_n in every row of cornell/interior at 4/16/64 spp (README).
    Auto,
    Fixed,  // the paper: sn, and hpFactor x sn at the finest level
    // The finest level's s from the data: the median absolute deviation of the finest HH
    // bands, all channels pooled, through the generalised Laplacian of shape pn; then
    // sn = that / hpFactor.
    Mad,
    // Beyond the paper: every band's s from the per-pixel variance of the mean
    // (BayesVarianceNoise); hpFactor and sn are then unused.
    Variance,
};

struct BayesParams {
    WaveletBasis basis = WaveletBasis::Haar;
    // swt: measured better than the paper's DWT on every cornell/interior frame (README).
    BayesTransform transform = BayesTransform::Swt;
    int levels = 3;          // clamped to what the image allows
    float sn = 0.19f;        // noise s (the paper's "cabin" example)
    float pn = 1.5f;         // noise shape p
    float hpFactor = 2.f;    // the finest level's noise s is hpFactor * sn (paper: 2)
    float floorRel = 1e-3f;  // log floor: floorRel times the channel's median positive value
    BayesNoise noise = BayesNoise::Auto;
    // Exact zeros come out exactly 0 (the paper's black stays black). Off (the default):
    // they are denoised like any pixel (from the log floor) and the local mean restores
    // their share: at low spp most zeros are noise, and kept they left black holes in
    // indirect light (issue 29; measured in docs/methods/bayes.md).
    bool restoreZeros = false;
    // Beyond the paper: scale each channel so its mean equals the input's (mean of the
    // finite, non-negative input values), undoing the log domain's pull toward the
    // geometric mean.
    bool keepMean = false;
    // Beyond the paper: restore the input's local means (0: off). Each output value is
    // multiplied by m_in / m_out, the means of the input's finite values >= 0 and of the
    // output over a tent window of radius 2 x meanRadius (a box of radius meanRadius twice,
    // each clipped to the image), where both are positive and finite. The log domain
    // estimates a geometric mean, below the mean by as much as the local noise is relative
    // to the signal: dark, noisy areas darken most. After keepMean.
    int meanRadius = 8;
    // Shift invariance by cycle spinning (Coifman & Donoho): the average of the method
    // over the spins x spins shifts (dx, dy) in [0, spins)^2, each made by padding the
    // image at the top left by mirroring (x -> -x-1) and cropping back. 1: off.
    int spins = 1;
    // Shrink the orthonormal opponent transform of the log channels (log luminance, two
    // log chroma) instead of log R, G, B. Needs 3 channels.
    bool opponent = false;
};

}  // namespace mcd
