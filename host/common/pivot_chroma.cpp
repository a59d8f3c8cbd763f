#include "host/common/pivot_chroma.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>

#include "host/common/local_mean.h"
#include "host/common/parallel.h"
#include "host/error.h"

namespace mcd {
namespace {

// The most colour channels pivot takes (PIVOT_MAX_CHANNELS).
constexpr int kMaxChannels = 4;
using Channels = std::array<double, kMaxChannels>;

// A value of channel c of an image of 1 or the colour's channels.
float ValueOf(const Image &image, int c, size_t p) {
    return image.Plane(image.channels == 1 ? 0 : c)[p];
}

// The sum of the chroma's standard deviations (value over the channels' sum, linearised) of
// a colour of `n` channels summing to `sum` with per-channel variances `var`.
double ChromaNoise(const Channels &value, const Channels &var, int n, double sum) {
    double noise = 0;
    for (int c = 0; c < n; ++c) {
        const double chroma = value[c] / sum;
        // The other channels' variances summed first, then scaled (the twin's order).
        double others = 0;
        for (int j = 0; j < n; ++j)
            if (j != c) others += var[j];
        noise += std::sqrt(var[c] * (1 - chroma) * (1 - chroma) + chroma * chroma * others);
    }
    return noise / sum;
}

// A weight rising from 0 where d is `lo` allowances to 1 where it is `hi`: pixels near a
// threshold move a little, not all or nothing (auto's probe would read a flip as an error).
// NaN where d is.
double Ramp(double d, double allowance, double lo, double hi) {
    if (d <= lo * allowance) return 0;
    if (d >= hi * allowance) return 1;
    return (d - lo * allowance) / ((hi - lo) * allowance);
}

// L1 distance between the chromas of a and b (sums sa and sb).
double ChromaDistance(const Channels &a, double sa, const Channels &b, double sb, int n) {
    double d = 0;
    for (int c = 0; c < n; ++c) d += std::fabs(a[c] / sa - b[c] / sb);
    return d;
}

struct Inputs {
    const Image &color, &pivot, &variance;
    const Image *objectId, *partId;
    double bound;
};

// Whether q's colour, variance and pivot are finite, variance and pivot not below 0.
bool Usable(const Inputs &in, size_t q) {
    for (int c = 0; c < in.color.channels; ++c) {
        float v = in.color.Plane(c)[q], var = ValueOf(in.variance, c, q),
              piv = ValueOf(in.pivot, c, q);
        if (!std::isfinite(v) || !std::isfinite(var) || !std::isfinite(piv) || var < 0 ||
            piv < 0)
            return false;
    }
    return true;
}

bool SameIds(const Inputs &in, size_t p, size_t q) {
    return (!in.objectId || in.objectId->data[p] == in.objectId->data[q]) &&
           (!in.partId || in.partId->data[p] == in.partId->data[q]);
}

// The window's expected colour at (x, y) and its variance; false where a channel's pivot
// sum (or the pixel's pivot) is not above 0.
bool WindowColour(const Inputs &in, int x, int y, Channels *e, Channels *ve) {
    const int w = in.color.width, h = in.color.height, n = in.color.channels;
    const size_t p = size_t(y) * w + x;
    Channels sum{}, pivotSum{}, varSum{};
    for (int v = std::max(0, y - kPivotChromaRadius);
         v <= std::min(h - 1, y + kPivotChromaRadius); ++v)
        for (int u = std::max(0, x - kPivotChromaRadius);
             u <= std::min(w - 1, x + kPivotChromaRadius); ++u) {
            const size_t q = size_t(v) * w + u;
            if (!SameIds(in, p, q) || !Usable(in, q)) continue;
            for (int c = 0; c < n; ++c) {
                sum[c] += in.color.Plane(c)[q];
                pivotSum[c] += ValueOf(in.pivot, c, q);
                varSum[c] += ValueOf(in.variance, c, q);
            }
        }
    for (int c = 0; c < n; ++c) {
        const double own = ValueOf(in.pivot, c, p);
        if (!(pivotSum[c] > 0) || !(own > 0)) return false;
        (*e)[c] = own * sum[c] / pivotSum[c];
        (*ve)[c] = own * own * varSum[c] / (pivotSum[c] * pivotSum[c]);
    }
    return true;
}

// The output of (x, y) moved to its window's chroma where its fit tints it; whether moved.
bool Mend(const Inputs &in, int x, int y, Image *output) {
    const int w = in.color.width, n = in.color.channels;
    const size_t p = size_t(y) * w + x;
    Channels out{}, input{}, inputVar{};
    double outSum = 0, inputSum = 0, inputVarSum = 0;
    bool kept = true;
    for (int c = 0; c < n; ++c) {
        out[c] = output->Plane(c)[p], input[c] = in.color.Plane(c)[p];
        inputVar[c] = ValueOf(in.variance, c, p);
        kept &= out[c] == input[c];
        outSum += out[c], inputSum += input[c], inputVarSum += inputVar[c];
    }
    if (kept || !std::isfinite(outSum) || !(outSum > 0) || !Usable(in, p)) return false;
    Channels e{}, ve{};
    if (!WindowColour(in, x, y, &e, &ve)) return false;
    double eSum = 0, veSum = 0;
    for (int c = 0; c < n; ++c) eSum += e[c], veSum += ve[c];
    if (!(eSum > 0)) return false;
    // How far the fit's chroma is off the window's, and how well the window stands for the
    // pixel: its input's chroma and brightness agree with it.
    double weight = Ramp(ChromaDistance(out, outSum, e, eSum, n), ChromaNoise(e, ve, n, eSum),
                         kPivotChromaFit, kPivotChromaFitFull);
    if (inputSum > 0)
        weight *= 1 - Ramp(ChromaDistance(input, inputSum, e, eSum, n),
                           ChromaNoise(input, inputVar, n, inputSum), kPivotChromaAgree,
                           kPivotChromaAgreeNone);
    if (inputVarSum > 0)
        weight *= 1 - Ramp(std::fabs(eSum - inputSum), std::sqrt(inputVarSum + veSum),
                           kPivotChromaAgree, kPivotChromaAgreeNone);
    if (!(weight > 0)) return false;
    // Held as the bound holds the fits: every channel within its k standard deviations.
    Channels mended{};
    for (int c = 0; c < n; ++c) {
        const float target = float(outSum * (e[c] / eSum));
        const double spread = NoiseSpread(in.variance, c, x, y);
        if (!(target >= 0) || (in.bound > 0 && spread >= 0 &&
                               !(std::fabs(target - input[c]) <= in.bound * spread)))
            return false;
        mended[c] = out[c] + weight * (target - out[c]);
    }
    for (int c = 0; c < n; ++c) output->Plane(c)[p] = float(mended[c]);
    return true;
}

}  // namespace

size_t KeepWindowChroma(const Image &color, const Image &pivot, const Image &variance,
                        const Image *objectId, const Image *partId, double bound,
                        Image *output) {
    auto sized = [&](const Image &image, bool colourChannels) {
        return image.width == color.width && image.height == color.height &&
               (image.channels == 1 || (colourChannels && image.channels == color.channels));
    };
    if (!color.SameShape(*output) || !sized(pivot, true) || !sized(variance, true) ||
        (objectId && !sized(*objectId, false)) || (partId && !sized(*partId, false)) ||
        color.channels > kMaxChannels)
        throw Error(
            "KeepWindowChroma: the output must have the colour's shape, the pivot and the "
            "variance its size and 1 or its channels, the ids its size and 1 channel",
            ErrorKind::Internal);
    if (color.channels < 2) return 0;
    const Inputs in{color, pivot, variance, objectId, partId, bound};
    const int w = color.width, h = color.height;
    const size_t window = (2 * kPivotChromaRadius + 1) * (2 * kPivotChromaRadius + 1);
    std::atomic<size_t> moved{0};
    ParallelFor(h, size_t(w) * h * window * color.channels * 4, [&](int yBegin, int yEnd) {
        size_t rows = 0;
        for (int y = yBegin; y < yEnd; ++y)
            for (int x = 0; x < w; ++x) rows += Mend(in, x, y, output);
        moved += rows;
    });
    return moved;
}

}  // namespace mcd
