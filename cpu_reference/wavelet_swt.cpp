#include "cpu_reference/wavelet_swt.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "host/error.h"
#include "wavelet/swt.h"

namespace mcd::ref {

bool SwtAxisTransformed(int n, int level) {
    long spacing = 1;
    for (int j = 0; j < level && spacing < n; ++j) spacing *= 2;
    return spacing < n;
}

namespace {

// Half-sample symmetric extension (period 2n), Haar's: -1 -> 0, n -> n-1.
int HalfMirror(int p, int n) {
    for (;;) {
        if (p < 0)
            p = -1 - p;
        else if (p >= n)
            p = 2 * n - 1 - p;
        else
            return p;
    }
}

using Planes = std::vector<std::vector<double>>;

// Column `x` of a width x height plane, and back.
std::vector<double> Column(const std::vector<double> &plane, int width, int height, int x) {
    std::vector<double> column(height);
    for (int y = 0; y < height; ++y) column[y] = plane[size_t(y) * width + x];
    return column;
}
void SetColumn(std::vector<double> *plane, int width, const std::vector<double> &column,
               int x) {
    for (size_t y = 0; y < column.size(); ++y) (*plane)[y * width + x] = column[y];
}

}  // namespace

void SwtAnalyze1D(std::span<const double> x, WaveletBasis basis, const FilterBank &bank,
                  int step, bool transform, std::vector<double> *low,
                  std::vector<double> *high) {
    int n = int(x.size());
    low->assign(x.begin(), x.end());
    high->assign(n, 0.0);
    if (!transform) return;
    const std::vector<double> &h0 = bank.analysisLow, &h1 = bank.analysisHigh;
    for (int i = 0; i < n; ++i) {
        if (basis == WaveletBasis::Haar) {
            // The pair (i, i + step), as the DWT's pair (2n, 2n + 1).
            double a = x[i], b = x[HalfMirror(i + step, n)];
            (*low)[i] = h0[0] * a + h0[1] * b;
            (*high)[i] = h1[0] * a + h1[1] * b;
            continue;
        }
        double l = 0, h = 0;
        int r0 = int(h0.size()) - 1, r1 = int(h1.size()) - 1;
        for (int k = -r0; k <= r0; ++k) l += h0[std::abs(k)] * x[MirrorIndex(i + k * step, n)];
        for (int k = -r1; k <= r1; ++k) h += h1[std::abs(k)] * x[MirrorIndex(i + k * step, n)];
        (*low)[i] = l;
        (*high)[i] = h;
    }
}

std::vector<double> SwtSynthesize1D(std::span<const double> low, std::span<const double> high,
                                    WaveletBasis basis, const FilterBank &bank, int step,
                                    bool transform) {
    int n = int(low.size());
    std::vector<double> x(low.begin(), low.end());
    if (!transform) return x;
    const std::vector<double> &g0 = bank.synthesisLow, &g1 = bank.synthesisHigh;
    for (int m = 0; m < n; ++m) {
        if (basis == WaveletBasis::Haar) {
            // m as the first sample of the pair at m; as the second of the pair at m - step.
            double first = g0[0] * low[m] + g1[0] * high[m];
            if (m < step) {
                x[m] = first;
            } else {
                double second = g0[1] * low[m - step] + g1[1] * high[m - step];
                x[m] = 0.5 * (first + second);
            }
            continue;
        }
        double sum = 0;
        int r0 = int(g0.size()) - 1, r1 = int(g1.size()) - 1;
        for (int k = -r0; k <= r0; ++k)
            sum += g0[std::abs(k)] * low[MirrorIndex(m - k * step, n)];
        for (int k = -r1; k <= r1; ++k)
            sum += g1[std::abs(k)] * high[MirrorIndex(m - k * step, n)];
        x[m] = 0.5 * sum;
    }
    return x;
}

std::vector<std::vector<double>> SwtAnalyzePlane(std::span<const double> plane, int width,
                                                 int height, WaveletBasis basis,
                                                 const FilterBank &bank, int levels) {
    CheckWaveletLevels(width, height, levels, "SwtAnalyzePlane");
    size_t size = size_t(width) * height;
    Planes planes(shader::SwtPlaneCount(levels), std::vector<double>(size, 0.0));
    std::vector<double> current(plane.begin(), plane.end());
    std::vector<double> low, high;
    for (int level = 0; level < levels; ++level) {
        int step = 1 << level;
        bool tx = SwtAxisTransformed(width, level);
        bool ty = SwtAxisTransformed(height, level);
        // Rows into a row-low and a row-high plane.
        std::vector<double> rowLow(size), rowHigh(size);
        for (int y = 0; y < height; ++y) {
            std::span<const double> row(current.data() + size_t(y) * width, width);
            SwtAnalyze1D(row, basis, bank, step, tx, &low, &high);
            std::copy(low.begin(), low.end(), rowLow.begin() + size_t(y) * width);
            std::copy(high.begin(), high.end(), rowHigh.begin() + size_t(y) * width);
        }
        // Columns: row-low -> LL, LH; row-high -> HL, HH.
        std::vector<double> &hl = planes[shader::SwtDetailPlane(level, 0)];
        std::vector<double> &lh = planes[shader::SwtDetailPlane(level, 1)];
        std::vector<double> &hh = planes[shader::SwtDetailPlane(level, 2)];
        std::vector<double> next(size);
        for (int x = 0; x < width; ++x) {
            SwtAnalyze1D(Column(rowLow, width, height, x), basis, bank, step, ty, &low, &high);
            SetColumn(&next, width, low, x);
            SetColumn(&lh, width, high, x);
            SwtAnalyze1D(Column(rowHigh, width, height, x), basis, bank, step, ty, &low, &high);
            SetColumn(&hl, width, low, x);
            SetColumn(&hh, width, high, x);
        }
        current = std::move(next);
    }
    planes[shader::SwtLowPlane(levels)] = std::move(current);
    return planes;
}

std::vector<double> SwtSynthesizePlane(const std::vector<std::vector<double>> &planes,
                                       int width, int height, WaveletBasis basis,
                                       const FilterBank &bank, int levels) {
    CheckWaveletLevels(width, height, levels, "SwtSynthesizePlane");
    if (int(planes.size()) != shader::SwtPlaneCount(levels))
        throw Error(
            fmt::format("SwtSynthesizePlane: {} planes for {} levels", planes.size(), levels),
            ErrorKind::Internal);
    size_t size = size_t(width) * height;
    std::vector<double> current = planes[shader::SwtLowPlane(levels)];
    for (int level = levels - 1; level >= 0; --level) {
        int step = 1 << level;
        bool tx = SwtAxisTransformed(width, level);
        bool ty = SwtAxisTransformed(height, level);
        const std::vector<double> &hl = planes[shader::SwtDetailPlane(level, 0)];
        const std::vector<double> &lh = planes[shader::SwtDetailPlane(level, 1)];
        const std::vector<double> &hh = planes[shader::SwtDetailPlane(level, 2)];
        // Columns: (LL, LH) -> row-low, (HL, HH) -> row-high; then rows.
        std::vector<double> rowLow(size), rowHigh(size);
        for (int x = 0; x < width; ++x) {
            SetColumn(&rowLow, width,
                      SwtSynthesize1D(Column(current, width, height, x),
                                      Column(lh, width, height, x), basis, bank, step, ty),
                      x);
            SetColumn(&rowHigh, width,
                      SwtSynthesize1D(Column(hl, width, height, x),
                                      Column(hh, width, height, x), basis, bank, step, ty),
                      x);
        }
        for (int y = 0; y < height; ++y) {
            std::span<const double> l(rowLow.data() + size_t(y) * width, width);
            std::span<const double> h(rowHigh.data() + size_t(y) * width, width);
            std::vector<double> row = SwtSynthesize1D(l, h, basis, bank, step, tx);
            std::copy(row.begin(), row.end(), current.begin() + size_t(y) * width);
        }
    }
    return current;
}

Image SwtAnalyzeImage(const Image &in, WaveletBasis basis, const FilterBank &bank, int levels) {
    CheckWaveletLevels(in.width, in.height, levels, "SwtAnalyzeImage");
    int count = shader::SwtPlaneCount(levels);
    Image out(in.width, in.height, in.channels * count);
    for (int c = 0; c < in.channels; ++c) {
        std::vector<double> plane(in.Plane(c), in.Plane(c) + in.PixelCount());
        Planes planes = SwtAnalyzePlane(plane, in.width, in.height, basis, bank, levels);
        for (int p = 0; p < count; ++p)
            std::transform(planes[p].begin(), planes[p].end(), out.Plane(c * count + p),
                           [](double v) { return float(v); });
    }
    return out;
}

Image WaveletSwtAnalyze(const Image &in, WaveletBasis basis, int levels) {
    return SwtAnalyzeImage(in, basis, GetFilterBank(basis), levels);
}

Image WaveletSwtSqAnalyze(const Image &variance, WaveletBasis basis, int levels) {
    return SwtAnalyzeImage(variance, basis, SquaredFilterBank(GetFilterBank(basis), basis),
                           levels);
}

Image WaveletSwtAnalyzeMagnitude(const Image &in, WaveletBasis basis, int levels) {
    Image absIn = in;
    for (float &v : absIn.data) v = std::abs(v);
    return SwtAnalyzeImage(absIn, basis, AbsoluteFilterBank(GetFilterBank(basis)), levels);
}

Image SwtSynthesizeImage(const Image &coefficients, WaveletBasis basis, const FilterBank &bank,
                         int levels) {
    CheckWaveletLevels(coefficients.width, coefficients.height, levels, "SwtSynthesizeImage");
    int count = shader::SwtPlaneCount(levels);
    if (coefficients.channels % count != 0)
        throw Error(
            fmt::format("SwtSynthesizeImage: {} planes are not channels x {} ({} levels)",
                        coefficients.channels, count, levels),
            ErrorKind::Internal);
    int channels = coefficients.channels / count;
    Image out(coefficients.width, coefficients.height, channels);
    for (int c = 0; c < channels; ++c) {
        Planes planes(count);
        for (int p = 0; p < count; ++p)
            planes[p].assign(coefficients.Plane(c * count + p),
                             coefficients.Plane(c * count + p) + coefficients.PixelCount());
        std::vector<double> x = SwtSynthesizePlane(planes, coefficients.width,
                                                   coefficients.height, basis, bank, levels);
        std::transform(x.begin(), x.end(), out.Plane(c), [](double v) { return float(v); });
    }
    return out;
}

Image WaveletSwtSynthesize(const Image &coefficients, WaveletBasis basis, int levels) {
    return SwtSynthesizeImage(coefficients, basis, GetFilterBank(basis), levels);
}

Image WaveletSwtSynthesizeMagnitude(const Image &coefficients, WaveletBasis basis, int levels) {
    Image absCoef = coefficients;
    for (float &v : absCoef.data) v = std::abs(v);
    return SwtSynthesizeImage(absCoef, basis, AbsoluteFilterBank(GetFilterBank(basis)), levels);
}

}  // namespace mcd::ref
