// Wavelet bases by number, shared by GLSL (specialization constant values) and C++.
#ifndef MCD_SHADERS_WAVELET_WAVELET_H
#define MCD_SHADERS_WAVELET_WAVELET_H

#define MCD_WAVELET_HAAR 0
#define MCD_WAVELET_LEGALL53 1
#define MCD_WAVELET_CDF97 2

#endif
