#include "host/common/box_mean.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include "host/common/parallel.h"

namespace mcd {
namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();

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

// The indices of a window sliding right whose extreme value is at the front (the largest
// where `larger`, else the smallest): each index enters and leaves once.
class SlidingExtreme {
  public:
    SlidingExtreme(const std::vector<float> &values, bool larger)
        : values(values), larger(larger) {}
    void Push(int i) {
        while (head < int(order.size()) && Beats(values[i], values[order.back()]))
            order.pop_back();
        order.push_back(i);
    }
    void PopBefore(int a) {
        while (head < int(order.size()) && order[head] < a) ++head;
    }
    float Front() const { return values[order[head]]; }

  private:
    bool Beats(float a, float b) const { return larger ? a >= b : a <= b; }
    const std::vector<float> &values;
    bool larger;
    std::vector<int> order;
    int head = 0;
};

// One row's box means where its sums in double are not all exact: a window whose values
// are finite and whose count times its largest magnitude is under 2^51 units in the last
// place of its smallest non-zero one has exact partial sums in any order, so its sum is
// the difference of the row's running sums in 128-bit integers (units of the last place of
// the row's smallest value); other windows are summed in order. The same bits as every
// window summed in order.
void BoxRowByWindow(const float *row, float *dst, int w, int r) {
    std::vector<float> largest(size_t(w), 0.f), smallest(size_t(w), kInfinity);
    float least = kInfinity, most = 0;
    for (int x = 0; x < w; ++x) {
        const float a = std::fabs(row[x]);
        if (!std::isfinite(a)) continue;
        largest[x] = a;
        if (a > 0) smallest[x] = a;
        least = std::min(least, smallest[x]);
        most = std::max(most, a);
    }
    // The row's running sums in units of its least value's last place, non-finite values
    // as 0 (their windows are summed in order); when they could overflow, every window is.
    const double unit = std::isfinite(least) ? FloatUlp(least) : 1.0;
    const bool fits = double(most) / unit * w < std::ldexp(1.0, 120);
    std::vector<__int128> running(size_t(w) + 1, 0);
    std::vector<int> nonFinite(size_t(w) + 1, 0);
    for (int x = 0; x < w; ++x) {
        const bool finite = std::isfinite(row[x]);
        running[x + 1] = running[x] + (finite && fits ? __int128(row[x] / unit) : 0);
        nonFinite[x + 1] = nonFinite[x] + !finite;
    }
    SlidingExtreme high(largest, true), low(smallest, false);
    for (int x = 0, next = 0; x < w; ++x) {
        const int a = std::max(0, x - r), b = std::min(w - 1, x + r), count = b - a + 1;
        for (; next <= b; ++next) high.Push(next), low.Push(next);
        high.PopBefore(a);
        low.PopBefore(a);
        if (fits && nonFinite[b + 1] == nonFinite[a] &&
            (!std::isfinite(low.Front()) ||
             double(high.Front()) * count < std::ldexp(FloatUlp(low.Front()), 51))) {
            dst[x] = float(double(running[b + 1] - running[a]) * unit / count);
            continue;
        }
        double sum = 0;
        for (int j = a; j <= b; ++j) sum += row[j];
        dst[x] = float(sum / count);
    }
}

// One row's box means: slid in double where every sum is exact, else window by window.
void BoxRow(const float *row, float *dst, int w, int r) {
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
    BoxRowByWindow(row, dst, w, r);
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
        for (int y = begin; y < end; ++y) BoxRow(in + size_t(y) * w, out + size_t(y) * w, w, r);
    });
}

}  // namespace mcd
