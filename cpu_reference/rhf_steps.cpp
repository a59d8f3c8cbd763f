#include "cpu_reference/rhf_steps.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "cpu_reference/rhf.h"

namespace mcd::ref {

RhfPairTerms RhfPixelPairTerms(const Image &hist, int px, int py, int qx, int qy,
                               double brightVeto) {
    const int bins = hist.channels - 1, perColour = bins / 3;
    const double np = hist.At(bins, py, px), nq = hist.At(bins, qy, qx);
    RhfPairTerms terms;
    if (np == 0 || nq == 0) return terms;
    int saturatedCounted = 0;
    for (int i = 0; i < bins; ++i) {
        double hp = hist.At(i, py, px), hq = hist.At(i, qy, qx);
        if (!(hp + hq > 1)) continue;
        double d = nq * hp - np * hq, den = np * nq * (hp + hq), term = d * d / den;
        terms.sum += term;
        terms.counted += 1;
        terms.magnitude += term + 2 * std::fabs(d) * (nq * hp + np * hq + std::fabs(d)) / den;
        // The last two bins of a colour hold the samples above the histogram's range.
        if (i % perColour >= perColour - 2) {
            terms.saturated += term;
            saturatedCounted += 1;
        }
    }
    terms.vetoBound = brightVeto * 2 * np * nq / (np + nq);
    terms.vetoed = brightVeto > 0 && saturatedCounted > 0 && terms.saturated > terms.vetoBound;
    return terms;
}

Image RhfDistancesFromTerms(const Image &sum, const Image &count, int searchHalf,
                            int patchHalf) {
    const int W = sum.width, H = sum.height, b = searchHalf, side = 2 * b + 1;
    Image out(W, H, side * side, -1.f);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            int w0 = std::min({patchHalf, x, y, W - 1 - x, H - 1 - y});
            for (int dy = -b; dy <= b; ++dy)
                for (int dx = -b; dx <= b; ++dx) {
                    int qx = x + dx, qy = y + dy;
                    // The candidate's patch must lie inside the image too.
                    if (qx < w0 || qx > W - 1 - w0 || qy < w0 || qy > H - 1 - w0) continue;
                    double total = 0, counted = 0;
                    bool vetoed = false;
                    for (int ty = -w0; ty <= w0; ++ty)
                        for (int tx = -w0; tx <= w0; ++tx) {
                            // Pair (p + t, q + t): stored at p + t for dy >= 0, else at
                            // q + t under the offset -o.
                            int sx = x + tx, sy = y + ty, ox = dx, oy = dy;
                            if (dy < 0) sx += dx, sy += dy, ox = -dx, oy = -dy;
                            int channel = oy * side + ox + b;
                            double c = count.At(channel, sy, sx);
                            vetoed = vetoed || c < 0;
                            total += sum.At(channel, sy, sx);
                            counted += c;
                        }
                    if (!vetoed)
                        out.At((dy + b) * side + dx + b, y, x) =
                            float(total / (counted + 1e-4));
                }
        }
    return out;
}

Image RhfAggregate(const Image &color, const Image &selected, int searchHalf, int patchHalf) {
    const int W = color.width, H = color.height, C = color.channels, b = searchHalf;
    const int side = 2 * b + 1;
    std::vector<double> total(color.Size(), 0.0), estimates(color.PixelCount(), 0.0);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            int w0 = std::min({patchHalf, x, y, W - 1 - x, H - 1 - y});
            // Eq. 6: the patch's estimate is the mean of its selected candidates.
            int n = 0;
            for (int o = 0; o < side * side; ++o) n += selected.At(o, y, x) != 0;
            if (n == 0) continue;
            for (int ty = -w0; ty <= w0; ++ty)
                for (int tx = -w0; tx <= w0; ++tx) {
                    size_t at = size_t(y + ty) * W + x + tx;
                    estimates[at] += 1;
                    for (int c = 0; c < C; ++c) {
                        double mean = 0;
                        for (int o = 0; o < side * side; ++o)
                            if (selected.At(o, y, x) != 0)
                                mean +=
                                    color.At(c, y + o / side - b + ty, x + o % side - b + tx);
                        total[c * color.PixelCount() + at] += mean / n;
                    }
                }
        }
    // Eq. 7: every pixel is the mean of its estimates.
    Image out = color;
    for (int c = 0; c < C; ++c)
        for (size_t p = 0; p < color.PixelCount(); ++p)
            if (estimates[p] > 0)
                out.data[c * color.PixelCount() + p] =
                    float(total[c * color.PixelCount() + p] / estimates[p]);
    return out;
}

Image RhfCombine(const Image &filtered, const Image &low, const Image &coarse) {
    Image upLow = RhfBicubicUpsample(low, filtered.width, filtered.height);
    Image upCoarse = RhfBicubicUpsample(coarse, filtered.width, filtered.height);
    Image out(filtered.width, filtered.height, filtered.channels);
    for (size_t i = 0; i < out.Size(); ++i)
        out.data[i] = float(double(filtered.data[i]) - upLow.data[i] + upCoarse.data[i]);
    return out;
}

}  // namespace mcd::ref
