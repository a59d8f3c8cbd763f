#include "cpu_reference/wavelet_sqanalyze.h"

#include "cpu_reference/wavelet_analyze.h"
#include "cpu_reference/wavelet_filters.h"

namespace mcd::ref {

Image WaveletSqAnalyze(const Image &variance, WaveletBasis basis, int levels, double lowSum,
                       double highSum) {
    CheckWaveletLevels(variance.width, variance.height, levels, "WaveletSqAnalyze");
    FilterBank squared = SquaredFilterBank(GetFilterBank(basis), basis, lowSum, highSum);
    return AnalyzeImage(variance, basis, squared, levels);
}

}  // namespace mcd::ref
