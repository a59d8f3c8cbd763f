#include "cpu_reference/rhf.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <tuple>
#include <vector>

namespace mcd::ref {
namespace {

double Keys(double x) {
    const double a = -0.5;
    x = std::fabs(x);
    if (x <= 1) return (a + 2) * x * x * x - (a + 3) * x * x + 1;
    if (x < 2) return a * x * x * x - 5 * a * x * x + 8 * a * x - 4 * a;
    return 0;
}

double SigmaOfScale(int s) {
    return 0.55 * std::sqrt(std::pow(4.0, s) - 1);
}

}  // namespace

int RhfMirror(int i, int n) {
    i %= 2 * n;
    if (i < 0) i += 2 * n;
    return i < n ? i : 2 * n - 1 - i;
}

int RhfScalesUsed(int width, int height, const RhfParams &params) {
    int side = 2 * params.searchHalf + 1, used = 1;
    while (used < params.scales) {
        int w = (width + (1 << used) - 1) >> used, h = (height + (1 << used) - 1) >> used;
        if (w < side || h < side) break;
        ++used;
    }
    return used;
}

double RhfPatchDistance(const Image &hist, int x0, int y0, int x1, int y1, int w0,
                        double brightVeto) {
    int n3 = hist.channels - 1, perColour = n3 / 3;
    double sum = 0;
    long counted = 0;
    for (int ty = -w0; ty <= w0; ++ty)
        for (int tx = -w0; tx <= w0; ++tx) {
            double nx = hist.At(n3, y0 + ty, x0 + tx), ny = hist.At(n3, y1 + ty, x1 + tx);
            if (nx == 0 || ny == 0) continue;
            double saturated = 0;
            long saturatedCounted = 0;
            for (int i = 0; i < n3; ++i) {
                double hx = hist.At(i, y0 + ty, x0 + tx), hy = hist.At(i, y1 + ty, x1 + tx);
                if (hx + hy <= 1) continue;
                double d = ny * hx - nx * hy, term = d * d / (nx * ny * (hx + hy));
                sum += term;
                ++counted;
                // The last two bins of a colour hold the samples above the range M.
                if (i % perColour >= perColour - 2) {
                    saturated += term;
                    ++saturatedCounted;
                }
            }
            // The veto: this pair's bright samples alone tell the patches apart.
            if (brightVeto > 0 && saturatedCounted > 0 &&
                saturated > brightVeto * 2 * nx * ny / (nx + ny))
                return -1;
        }
    return sum / (double(counted) + 1e-4);
}

Image RhfBlockMax(const Image &hist, float histScale, int block) {
    const int n3 = hist.channels - 1, blocks = (hist.width + block - 1) / block;
    Image out(blocks, hist.height, n3);
    for (int i = 0; i < n3; ++i)
        for (int y = 0; y < hist.height; ++y)
            for (int b = 0; b < blocks; ++b) {
                float largest = -std::numeric_limits<float>::max();
                for (int x = b * block; x < std::min(hist.width, (b + 1) * block); ++x) {
                    float n = hist.At(n3, y, x) * histScale;
                    if (n != 0) largest = std::max(largest, hist.At(i, y, x) * histScale);
                }
                out.At(i, y, b) = largest;
            }
    return out;
}

std::vector<bool> RhfSelect(const std::vector<double> &distances, int nearest,
                            double threshold) {
    int n = int(distances.size());
    std::vector<int> order(n);
    for (int i = 0; i < n; ++i) order[i] = i;
    std::vector<bool> picked(n, false);
    for (int k = 0; k < std::min(nearest, n); ++k) {
        int best = k;
        for (int j = k + 1; j < n; ++j)
            if (distances[order[j]] < distances[order[best]]) best = j;
        std::swap(order[k], order[best]);
        picked[order[k]] = true;
    }
    for (int i = 0; i < n; ++i)
        if (distances[i] < threshold) picked[i] = true;
    return picked;
}

std::vector<float> RhfBrightPool(const Image &hist, int patchHalf) {
    const int W = hist.width, H = hist.height, n = (hist.channels - 1) / 3;
    std::vector<float> pool(size_t(W) * H);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            float sum = 0.f;
            for (int ty = y - patchHalf; ty <= y + patchHalf; ++ty)
                for (int tx = x - patchHalf; tx <= x + patchHalf; ++tx) {
                    if (tx < 0 || ty < 0 || tx >= W || ty >= H) continue;
                    float bright = 0.f;
                    for (int c = 0; c < 3; ++c)
                        for (int b = std::max(0, n - 2); b < n; ++b)
                            bright += hist.At(c * n + b, ty, tx);
                    sum += bright;
                }
            pool[size_t(y) * W + x] = sum;
        }
    return pool;
}

Image RhfSingleScale(const Image &color, const Image &hist, int patchHalf, int searchHalf,
                     double threshold, int knn, double brightVeto, double brightPool) {
    const int W = color.width, H = color.height, C = color.channels;
    const std::vector<float> pool =
        brightPool > 0 ? RhfBrightPool(hist, patchHalf) : std::vector<float>();
    // The pixels of (x, y)'s pool box, cut at the image's edges.
    auto boxArea = [&](int x, int y) {
        int across = std::min(W - 1, x + patchHalf) - std::max(0, x - patchHalf) + 1;
        int down = std::min(H - 1, y + patchHalf) - std::max(0, y - patchHalf) + 1;
        return float(across * down);
    };
    // The pooled veto: rates r = P / a, each with variance P / a^2 (counts), apart when
    // (rP - rQ)^2 > brightPool (P / aP^2 + Q / aQ^2). Both sides times aP^2 aQ^2, in
    // float, unfused, as the kernel compares.
    auto pooledApart = [&](int x, int y, int qx, int qy) {
        if (brightPool <= 0) return false;
        float own = pool[size_t(y) * W + x], other = pool[size_t(qy) * W + qx];
        float ownArea = boxArea(x, y), area = boxArea(qx, qy);
        float diff = own * area - other * ownArea, square = diff * diff;
        float bound = float(brightPool) * (own * area * area + other * ownArea * ownArea);
        return square > bound;
    };
    std::vector<double> sum(size_t(C) * W * H, 0.0), count(size_t(W) * H, 0.0);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            // Shrink the patch to fit; clamp the window so every compared patch fits.
            int w0 = std::min({patchHalf, x, y, W - 1 - x, H - 1 - y});
            int xmin = std::max(x - searchHalf, w0),
                xmax = std::min(x + searchHalf, W - 1 - w0);
            int ymin = std::max(y - searchHalf, w0),
                ymax = std::min(y + searchHalf, H - 1 - w0);
            // Candidates in the tool's order: column by column of the clamped window.
            std::vector<double> distances;
            std::vector<std::pair<int, int>> where;
            for (int qx = xmin; qx <= xmax; ++qx)
                for (int qy = ymin; qy <= ymax; ++qy) {
                    double d = RhfPatchDistance(hist, x, y, qx, qy, w0, brightVeto);
                    if (d < 0 || pooledApart(x, y, qx, qy)) continue;
                    distances.push_back(d);
                    where.emplace_back(qx, qy);
                }
            // The k_NN nearest besides the patch itself, and every one under the threshold.
            std::vector<bool> picked = RhfSelect(distances, knn > 0 ? knn + 1 : 0, threshold);
            // Eq. 6: the average of the selected patches.
            int side = 2 * w0 + 1;
            std::vector<double> patch(size_t(C) * side * side, 0.0);
            int selected = 0;
            for (size_t k = 0; k < where.size(); ++k) {
                if (!picked[k]) continue;
                auto [qx, qy] = where[k];
                ++selected;
                for (int c = 0; c < C; ++c)
                    for (int ty = -w0; ty <= w0; ++ty)
                        for (int tx = -w0; tx <= w0; ++tx)
                            patch[(size_t(c) * side + ty + w0) * side + tx + w0] +=
                                color.At(c, qy + ty, qx + tx);
            }
            if (selected == 0) continue;
            // Eq. 7: one more estimate for every pixel of the patch.
            for (int ty = -w0; ty <= w0; ++ty)
                for (int tx = -w0; tx <= w0; ++tx) {
                    size_t at = size_t(y + ty) * W + x + tx;
                    count[at] += 1;
                    for (int c = 0; c < C; ++c)
                        sum[size_t(c) * W * H + at] +=
                            patch[(size_t(c) * side + ty + w0) * side + tx + w0] / selected;
                }
        }
    Image out(W, H, C);
    for (int c = 0; c < C; ++c)
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                size_t at = size_t(y) * W + x;
                out.At(c, y, x) = count[at] > 0 ? float(sum[size_t(c) * W * H + at] / count[at])
                                                : color.At(c, y, x);
            }
    return out;
}

Image RhfGaussianDownsample(const Image &image, int s, double sigma) {
    double scale = std::ldexp(1.0, -s);
    int radius = int(std::ceil(sigma * std::sqrt(4 * std::log(10.0))));
    int W = int(std::ceil(image.width * scale)), H = int(std::ceil(image.height * scale));
    // One axis: dst(x) = sum_j g_x(j) src(mirror(j)), the kernel centred on (x + 0.5) /
    // scale in the source's pixel-edge coordinates and normalised per x.
    auto axis = [&](int n, int out) {
        std::vector<std::vector<std::pair<int, double>>> taps(out);
        for (int x = 0; x < out; ++x) {
            double xx = (x + 0.5) / scale;
            int xc = int(std::floor(xx));
            double total = 0;
            for (int j = xc - radius; j <= xc + radius; ++j) {
                double t = (j + 0.5 - xx) / sigma;
                taps[x].emplace_back(RhfMirror(j, n), std::exp(-0.5 * t * t));
                total += taps[x].back().second;
            }
            for (auto &tap : taps[x]) tap.second /= total;
        }
        return taps;
    };
    auto tx = axis(image.width, W), ty = axis(image.height, H);
    Image out(W, H, image.channels);
    for (int c = 0; c < image.channels; ++c)
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                double v = 0;
                for (auto [j, gy] : ty[y])
                    for (auto [i, gx] : tx[x]) v += gy * gx * image.At(c, j, i);
                out.At(c, y, x) = float(v);
            }
    return out;
}

Image RhfBicubicUpsample(const Image &coarse, int width, int height) {
    // Pixel centres aligned: fine x sits at coarse (x + 0.5) n_coarse / n_fine - 0.5.
    auto axis = [](int n, int out) {
        std::vector<std::array<std::pair<int, double>, 4>> taps(out);
        for (int x = 0; x < out; ++x) {
            double t = (x + 0.5) * n / out - 0.5;
            int i0 = int(std::floor(t));
            for (int k = 0; k < 4; ++k)
                taps[x][k] = {RhfMirror(i0 - 1 + k, n), Keys(t - (i0 - 1 + k))};
        }
        return taps;
    };
    auto tx = axis(coarse.width, width), ty = axis(coarse.height, height);
    Image out(width, height, coarse.channels);
    for (int c = 0; c < coarse.channels; ++c)
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x) {
                double v = 0;
                for (auto [j, wy] : ty[y])
                    for (auto [i, wx] : tx[x]) v += wy * wx * coarse.At(c, j, i);
                out.At(c, y, x) = float(v);
            }
    return out;
}

Image Rhf(const Image &color, const Image &hist, const RhfParams &params,
          std::vector<std::pair<std::string, Image>> *stages) {
    int scales = RhfScalesUsed(color.width, color.height, params);
    int n3 = hist.channels - 1;
    // n_T: the total of the count channel over the image, kept at every scale.
    double total = 0;
    for (size_t p = 0; p < hist.PixelCount(); ++p) total += hist.Plane(n3)[p];
    Image previous;
    for (int s = scales - 1; s >= 0; --s) {
        Image u = color, h = hist;
        double factor = 1;
        if (s > 0) {
            u = RhfGaussianDownsample(color, s, SigmaOfScale(s));
            h = RhfGaussianDownsample(hist, s, SigmaOfScale(s));
            double totalS = 0;
            for (size_t p = 0; p < h.PixelCount(); ++p) totalS += h.Plane(n3)[p];
            factor = totalS > 0 ? total / totalS : 1.0;
            for (float &v : h.data) v = float(v * factor);
            if (stages) stages->push_back({fmt::format("color s{}", s), u});
        }
        // The veto's bound is in the frame's sample counts: divide it by the rescale.
        Image filtered =
            RhfSingleScale(u, h, params.patchHalf, params.searchHalf, double(params.threshold),
                           s == 0 ? params.knn : 0, double(params.brightVeto) / factor,
                           s == 0 ? double(params.brightPool) : 0.0);
        if (stages) stages->push_back({fmt::format("filtered s{}", s), filtered});
        if (s < scales - 1) {
            // u_s - U(D(u_s)) + U(u_{s+1}).
            Image low = RhfBicubicUpsample(RhfGaussianDownsample(filtered, 1, SigmaOfScale(1)),
                                           u.width, u.height);
            Image coarse = RhfBicubicUpsample(previous, u.width, u.height);
            for (size_t i = 0; i < filtered.Size(); ++i)
                filtered.data[i] =
                    float(double(filtered.data[i]) - low.data[i] + coarse.data[i]);
            if (stages) stages->push_back({fmt::format("combined s{}", s), filtered});
        }
        previous = std::move(filtered);
    }
    return previous;
}

}  // namespace mcd::ref
