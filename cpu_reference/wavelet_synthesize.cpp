#include "cpu_reference/wavelet_synthesize.h"

#include <algorithm>
#include <cmath>

namespace mcd::ref {

std::vector<double> Synthesize1D(std::span<const double> c, WaveletBasis basis,
                                 const FilterBank &bank) {
    int n = int(c.size());
    std::vector<double> x(c.begin(), c.end());
    if (n <= 1) return x;
    int nLow = (n + 1) / 2, nHigh = n / 2;
    std::span<const double> s = c.subspan(0, nLow), d = c.subspan(nLow, nHigh);
    const std::vector<double> &g0 = bank.synthesisLow, &g1 = bank.synthesisHigh;
    if (basis == WaveletBasis::Haar) {
        for (int i = 0; i < nHigh; ++i) {
            x[2 * i] = g0[0] * s[i] + g1[0] * d[i];
            x[2 * i + 1] = g0[1] * s[i] + g1[1] * d[i];
        }
        // The unpaired last sample had d = 0 (x[N] = x[N-1]).
        if (n % 2 == 1) x[n - 1] = g0[0] * s[nLow - 1];
        return x;
    }
    int lowRadius = int(g0.size()) - 1, highRadius = int(g1.size()) - 1;
    int radius = std::max(lowRadius, highRadius);
    for (int p = 0; p < n; ++p) {
        // Gather from the coefficients at positions q near p; s sits at even q, d at odd q.
        double sum = 0;
        for (int q = p - radius; q <= p + radius; ++q) {
            int distance = std::abs(p - q);
            int m = MirrorIndex(q, n);
            if ((q & 1) == 0) {
                if (distance <= lowRadius) sum += g0[distance] * s[m / 2];
            } else {
                if (distance <= highRadius) sum += g1[distance] * d[(m - 1) / 2];
            }
        }
        x[p] = sum;
    }
    return x;
}

std::vector<double> Synthesize1D(std::span<const double> c, WaveletBasis basis) {
    return Synthesize1D(c, basis, GetFilterBank(basis));
}

std::vector<double> SynthesizePlane(std::span<const double> coefficients, int width, int height,
                                    WaveletBasis basis, const FilterBank &bank, int levels) {
    CheckWaveletLevels(width, height, levels, "SynthesizePlane");
    std::vector<double> x(coefficients.begin(), coefficients.end());
    std::vector<double> line;
    for (int level = levels - 1; level >= 0; --level) {
        int w = LevelExtent(width, level), h = LevelExtent(height, level);
        // Undo the columns of the region, then its rows.
        if (h > 1) {
            for (int i = 0; i < w; ++i) {
                line.resize(h);
                for (int y = 0; y < h; ++y) line[y] = x[size_t(y) * width + i];
                std::vector<double> t = Synthesize1D(line, basis, bank);
                for (int y = 0; y < h; ++y) x[size_t(y) * width + i] = t[y];
            }
        }
        if (w > 1) {
            for (int y = 0; y < h; ++y) {
                line.assign(x.begin() + size_t(y) * width, x.begin() + size_t(y) * width + w);
                std::vector<double> t = Synthesize1D(line, basis, bank);
                std::copy(t.begin(), t.end(), x.begin() + size_t(y) * width);
            }
        }
    }
    return x;
}

std::vector<double> SynthesizePlane(std::span<const double> coefficients, int width, int height,
                                    WaveletBasis basis, int levels) {
    return SynthesizePlane(coefficients, width, height, basis, GetFilterBank(basis), levels);
}

Image SynthesizeImage(const Image &coefficients, WaveletBasis basis, const FilterBank &bank,
                      int levels) {
    const Image &in = coefficients;
    CheckWaveletLevels(in.width, in.height, levels, "SynthesizeImage");
    Image out(in.width, in.height, in.channels);
    for (int ch = 0; ch < in.channels; ++ch) {
        std::vector<double> plane(in.Plane(ch), in.Plane(ch) + in.PixelCount());
        std::vector<double> x =
            SynthesizePlane(plane, in.width, in.height, basis, bank, levels);
        std::transform(x.begin(), x.end(), out.Plane(ch), [](double v) { return float(v); });
    }
    return out;
}

Image WaveletSynthesize(const Image &coefficients, WaveletBasis basis, int levels) {
    CheckWaveletLevels(coefficients.width, coefficients.height, levels, "WaveletSynthesize");
    return SynthesizeImage(coefficients, basis, GetFilterBank(basis), levels);
}

Image WaveletSynthesizeMagnitude(const Image &coefficients, WaveletBasis basis, int levels) {
    CheckWaveletLevels(coefficients.width, coefficients.height, levels,
                       "WaveletSynthesizeMagnitude");
    Image absCoefficients = coefficients;
    for (float &v : absCoefficients.data) v = std::abs(v);
    return SynthesizeImage(absCoefficients, basis, AbsoluteFilterBank(GetFilterBank(basis)),
                           levels);
}

}  // namespace mcd::ref
