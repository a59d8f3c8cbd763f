// Adaptive Wavelet Rendering's parameters (Overbeck et al.): the reconstruction's (section
// 4.2), as the GPU pipeline (host/methods/awr.h), the front end (host/api/method_awr.cpp)
// and the CPU reference (cpu_reference/awr_reconstruct.h) read them, and the adaptive
// sampler's (section 4.1), as the renderer (tools/render/adaptive.h) and `mcdenoise render`
// read them. A layout, like a kernel's push-constant header; the initializers are the
// defaults the command line shows.
#pragma once

#include "host/wavelet.h"

namespace mcd {

struct AwrParams {
    WaveletBasis basis = WaveletBasis::Cdf97;
    int levels = -1;  // -1: as many as the image allows
    float cs = 1.f;   // smoothing constant c_s (eq. 11)
    // The squared 1D low- and high-pass filters of the variance DWT (eq. 10) are
    // renormalised to sum to this (the paper: 2^-1/2 for the reconstruction, to damp
    // coarse-scale smoothing).
    float renorm = 0.70710678f;
    // Cycle spinning over spins x spins shifts (host/common/cycle_spin.h), 1 to 8; 1 is
    // the paper's reconstruction. Beyond the paper: the decimated DWT's soft shrinkage
    // depends on where its grid falls, and the mean over shifts removes that (README).
    // 4: with the paper's 1 the shrinkage's blocks left awr worse than its input on our
    // cornell and on real frames with small lights (issue 29).
    int spins = 4;
};

struct AwrSamplerParams {
    int initialSpp = 4;  // uniform samples per pixel before the first round
    int maxLevel = 5;    // scale coefficients of levels 0..maxLevel are ranked
    WaveletBasis basis = WaveletBasis::Cdf97;
    // Sum of the squared 1D low-pass filter in the priorities' variance DWT (eq. 9); each
    // level multiplies a smooth variance by its square, tilting pops toward coarse levels.
    // Not the paper's 1.05, which sends every sample to level 0 on smooth noise; 1.2 serves
    // edges from fine levels and smooth noise from coarse ones (README, the sampler).
    float lowSum = 1.2f;
    // Luminance floor f of the sampler's contrast (eq. 5): (Imax - Imin)^2 / ((Imax + Imin)^2
    // + (2f)^2). Mitchell's contrast (f = 0) is scale-free, so a shadow pixel with samples
    // 0 and 0.001 ranks with the brightest edge; the floor makes it the range relative to
    // sqrt(mean^2 + f^2), the denominator of relMSE (f = 0.1: eps 0.01); measured in
    // docs/methods/awr.md (the adaptive sampler).
    float contrastFloor = 0.1f;
};

}  // namespace mcd
