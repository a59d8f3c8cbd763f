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

// The columns whose partial sums, in any order, are all exact in double: finite values,
// all multiples of the smallest one's ulp q, with an absolute sum under 2^51 q (margin for
// the rounding of that sum itself), so every partial sum is an integer times q under 2^53.
std::vector<int> InexactColumns(const float *in, int w, int h) {
    std::vector<double> total(size_t(w), 0.0);
    std::vector<float> smallest(size_t(w), std::numeric_limits<float>::infinity());
    std::vector<char> finite(size_t(w), 1);
    for (int y = 0; y < h; ++y) {
        const float *row = in + size_t(y) * w;
        for (int x = 0; x < w; ++x) {
            float a = std::fabs(row[x]);
            finite[x] &= std::isfinite(a);
            total[x] += a;
            if (a > 0) smallest[x] = std::min(smallest[x], a);
        }
    }
    std::vector<int> inexact;
    for (int x = 0; x < w; ++x) {
        bool exact = finite[x] && (!std::isfinite(smallest[x]) ||
                                   total[x] < std::ldexp(FloatUlp(smallest[x]), 51));
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

// Whether every partial sum of the n values at `values` (a stride apart) is exact in
// double, as InexactColumns tests a column.
bool ExactSums(const float *values, int n) {
    double total = 0;
    float smallest = std::numeric_limits<float>::infinity();
    bool finite = true;
    for (int i = 0; i < n; ++i) {
        float a = std::fabs(values[i]);
        finite = finite && std::isfinite(a);
        total += a;
        if (a > 0) smallest = std::min(smallest, a);
    }
    return finite && (!std::isfinite(smallest) || total < std::ldexp(FloatUlp(smallest), 51));
}

// One row's box means: slid where exact, else each window summed in order (the interior's
// windows side by side, so the sums run over contiguous memory).
void BoxRow(const float *row, float *dst, int w, int r, std::vector<double> &sum) {
    if (r > 2 && ExactSums(row, w)) {
        double s = 0;
        int a = 0, b = std::min(w - 1, r);
        for (int j = a; j <= b; ++j) s += row[j];
        for (int x = 0; x < w; ++x) {
            int nextA = std::max(0, x - r), nextB = std::min(w - 1, x + r);
            if (nextB > b) s += row[nextB];
            if (nextA > a) s -= row[a];
            a = nextA;
            b = nextB;
            dst[x] = float(s / (b - a + 1));
        }
        return;
    }
    sum.assign(size_t(w), 0.0);
    const int lo = std::min(r, w), hi = std::max(lo, w - r);  // interior: [lo, hi)
    for (int j = 0; j <= 2 * r; ++j)
        for (int x = lo; x < hi; ++x) sum[x] += row[x - r + j];
    for (int x = 0; x < w; ++x) {
        int a = std::max(0, x - r), b = std::min(w - 1, x + r);
        if (x < lo || x >= hi)
            for (int j = a; j <= b; ++j) sum[x] += row[j];
        dst[x] = float(sum[x] / (b - a + 1));
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
