#include "host/common/input_minimum.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <vector>

#include "host/common/parallel.h"
#include "host/error.h"

namespace mcd {
namespace {

// The smaller of two values; NaN if either is not finite (a window with a value that is not
// finite is left).
float Lower(float a, float b) {
    return std::isfinite(a) && std::isfinite(b) ? std::min(a, b)
                                                : std::numeric_limits<float>::quiet_NaN();
}

}  // namespace

size_t RaiseToInputMinimum(const Image &input, int r, Image *output) {
    if (!input.SameShape(*output) || r < 0)
        throw Error("RaiseToInputMinimum: the output must have the input's shape, r >= 0",
                    ErrorKind::Internal);
    const int w = input.width, h = input.height;
    std::atomic<size_t> moved{0};
    std::vector<float> rowLow(size_t(w) * h);
    for (int c = 0; c < input.channels; ++c) {
        const float *in = input.Plane(c);
        float *out = output->Plane(c);
        // Each row's minima over the window's columns first, then those over its rows.
        ParallelFor(h, size_t(w) * h * (2 * r + 1), [&](int yBegin, int yEnd) {
            for (int y = yBegin; y < yEnd; ++y)
                for (int x = 0; x < w; ++x) {
                    float low = in[size_t(y) * w + x];
                    for (int u = std::max(0, x - r); u <= std::min(w - 1, x + r); ++u)
                        low = Lower(low, in[size_t(y) * w + u]);
                    rowLow[size_t(y) * w + x] = low;
                }
        });
        ParallelFor(h, size_t(w) * h * (2 * r + 1), [&](int yBegin, int yEnd) {
            size_t movedHere = 0;
            for (int y = yBegin; y < yEnd; ++y)
                for (int x = 0; x < w; ++x) {
                    const size_t p = size_t(y) * w + x;
                    float low = rowLow[p];
                    for (int v = std::max(0, y - r); v <= std::min(h - 1, y + r); ++v)
                        low = Lower(low, rowLow[size_t(v) * w + x]);
                    if (!std::isfinite(low) || !std::isfinite(out[p]) || !(out[p] < low))
                        continue;
                    out[p] = low;
                    ++movedHere;
                }
            moved += movedHere;
        });
    }
    return moved.load();
}

}  // namespace mcd
