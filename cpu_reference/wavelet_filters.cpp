#include "cpu_reference/wavelet_filters.h"

#include <cmath>
#include <cstdlib>

#include <fmt/format.h>

#include "host/error.h"

namespace mcd::ref {

namespace {

constexpr double kSqrt2 = 1.41421356237309504880;

// CDF 9/7 with DC gain 1, as AWR appendix A prints it to 6 digits (index 0 = centre).
// These are the exact values to double precision, from the closed form: low-pass =
// cos^4(w/2) (1 + a y + b y^2), synthesis-side low-pass / 2 = cos^4(w/2) (1 - y / r),
// y = sin^2(w/2), r the real root of 1 + 4y + 10y^2 + 20y^3 (a = 4 + 1/r, b = 10 + a/r).
// The often quoted JPEG2000 values (0.6029490182363579, ...) differ by up to 6e-15.
const double kCdf97Low[5] = {0.6029490182363603482, 0.2668641184428749544,
                             -0.07822326652899026251, -0.01686411844287495443,
                             0.02674875741081008841};
const double kCdf97High[4] = {1.115087052457000365, -0.5912717631142500911,
                              -0.05754352622850018230, 0.09127176311425009115};

std::vector<double> Scaled(double scale, std::initializer_list<double> taps) {
    std::vector<double> result;
    for (double t : taps) result.push_back(scale * t);
    return result;
}

FilterBank MakeHaar() {
    double r = 1 / kSqrt2;
    return FilterBank{{r, r}, {-r, r}, {r, r}, {-r, r}};
}

FilterBank MakeLeGall53() {
    // Appendix A, including its sign of the high-pass pair.
    return FilterBank{Scaled(kSqrt2 / 8, {6, 2, -1}), Scaled(1 / kSqrt2 / 2, {-2, 1}),
                      Scaled(1 / kSqrt2 / 2, {2, 1}), Scaled(kSqrt2 / 8, {-6, 2, 1})};
}

FilterBank MakeCdf97() {
    const double *l = kCdf97Low, *h = kCdf97High;
    return FilterBank{Scaled(kSqrt2, {l[0], l[1], l[2], l[3], l[4]}),
                      Scaled(1 / kSqrt2, {h[0], h[1], h[2], h[3]}),
                      Scaled(1 / kSqrt2, {h[0], -h[1], h[2], -h[3]}),
                      Scaled(kSqrt2, {l[0], -l[1], l[2], -l[3], l[4]})};
}

std::vector<double> SquaredTaps(const std::vector<double> &taps, WaveletBasis basis,
                                double targetSum) {
    std::vector<double> result;
    for (double t : taps) result.push_back(t * t);
    if (targetSum > 0) {
        double scale = targetSum / FullFilterSum(result, basis);
        for (double &t : result) t *= scale;
    }
    return result;
}

}  // namespace

const FilterBank &GetFilterBank(WaveletBasis basis) {
    static const FilterBank haar = MakeHaar();
    static const FilterBank leGall53 = MakeLeGall53();
    static const FilterBank cdf97 = MakeCdf97();
    switch (basis) {
        case WaveletBasis::Haar:
            return haar;
        case WaveletBasis::LeGall53:
            return leGall53;
        case WaveletBasis::Cdf97:
            return cdf97;
    }
    throw Error(fmt::format("GetFilterBank: unknown wavelet basis {}", int(basis)),
                ErrorKind::InvalidArgument);
}

double FullFilterSum(const std::vector<double> &taps, WaveletBasis basis) {
    double sum = 0;
    for (size_t k = 0; k < taps.size(); ++k) {
        // Half filters count every tap but the centre twice.
        bool twice = basis != WaveletBasis::Haar && k > 0;
        sum += twice ? 2 * taps[k] : taps[k];
    }
    return sum;
}

FilterBank AbsoluteFilterBank(const FilterBank &bank) {
    auto abs = [](std::vector<double> taps) {
        for (double &t : taps) t = std::abs(t);
        return taps;
    };
    return FilterBank{abs(bank.analysisLow), abs(bank.analysisHigh), abs(bank.synthesisLow),
                      abs(bank.synthesisHigh)};
}

FilterBank SquaredFilterBank(const FilterBank &bank, WaveletBasis basis, double lowSum,
                             double highSum) {
    return FilterBank{SquaredTaps(bank.analysisLow, basis, lowSum),
                      SquaredTaps(bank.analysisHigh, basis, highSum),
                      SquaredTaps(bank.synthesisLow, basis, 0),
                      SquaredTaps(bank.synthesisHigh, basis, 0)};
}

int MirrorIndex(int p, int n) {
    if (n < 2) return 0;
    // Reflect about 0 and about n-1 until p lands inside.
    for (;;) {
        p = std::abs(p);
        if (p <= n - 1) return p;
        p = 2 * (n - 1) - p;
    }
}

void CheckWaveletLevels(int width, int height, int levels, const char *caller) {
    int maxLevels = MaxWaveletLevels(width, height);
    if (levels < 0 || levels > maxLevels)
        throw Error(fmt::format("{}: {} levels requested for a {}x{} image (0..{} allowed)",
                                caller, levels, width, height, maxLevels),
                    ErrorKind::InvalidArgument);
}

}  // namespace mcd::ref
