#include "cpu_reference/awr_reconstruct.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "cpu_reference/wavelet_analyze.h"
#include "cpu_reference/wavelet_sqanalyze.h"
#include "cpu_reference/wavelet_synthesize.h"

namespace mcd::ref {

Image AwrShrink(const Image &coefficients, const Image &variance, int lowWidth, int lowHeight,
                double cs) {
    Image out = coefficients;
    for (int c = 0; c < out.channels; ++c)
        for (int y = 0; y < out.height; ++y)
            for (int x = 0; x < out.width; ++x) {
                if (x < lowWidth && y < lowHeight) continue;
                double w = coefficients.At(c, y, x);
                double delta = std::sqrt(double(variance.At(c, y, x)));
                double magnitude = std::max(0.0, std::fabs(w) - cs * delta);
                out.At(c, y, x) = float(w < 0 ? -magnitude : (w > 0 ? magnitude : 0.0));
            }
    return out;
}

Image AwrReconstruct(const Image &color, const Image &variance, WaveletBasis basis, int levels,
                     double cs, double lowSum, double highSum) {
    Image coefficients = WaveletAnalyze(color, basis, levels);
    Image coefficientVariance = WaveletSqAnalyze(variance, basis, levels, lowSum, highSum);
    Image shrunk =
        AwrShrink(coefficients, coefficientVariance, LevelExtent(color.width, levels),
                  LevelExtent(color.height, levels), cs);
    return WaveletSynthesize(shrunk, basis, levels);
}

Image AwrReconstructSpun(const Image &color, const Image &variance, WaveletBasis basis,
                         int levels, double cs, double lowSum, double highSum, int spins) {
    int w = color.width, h = color.height, channels = color.channels;
    std::vector<double> mean(color.Size(), 0.0);
    for (int dy = 0; dy < spins; ++dy)
        for (int dx = 0; dx < spins; ++dx) {
            Image shiftedColor(w + dx, h + dy, channels),
                shiftedVariance(w + dx, h + dy, channels);
            for (int c = 0; c < channels; ++c)
                for (int y = 0; y < h + dy; ++y)
                    for (int x = 0; x < w + dx; ++x) {
                        // Source pixel: mirrored across the top and left edges.
                        int sy = y - dy, sx = x - dx;
                        if (sy < 0) sy = std::min(-sy - 1, h - 1);
                        if (sx < 0) sx = std::min(-sx - 1, w - 1);
                        shiftedColor.At(c, y, x) = color.At(c, sy, sx);
                        shiftedVariance.At(c, y, x) = variance.At(c, sy, sx);
                    }
            Image out = AwrReconstruct(shiftedColor, shiftedVariance, basis, levels, cs, lowSum,
                                       highSum);
            for (int c = 0; c < channels; ++c)
                for (int y = 0; y < h; ++y)
                    for (int x = 0; x < w; ++x)
                        mean[(size_t(c) * h + y) * w + x] += out.At(c, y + dy, x + dx);
        }
    Image result(w, h, channels);
    for (size_t i = 0; i < mean.size(); ++i) result.data[i] = float(mean[i] / (spins * spins));
    return result;
}

Image AwrReconstruct(const Image &color, const Image &variance, const AwrParams &params,
                     std::vector<std::pair<std::string, Image>> *stages) {
    int levels =
        params.levels < 0 ? MaxWaveletLevels(color.width, color.height) : params.levels;
    const double cs = params.cs, renorm = params.renorm;
    bool anyVariance = false;
    for (float v : variance.data) anyVariance |= v > 0;
    // Shrinking by zero keeps every coefficient: no stage runs, the output is the input.
    if (!anyVariance || cs == 0 || levels == 0) return color;
    Image coefficients = WaveletAnalyze(color, params.basis, levels);
    Image coefficientVariance =
        WaveletSqAnalyze(variance, params.basis, levels, renorm, renorm);
    Image shrunk =
        AwrShrink(coefficients, coefficientVariance, LevelExtent(color.width, levels),
                  LevelExtent(color.height, levels), cs);
    Image out = WaveletSynthesize(shrunk, params.basis, levels);
    if (stages) {
        stages->emplace_back("analysis", std::move(coefficients));
        stages->emplace_back("variance analysis", std::move(coefficientVariance));
        stages->emplace_back("shrinkage", std::move(shrunk));
        stages->emplace_back("synthesis", out);
    }
    if (params.spins <= 1) return out;
    Image spun = AwrReconstructSpun(color, variance, params.basis, levels, cs, renorm, renorm,
                                    params.spins);
    if (stages) stages->emplace_back("cycle spinning", spun);
    return spun;
}

}  // namespace mcd::ref
