#include "host/common/squared_tent.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "host/common/parallel.h"

namespace mcd {
namespace {

using Wide = __int128;

// The exponent e of a finite non-zero v = m 2^e, m in [1/2, 1).
int Exponent(float v) {
    uint32_t bits;
    std::memcpy(&bits, &v, 4);
    const int field = int(bits >> 23) & 0xff;
    if (field) return field - 126;
    // A subnormal: v = mantissa 2^-149.
    return 32 - __builtin_clz(bits & 0x7fffff) - 149;
}

// Whether a set of values are all finite, and the exponents of its smallest and largest
// non-zero magnitudes (lo > hi: none).
struct Span {
    bool finite = true;
    int lo = INT_MAX, hi = INT_MIN;
    void Add(float v) {
        if (!std::isfinite(v)) {
            finite = false;
        } else if (v != 0) {
            const int e = Exponent(v);
            lo = std::min(lo, e);
            hi = std::max(hi, e);
        }
    }
    bool Exact(int maxSpread) const { return finite && (lo > hi || hi - lo <= maxSpread); }
    // The unit: the last place of the smallest value, at least the float's least (1 where
    // all are 0).
    int Unit() const { return lo > hi ? 0 : std::max(lo - 24, -149); }
};

// v (finite, a multiple of 2^q) in units of 2^q.
Wide Units(float v, int q) {
    uint32_t bits;
    std::memcpy(&bits, &v, 4);
    if ((bits & 0x7fffffff) == 0) return 0;
    const int field = int(bits >> 23) & 0xff;
    const Wide mantissa = field ? (bits & 0x7fffff) | 0x800000 : bits & 0x7fffff;
    const Wide units = mantissa << (field ? field - 150 - q : -149 - q);
    return bits >> 31 ? -units : units;
}

// The squared tent's weight at offset d: (n - |d|)^2, 0 from |d| = n on.
int64_t Weight(int d, int n) {
    const int64_t t = std::max(0, n - std::abs(d));
    return t * t;
}

// The largest absolute weight sum of the squared tent and of its first three differences:
// the running sums of ExactLine are those weights' sums over the line's values.
double RunningBound(int n) {
    std::vector<double> k(size_t(2 * n + 4), 0.0);
    for (int t = 0; t < 2 * n + 4; ++t) k[t] = double(Weight(t - n, n));
    double bound = 0;
    for (int order = 0; order <= 3; ++order) {
        double sum = 0;
        for (double v : k) sum += std::fabs(v);
        bound = std::max(bound, sum);
        for (size_t t = k.size() - 1; t > 0; --t) k[t] -= k[t - 1];
    }
    return bound;
}

// The largest exponent spread whose sums stay exact in 128 bits: each value is under
// 2^(spread + 24) units, each running sum under RunningBound times that, and 2^126 leaves a
// bit of margin.
int MaxSpread(int n) {
    return 126 - 24 - int(std::ceil(std::log2(RunningBound(n))));
}

// The clipped weights' sum at each position of a line of `length`.
std::vector<int64_t> ClippedTotals(int length, int n) {
    // before[k]: the sum of the weights at offsets below k - (n - 1).
    std::vector<int64_t> before(size_t(2 * n), 0);
    for (int k = 1; k < 2 * n; ++k) before[k] = before[k - 1] + Weight(k - 1 - (n - 1), n);
    std::vector<int64_t> total(static_cast<size_t>(length));
    for (int c = 0; c < length; ++c) {
        const int lo = std::max(-(n - 1), -c), hi = std::min(n - 1, length - 1 - c);
        total[c] = before[hi + n] - before[lo + n - 1];
    }
    return total;
}

// One line whose windows are all exact: the values in units of 2^q behind 2n + 2 zeros;
// the squared tent's third difference (1 at offsets 1 and 2, -4n at n + 1, 4n at n + 2,
// -1 at 2n + 1 and 2n + 2) summed three times gives the weighted sum around c at c + n.
void ExactLine(const float *line, int length, int n, int q, const int64_t *total, float *out,
               std::vector<Wide> *buffer) {
    const int pad = 2 * n + 2;
    buffer->assign(size_t(pad + length + n), 0);
    Wide *u = buffer->data() + pad;
    for (int j = 0; j < length; ++j) u[j] = Units(line[j], q);
    const Wide fourN = 4 * Wide(n);
    const double scale = std::ldexp(1.0, q);  // exact: the sums and 2^q are normal doubles
    Wide p1 = 0, p2 = 0, p3 = 0;
    for (int i = 0; i < length + n; ++i) {
        p1 += u[i - 1] + u[i - 2] - u[i - 2 * n - 1] - u[i - 2 * n - 2] +
              fourN * (u[i - n - 2] - u[i - n - 1]);
        p2 += p1;
        p3 += p2;
        if (i >= n) out[i - n] = float(double(p3) * scale / double(total[i - n]));
    }
}

// The weighted sum of the window [a, b] around c: exact in 128 bits where its values allow,
// else in double from a (each product is exact: a 24-bit value times a weight under 2^29).
double WindowSum(const float *line, int a, int b, int c, int n, int maxSpread) {
    Span span;
    for (int j = a; j <= b; ++j) span.Add(line[j]);
    if (span.Exact(maxSpread)) {
        const int q = span.Unit();
        Wide sum = 0;
        for (int j = a; j <= b; ++j) sum += Wide(Weight(j - c, n)) * Units(line[j], q);
        return std::ldexp(double(sum), q);
    }
    double sum = 0;
    for (int j = a; j <= b; ++j) sum += double(Weight(j - c, n)) * double(line[j]);
    return sum;
}

// One line's means: by running sums where every window is exact, else window by window.
void Line(const float *line, int length, int n, int maxSpread, const int64_t *total, float *out,
          std::vector<Wide> *buffer) {
    Span span;
    for (int j = 0; j < length; ++j) span.Add(line[j]);
    if (span.Exact(maxSpread)) {
        ExactLine(line, length, n, span.Unit(), total, out, buffer);
        return;
    }
    for (int c = 0; c < length; ++c) {
        const int a = std::max(0, c - (n - 1)), b = std::min(length - 1, c + (n - 1));
        out[c] = float(WindowSum(line, a, b, c, n, maxSpread) / double(total[c]));
    }
}

// out (h x w) = in (w x h) transposed, in blocks that stay in cache; bands of rows of the
// input split among the cores.
void Transpose(const float *in, float *out, int w, int h) {
    constexpr int kBlock = 32;
    ParallelFor((h + kBlock - 1) / kBlock, size_t(w) * h * 8, [&](int begin, int end) {
        for (int y0 = begin * kBlock; y0 < std::min(h, end * kBlock); y0 += kBlock)
            for (int x0 = 0; x0 < w; x0 += kBlock)
                for (int y = y0; y < std::min(h, y0 + kBlock); ++y)
                    for (int x = x0; x < std::min(w, x0 + kBlock); ++x)
                        out[size_t(x) * h + y] = in[size_t(y) * w + x];
    });
}

}  // namespace

bool SquaredTentExact(const float *values, int count, int s) {
    Span span;
    for (int j = 0; j < count; ++j) span.Add(values[j]);
    return span.Exact(MaxSpread(2 * s + 1));
}

void SquaredTentMeanRows(const float *in, float *out, int w, int h, int s) {
    const int n = 2 * s + 1, maxSpread = MaxSpread(n);
    const std::vector<int64_t> total = ClippedTotals(w, n);
    ParallelFor(h, size_t(w) * h * 24, [&](int begin, int end) {
        std::vector<Wide> buffer;
        for (int y = begin; y < end; ++y)
            Line(in + size_t(y) * w, w, n, maxSpread, total.data(), out + size_t(y) * w,
                 &buffer);
    });
}

void SquaredTentMeanColumns(const float *in, float *out, int w, int h, int s) {
    std::vector<float> columns(size_t(w) * h), means(size_t(w) * h);
    Transpose(in, columns.data(), w, h);
    SquaredTentMeanRows(columns.data(), means.data(), h, w, s);
    Transpose(means.data(), out, h, w);
}

}  // namespace mcd
