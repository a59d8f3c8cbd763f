#include "cpu_reference/wavelet_analyze.h"

#include <algorithm>
#include <cmath>

namespace mcd::ref {

namespace {

// Symmetric half filter `taps` centred on sample `centre`, whole-sample symmetric extension.
double ConvolveAt(const std::vector<double> &taps, std::span<const double> x, int centre) {
    int n = int(x.size());
    int radius = int(taps.size()) - 1;
    double sum = 0;
    for (int k = -radius; k <= radius; ++k)
        sum += taps[std::abs(k)] * x[MirrorIndex(centre + k, n)];
    return sum;
}

}  // namespace

std::vector<double> Analyze1D(std::span<const double> x, WaveletBasis basis,
                              const FilterBank &bank) {
    int n = int(x.size());
    std::vector<double> out(x.begin(), x.end());
    if (n <= 1) return out;
    int nLow = (n + 1) / 2, nHigh = n / 2;
    const std::vector<double> &h0 = bank.analysisLow, &h1 = bank.analysisHigh;
    if (basis == WaveletBasis::Haar) {
        // Pairs (2i, 2i+1); an unpaired last sample is its own partner (x[N] = x[N-1]).
        for (int i = 0; i < nLow; ++i) {
            int a = 2 * i, b = std::min(2 * i + 1, n - 1);
            out[i] = h0[0] * x[a] + h0[1] * x[b];
        }
        for (int i = 0; i < nHigh; ++i) out[nLow + i] = h1[0] * x[2 * i] + h1[1] * x[2 * i + 1];
        return out;
    }
    for (int i = 0; i < nLow; ++i) out[i] = ConvolveAt(h0, x, 2 * i);
    for (int i = 0; i < nHigh; ++i) out[nLow + i] = ConvolveAt(h1, x, 2 * i + 1);
    return out;
}

std::vector<double> Analyze1D(std::span<const double> x, WaveletBasis basis) {
    return Analyze1D(x, basis, GetFilterBank(basis));
}

std::vector<double> AnalyzePlane(std::span<const double> plane, int width, int height,
                                 WaveletBasis basis, const FilterBank &bank, int levels) {
    CheckWaveletLevels(width, height, levels, "AnalyzePlane");
    std::vector<double> c(plane.begin(), plane.end());
    std::vector<double> line;
    for (int level = 0; level < levels; ++level) {
        int w = LevelExtent(width, level), h = LevelExtent(height, level);
        // Transform the rows of the region, then its columns.
        if (w > 1) {
            for (int y = 0; y < h; ++y) {
                line.assign(c.begin() + size_t(y) * width, c.begin() + size_t(y) * width + w);
                std::vector<double> t = Analyze1D(line, basis, bank);
                std::copy(t.begin(), t.end(), c.begin() + size_t(y) * width);
            }
        }
        if (h > 1) {
            for (int x = 0; x < w; ++x) {
                line.resize(h);
                for (int y = 0; y < h; ++y) line[y] = c[size_t(y) * width + x];
                std::vector<double> t = Analyze1D(line, basis, bank);
                for (int y = 0; y < h; ++y) c[size_t(y) * width + x] = t[y];
            }
        }
    }
    return c;
}

std::vector<double> AnalyzePlane(std::span<const double> plane, int width, int height,
                                 WaveletBasis basis, int levels) {
    return AnalyzePlane(plane, width, height, basis, GetFilterBank(basis), levels);
}

Image AnalyzeImage(const Image &in, WaveletBasis basis, const FilterBank &bank, int levels) {
    CheckWaveletLevels(in.width, in.height, levels, "AnalyzeImage");
    Image out(in.width, in.height, in.channels);
    for (int ch = 0; ch < in.channels; ++ch) {
        std::vector<double> plane(in.Plane(ch), in.Plane(ch) + in.PixelCount());
        std::vector<double> c = AnalyzePlane(plane, in.width, in.height, basis, bank, levels);
        std::transform(c.begin(), c.end(), out.Plane(ch), [](double v) { return float(v); });
    }
    return out;
}

Image WaveletAnalyze(const Image &in, WaveletBasis basis, int levels) {
    CheckWaveletLevels(in.width, in.height, levels, "WaveletAnalyze");
    return AnalyzeImage(in, basis, GetFilterBank(basis), levels);
}

Image WaveletAnalyzeMagnitude(const Image &in, WaveletBasis basis, int levels) {
    CheckWaveletLevels(in.width, in.height, levels, "WaveletAnalyzeMagnitude");
    Image absIn = in;
    for (float &v : absIn.data) v = std::abs(v);
    return AnalyzeImage(absIn, basis, AbsoluteFilterBank(GetFilterBank(basis)), levels);
}

}  // namespace mcd::ref
