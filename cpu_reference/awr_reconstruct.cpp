#include "cpu_reference/awr_reconstruct.h"

#include <cmath>

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

}  // namespace mcd::ref
