// Wavelet bases and the multi-level (Mallat) coefficient layout, shared by the GPU path,
// the CPU reference and the tests. This is layout, not algorithm.
//
// Layout: level k (0-based) transforms the top-left region of LevelExtent(w, k) x
// LevelExtent(h, k) of the coefficient image. Along an axis of length n > 1 the
// ceil(n/2) low-pass coefficients come first, then the floor(n/2) high-pass ones; an
// axis of length 1 is passed through unchanged. Rows are transformed before columns.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "wavelet/wavelet.h"

namespace mcd {

enum class WaveletBasis : int {
    Haar = MCD_WAVELET_HAAR,
    LeGall53 = MCD_WAVELET_LEGALL53,
    Cdf97 = MCD_WAVELET_CDF97,
};

inline int LevelExtent(int n, int level) {
    for (int k = 0; k < level; ++k) n = (n + 1) / 2;
    return n;
}

// Levels until both axes are down to one coefficient.
inline int MaxWaveletLevels(int width, int height) {
    int levels = 0;
    while (width > 1 || height > 1) {
        width = (width + 1) / 2;
        height = (height + 1) / 2;
        ++levels;
    }
    return levels;
}

inline const char *WaveletName(WaveletBasis basis) {
    switch (basis) {
        case WaveletBasis::Haar:
            return "haar";
        case WaveletBasis::LeGall53:
            return "legall53";
        case WaveletBasis::Cdf97:
            return "cdf97";
    }
    return "?";
}

inline std::optional<WaveletBasis> ParseWavelet(std::string_view name) {
    if (name == "haar") return WaveletBasis::Haar;
    if (name == "legall53" || name == "legall" || name == "5/3") return WaveletBasis::LeGall53;
    if (name == "cdf97" || name == "9/7" || name == "daubechies97") return WaveletBasis::Cdf97;
    return std::nullopt;
}

}  // namespace mcd
