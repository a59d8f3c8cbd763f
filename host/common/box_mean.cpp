#include "host/common/box_mean.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include "host/common/parallel.h"

namespace mcd {
namespace {

// The unit in the last place of a float a > 0: every float at least a is a multiple of it.
double FloatUlp(float a) {
    int e = 0;
    std::frexp(a, &e);  // a = m 2^e, m in [1/2, 1)
    return std::max(std::ldexp(1.0, e - 24), std::ldexp(1.0, -149));
}

// Whether values of absolute sum `sum`, all multiples of the ulp q of the smallest nonzero
// magnitude `least` (infinite: every value 0), have exact partial sums in double in any
// order: sum finite and under 2^51 q.
bool WithinExactBound(double sum, float least) {
    return std::isfinite(sum) &&
           (!std::isfinite(least) || sum < std::ldexp(FloatUlp(least), 51));
}

// The columns whose partial sums, in any order, are all exact in double: finite values,
// all multiples of the smallest one's ulp q, with an absolute sum under 2^51 q (margin for
// the rounding of that sum itself), so every partial sum is an integer times q under 2^53.
// A NaN or an infinity makes the column's absolute sum one too, so that sum alone tells
// both (the loops then run side by side over the columns without branches).
std::vector<int> InexactColumns(const float *in, int w, int h) {
    constexpr float kInf = std::numeric_limits<float>::infinity();
    std::vector<double> total(size_t(w), 0.0);
    std::vector<float> smallest(size_t(w), kInf);
    for (int y = 0; y < h; ++y) {
        const float *row = in + size_t(y) * w;
        for (int x = 0; x < w; ++x) {
            float a = std::fabs(row[x]);
            total[x] += a;
            smallest[x] = std::min(smallest[x], a > 0 ? a : kInf);
        }
    }
    std::vector<int> inexact;
    for (int x = 0; x < w; ++x) {
        bool exact = WithinExactBound(total[x], smallest[x]);
        if (!exact) inexact.push_back(x);
    }
    return inexact;
}

// Rows [yBegin, yEnd): each window summed on its own, in order; a whole row of windows at
// once, so the sums run side by side over contiguous memory.
void SummedRows(const float *in, float *out, int w, int h, int r, int yBegin, int yEnd) {
    std::vector<double> sum(static_cast<size_t>(w));
    for (int y = yBegin; y < yEnd; ++y) {
        int a = std::max(0, y - r), b = std::min(h - 1, y + r);
        std::fill(sum.begin(), sum.end(), 0.0);
        for (int j = a; j <= b; ++j) {
            const float *row = in + size_t(j) * w;
            for (int x = 0; x < w; ++x) sum[x] += row[x];
        }
        float *dst = out + size_t(y) * w;
        for (int x = 0; x < w; ++x) dst[x] = float(sum[x] / (b - a + 1));
    }
}

// Rows [yBegin, yEnd): the first row's windows summed in order, then slid down (exact in
// the columns not listed in `inexact`; those summed in order again).
void SlidRows(const float *in, float *out, int w, int h, int r, int yBegin, int yEnd,
              const std::vector<int> &inexact) {
    std::vector<double> sum(static_cast<size_t>(w), 0.0);
    int a = std::max(0, yBegin - r), b = std::min(h - 1, yBegin + r);
    for (int j = a; j <= b; ++j) {
        const float *row = in + size_t(j) * w;
        for (int x = 0; x < w; ++x) sum[x] += row[x];
    }
    for (int y = yBegin; y < yEnd; ++y) {
        if (y > yBegin) {
            int nextA = std::max(0, y - r), nextB = std::min(h - 1, y + r);
            if (nextB > b) {
                const float *row = in + size_t(nextB) * w;
                for (int x = 0; x < w; ++x) sum[x] += row[x];
            }
            if (nextA > a) {
                const float *row = in + size_t(a) * w;
                for (int x = 0; x < w; ++x) sum[x] -= row[x];
            }
            a = nextA;
            b = nextB;
            for (int x : inexact) {
                double s = 0;
                for (int j = a; j <= b; ++j) s += in[size_t(j) * w + x];
                sum[x] = s;
            }
        }
        float *dst = out + size_t(y) * w;
        for (int x = 0; x < w; ++x) dst[x] = float(sum[x] / (b - a + 1));
    }
}

// Whether every partial sum of the n values at `values` is exact in double, as
// InexactColumns tests a column. The absolute sum is taken in four lanes: its rounding in
// any order is far inside the bound's margin, and where a row is that near the bound its
// sums are exact either way, so the means do not depend on the order.
bool ExactSums(const float *values, int n) {
    constexpr float kInf = std::numeric_limits<float>::infinity();
    double total[4] = {0, 0, 0, 0};
    float smallest[4] = {kInf, kInf, kInf, kInf};
    int i = 0;
    for (; i + 4 <= n; i += 4)
        for (int k = 0; k < 4; ++k) {
            float a = std::fabs(values[i + k]);
            total[k] += a;
            smallest[k] = std::min(smallest[k], a > 0 ? a : kInf);
        }
    for (; i < n; ++i) {
        float a = std::fabs(values[i]);
        total[0] += a;
        smallest[0] = std::min(smallest[0], a > 0 ? a : kInf);
    }
    const double sum = (total[0] + total[1]) + (total[2] + total[3]);
    const float least =
        std::min(std::min(smallest[0], smallest[1]), std::min(smallest[2], smallest[3]));
    return WithinExactBound(sum, least);
}

// Outputs [x0, x1) of a row whose values [a, b) have exact partial sums in any order: each
// window's sum is the difference of two prefix sums from a, the same value as summed in order.
void PrefixWindows(const float *row, float *dst, int w, int r, int x0, int x1, int a, int b,
                   std::vector<double> &sum) {
    sum.resize(size_t(b - a) + 1);
    sum[0] = 0;
    for (int x = a; x < b; ++x) sum[x - a + 1] = sum[x - a] + row[x];
    // sum[x - a]: the sum of the values in [a, x).
    const int lo = std::clamp(r, x0, x1), hi = std::clamp(w - r, lo, x1);  // interior part
    auto clipped = [&](int x) {
        const int from = std::max(0, x - r), to = std::min(w - 1, x + r);
        dst[x] = float((sum[to + 1 - a] - sum[from - a]) / (to - from + 1));
    };
    for (int x = x0; x < lo; ++x) clipped(x);
    const double count = 2 * r + 1;
    for (int x = lo; x < hi; ++x) dst[x] = float((sum[x + r + 1 - a] - sum[x - r - a]) / count);
    for (int x = hi; x < x1; ++x) clipped(x);
}

// Outputs [x0, x1) of a row, each window summed in order from its left. Interior windows go
// kLanes at a time, their sums held in registers while the window's values are added.
void SummedWindows(const float *row, float *dst, int w, int r, int x0, int x1) {
    constexpr int kLanes = 16;
    const int lo = std::clamp(r, x0, x1), hi = std::clamp(w - r, lo, x1);  // interior part
    auto clipped = [&](int x) {
        const int from = std::max(0, x - r), to = std::min(w - 1, x + r);
        double s = 0;
        for (int j = from; j <= to; ++j) s += row[j];
        dst[x] = float(s / (to - from + 1));
    };
    for (int x = x0; x < lo; ++x) clipped(x);
    const double count = 2 * r + 1;
    int x = lo;
    for (; x + kLanes <= hi; x += kLanes) {
        double acc[kLanes] = {};
        const float *from = row + (x - r);
        for (int j = 0; j <= 2 * r; ++j)
            for (int k = 0; k < kLanes; ++k) acc[k] += from[j + k];
        for (int k = 0; k < kLanes; ++k) dst[x + k] = float(acc[k] / count);
    }
    for (; x < x1; ++x) clipped(x);
}

// One row's box means: differences of prefix sums where the row's sums are exact; else in
// segments of outputs, each tested on the values its windows read (a segment's range of
// values is narrower than the row's, so more of it passes), else each window summed in order.
void BoxRow(const float *row, float *dst, int w, int r, std::vector<double> &sum) {
    if (r > 2 && ExactSums(row, w)) return PrefixWindows(row, dst, w, r, 0, w, 0, w, sum);
    const int segment = std::max(256, 8 * r);
    // One segment would read the whole row again: its test has just failed.
    if (w <= segment) return SummedWindows(row, dst, w, r, 0, w);
    for (int x0 = 0; x0 < w; x0 += segment) {
        const int x1 = std::min(w, x0 + segment);
        const int a = std::max(0, x0 - r), b = std::min(w, x1 + r);  // values read: [a, b)
        if (r > 2 && ExactSums(row + a, b - a))
            PrefixWindows(row, dst, w, r, x0, x1, a, b, sum);
        else
            SummedWindows(row, dst, w, r, x0, x1);
    }
}

}  // namespace

void BoxMeanColumns(const float *in, float *out, int w, int h, int r) {
    // Bands of rows, each tested on the rows its windows read: a column's range of values
    // is narrower over a band than over the whole plane, so more of it slides.
    const int band = std::max(64, 4 * r);
    const int bands = (h + band - 1) / band;
    ParallelFor(bands, size_t(w) * h * 8, [&](int begin, int end) {
        for (int k = begin; k < end; ++k) {
            const int y0 = k * band, y1 = std::min(h, y0 + band);
            const int lo = std::max(0, y0 - r), hi = std::min(h, y1 + r);
            std::vector<int> inexact = InexactColumns(in + size_t(lo) * w, w, hi - lo);
            // Columns summed one by one read memory a row apart: worth it for a few only.
            if (r > 2 && inexact.size() * 8 <= size_t(w))
                SlidRows(in, out, w, h, r, y0, y1, inexact);
            else
                SummedRows(in, out, w, h, r, y0, y1);
        }
    });
}

void BoxMeanRows(const float *in, float *out, int w, int h, int r) {
    ParallelFor(h, size_t(w) * h * 8, [&](int begin, int end) {
        std::vector<double> sum;
        for (int y = begin; y < end; ++y)
            BoxRow(in + size_t(y) * w, out + size_t(y) * w, w, r, sum);
    });
}

}  // namespace mcd
