#include "cpu_reference/local_mean.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "host/error.h"

namespace mcd::ref {
namespace {

// The mean of each plane over the box of radius r around each pixel, clipped to the image.
Image BoxMean(const Image &image, int r) {
    Image out(image.width, image.height, image.channels);
    for (int c = 0; c < image.channels; ++c)
        for (int y = 0; y < image.height; ++y)
            for (int x = 0; x < image.width; ++x) {
                double sum = 0;
                int n = 0;
                for (int v = std::max(0, y - r); v <= std::min(image.height - 1, y + r); ++v)
                    for (int u = std::max(0, x - r); u <= std::min(image.width - 1, x + r);
                         ++u) {
                        sum += image.At(c, v, u);
                        ++n;
                    }
                out.At(c, y, x) = float(sum / n);
            }
    return out;
}

Image Tent(const Image &image, int r) {
    return BoxMean(BoxMean(image, r), r);
}

// The output with the values kept (equal to the input's) as 0.
Image Moved(const Image &output, const std::vector<bool> &kept) {
    Image moved = output;
    for (size_t i = 0; i < moved.data.size(); ++i)
        if (kept[i]) moved.data[i] = 0;
    return moved;
}

// Whether (y, x) is exact and lit: every channel's variance 0, the input's channels summed
// finite and above 0.
bool ExactLitAt(const Image &input, const Image &variance, int y, int x) {
    double in = 0;
    for (int c = 0; c < input.channels; ++c) {
        if (variance.At(variance.channels == 1 ? 0 : c, y, x) != 0) return false;
        in += input.At(c, y, x);
    }
    return std::isfinite(in) && in > 0;
}

// Whether every neighbour of (y, x) inside the frame, 3 or more, is exact and lit: the
// pixel's spread is its footprint's coverage of something bright, not a rare path.
bool AmongExactLitAt(const Image &input, const Image &variance, int y, int x) {
    int count = 0;
    for (int v = y - 1; v <= y + 1; ++v)
        for (int u = x - 1; u <= x + 1; ++u) {
            if ((u == x && v == y) || u < 0 || v < 0 || u >= input.width || v >= input.height)
                continue;
            if (!ExactLitAt(input, variance, v, u)) return false;
            ++count;
        }
    return count >= 3;
}

bool OverAt(const Image &input, const Image *variance, const Image &moved, const Image &level,
            int y, int x) {
    double in = 0, out = 0, around = 0, v = 0;
    for (int c = 0; c < input.channels; ++c) {
        if (!std::isfinite(input.At(c, y, x))) return false;
        in += input.At(c, y, x);
        out += moved.At(c, y, x);
        around += level.At(c, y, x);
        if (variance) v += variance->At(variance->channels == 1 ? 0 : c, y, x);
    }
    if (!(in > 0 && in > 16 * std::min(out, around))) return false;
    return !variance || (std::isfinite(v) && ((in - out) * (in - out) > 16 * v ||
                                              AmongExactLitAt(input, *variance, y, x)));
}

// One ring of highlights: the pixels over the test (read against the output's tent mean
// without the values kept so far) with 2 of 8 neighbours so too (or a variance), and, after
// the first ring, beside a highlight already taken.
bool HighlightRing(const Image &input, const Image *variance, int r, bool first,
                   std::vector<bool> *taken, std::vector<bool> *kept, Image *output) {
    Image moved = Moved(*output, *kept), level = Tent(moved, r);
    const int w = input.width, h = input.height;
    std::vector<bool> take(size_t(w) * h);
    bool any = false;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            if ((*taken)[size_t(y) * w + x] || !OverAt(input, variance, moved, level, y, x))
                continue;
            int neighbours = 0;
            bool beside = false;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    int v = y + dy, u = x + dx;
                    if (!(dx || dy) || v < 0 || v >= h || u < 0 || u >= w) continue;
                    if (OverAt(input, variance, moved, level, v, u)) ++neighbours;
                    if ((*taken)[size_t(v) * w + u]) beside = true;
                }
            bool ok = (variance || neighbours >= 2) && (first || beside);
            take[size_t(y) * w + x] = ok;
            any = any || ok;
        }
    for (int c = 0; c < input.channels; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                if (take[size_t(y) * w + x]) {
                    const size_t i = (size_t(c) * h + y) * w + x;
                    if (!(*kept)[i]) output->At(c, y, x) = input.At(c, y, x);
                    (*kept)[i] = true;
                    (*taken)[size_t(y) * w + x] = true;
                }
    return any;
}

// The first ring, then up to 4 more grown from it.
void Highlights(const Image &input, const Image *variance, int r, std::vector<bool> *kept,
                Image *output) {
    std::vector<bool> taken(size_t(input.width) * input.height);
    for (int ring = 0; ring < 5; ++ring)
        if (!HighlightRing(input, variance, r, ring == 0, &taken, kept, output)) break;
}

// The sum of the squared weights of the tent of radius 2s, from its 2D weights.
double SquaredWeights(int s) {
    int n = 2 * s + 1;
    std::vector<double> tent(2 * n - 1, 0);
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) tent[i + j] += 1.0 / (double(n) * n);
    double sum = 0;
    for (double a : tent)
        for (double b : tent) sum += (a * b) * (a * b);
    return sum;
}

// The mean of each plane over the tent of radius 2s around each pixel, clipped to the image,
// weighted by the tent's squared weights, from the 2D weights one by one.
Image SquaredTent(const Image &image, int s) {
    int n = 2 * s + 1;
    std::vector<double> tent(2 * n - 1, 0);
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) tent[i + j] += 1.0 / (double(n) * n);
    const int reach = n - 1;
    Image out(image.width, image.height, image.channels);
    for (int c = 0; c < image.channels; ++c)
        for (int y = 0; y < image.height; ++y)
            for (int x = 0; x < image.width; ++x) {
                double sum = 0, total = 0;
                for (int v = std::max(0, y - reach); v <= std::min(image.height - 1, y + reach);
                     ++v)
                    for (int u = std::max(0, x - reach);
                         u <= std::min(image.width - 1, x + reach); ++u) {
                        double wt = tent[v - y + reach] * tent[u - x + reach];
                        sum += wt * wt * image.At(c, v, u);
                        total += wt * wt;
                    }
                out.At(c, y, x) = float(sum / total);
            }
    return out;
}

void Scale(const Image &input, const std::vector<bool> &kept, int s, double noiseWeight,
           bool pixelNoise, Image *output) {
    Image clean(input.width, input.height, input.channels), moved = Moved(*output, kept);
    Image squared = clean;
    for (size_t i = 0; i < input.data.size(); ++i) {
        float v = input.data[i];
        if (kept[i]) continue;
        clean.data[i] = std::isfinite(v) && v > 0 ? v : 0.f;
        float e = clean.data[i] - moved.data[i];
        squared.data[i] = e * e;
    }
    Image mIn = Tent(clean, s), mOut = Tent(moved, s);
    Image mSq = pixelNoise ? SquaredTent(squared, s) : Tent(squared, s);
    double weights = SquaredWeights(s);
    for (size_t i = 0; i < output->data.size(); ++i) {
        if (kept[i]) continue;
        double a = mIn.data[i], b = mOut.data[i], q = mSq.data[i] * weights * noiseWeight;
        if (!(a > 0 && b > 0 && std::isfinite(a) && std::isfinite(b) && std::isfinite(q)))
            continue;
        double d = a - b;
        d *= d * d > q ? 1 - q / (d * d) : 0;
        output->data[i] = float(output->data[i] * ((b + d) / b));
    }
}

}  // namespace

void RestoreLocalMeans(const Image &input, int r, Image *output, const Image *variance,
                       double rebalance, bool pixelNoise, std::vector<bool> *left) {
    if (left && left->size() != input.data.size())
        throw Error("ref::RestoreLocalMeans: a kept mask one flag per value",
                    ErrorKind::Internal);
    if (variance && (variance->width != input.width || variance->height != input.height ||
                     (variance->channels != 1 && variance->channels != input.channels)))
        variance = nullptr;
    // The method's own word on what it left, else the values equal to the input's.
    std::vector<bool> kept = left ? *left : std::vector<bool>(input.data.size(), false);
    if (!left)
        for (size_t i = 0; i < kept.size(); ++i) kept[i] = output->data[i] == input.data[i];
    Highlights(input, variance, r, &kept, output);
    Scale(input, kept, 4 * r, 1, pixelNoise, output);
    Scale(input, kept, r, 1, pixelNoise, output);
    if (rebalance >= 0) Scale(input, kept, 4 * r, rebalance, pixelNoise, output);
    if (left) *left = kept;
}

void RestoreLocalMeanAt(const Image &input, int s, double noiseWeight, Image *output,
                        const std::vector<bool> *left) {
    if (left && left->size() != input.data.size())
        throw Error("ref::RestoreLocalMeanAt: a kept mask one flag per value",
                    ErrorKind::Internal);
    const int w = input.width, h = input.height, reach = 2 * s;
    // The tent's sum within the image at each place of an axis of n values.
    auto sums = [&](int n) {
        std::vector<double> sum(n, 0.0);
        for (int at = 0; at < n; ++at)
            for (int k = 0; k < n; ++k) sum[at] += std::max(0, reach + 1 - std::abs(k - at));
        return sum;
    };
    const std::vector<double> sumX = sums(w), sumY = sums(h);
    auto tent = [&](const std::vector<double> &sum, int at, int u) {
        return std::max(0, reach + 1 - std::abs(u - at)) / sum[at];
    };
    // Each value's shrunk gain (1 - q / d^2 where positive, times d / b) and whether it has one
    // (a, b > 0, all finite).
    const Image before = *output;
    const size_t n = input.data.size();
    // Whether value (c, y, x) is kept: as the method says, else equal to the input's.
    auto keptAt = [&](int c, int y, int x) {
        return left ? bool((*left)[(size_t(c) * h + y) * w + x])
                    : before.At(c, y, x) == input.At(c, y, x);
    };
    std::vector<double> gain(n, 0.0), valid(n, 0.0);
    for (int c = 0; c < input.channels; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                if (keptAt(c, y, x)) continue;
                double a = 0, b = 0, q = 0;
                for (int v = std::max(0, y - reach); v <= std::min(h - 1, y + reach); ++v)
                    for (int u = std::max(0, x - reach); u <= std::min(w - 1, x + reach); ++u) {
                        if (keptAt(c, v, u)) continue;
                        float in = input.At(c, v, u), out = before.At(c, v, u);
                        double clean = std::isfinite(in) && in > 0 ? in : 0;
                        double wt = tent(sumX, x, u) * tent(sumY, y, v);
                        a += wt * clean;
                        b += wt * out;
                        q += wt * wt * (clean - out) * (clean - out);
                    }
                q *= noiseWeight;
                if (!(a > 0 && b > 0 && std::isfinite(a) && std::isfinite(b) &&
                      std::isfinite(q)))
                    continue;
                const size_t i = (size_t(c) * h + y) * w + x;
                double d = a - b;
                gain[i] = float((d * d > q ? 1 - q / (d * d) : 0) * d / b);
                valid[i] = 1;
            }
    // The output times 1 + the tent's mean of the gains among the values that have one.
    for (int c = 0; c < input.channels; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const size_t i = (size_t(c) * h + y) * w + x;
                if (valid[i] == 0) continue;
                double num = 0, den = 0;
                for (int v = std::max(0, y - reach); v <= std::min(h - 1, y + reach); ++v)
                    for (int u = std::max(0, x - reach); u <= std::min(w - 1, x + reach); ++u) {
                        const size_t j = (size_t(c) * h + v) * w + u;
                        double wt = tent(sumX, x, u) * tent(sumY, y, v);
                        num += wt * gain[j];
                        den += wt * valid[j];
                    }
                output->At(c, y, x) = float(before.At(c, y, x) * (1 + num / den));
            }
}

namespace {

// The lower middle of the values of plane c (or of the channels' sums, c < 0) at the
// neighbours of (x, y) inside the image (with `positive`, those not <= 0 only); NaN without
// any or where one is not finite.
double MedianAround(const Image &image, int c, int y, int x, bool positive = false) {
    std::vector<double> values;
    for (int v = y - 1; v <= y + 1; ++v)
        for (int u = x - 1; u <= x + 1; ++u) {
            if ((u == x && v == y) || u < 0 || v < 0 || u >= image.width || v >= image.height)
                continue;
            double sum = 0;
            if (c >= 0)
                sum = image.At(c, v, u);
            else
                for (int k = 0; k < image.channels; ++k) sum += image.At(k, v, u);
            if (!positive || !(float(sum) <= 0)) values.push_back(float(sum));
        }
    for (double v : values)
        if (!std::isfinite(v)) return NAN;
    if (values.empty()) return NAN;
    std::sort(values.begin(), values.end());
    return values[(values.size() - 1) / 2];
}

bool SpikeOver(const Image &image, int y, int x) {
    double sum = 0;
    for (int k = 0; k < image.channels; ++k) sum += image.At(k, y, x);
    float s = std::isfinite(sum) ? float(sum) : NAN;
    double m = MedianAround(image, -1, y, x);
    return std::isfinite(s) && s > 0 && std::isfinite(m) && s > 16 * m;
}

}  // namespace

namespace {

float SumAt(const Image &image, int y, int x) {
    double sum = 0;
    for (int k = 0; k < image.channels; ++k) sum += image.At(k, y, x);
    return std::isfinite(sum) ? float(sum) : NAN;
}

bool LightAt(const Image &image, const Image &variance, int y, int x) {
    double s = SumAt(image, y, x);
    if (!std::isfinite(s) || !(s > 0)) return false;
    double v = 0;
    for (int c = 0; c < variance.channels; ++c) v += variance.At(c, y, x);
    return v <= 0.01 * 0.01 * s * s;
}

}  // namespace

size_t CutSpikes(Image *color, const Image *variance) {
    const Image given = *color;
    const bool usable = variance && variance->width == given.width &&
                        variance->height == given.height &&
                        (variance->channels == 1 || variance->channels == given.channels);
    size_t count = 0;
    for (int y = 0; y < given.height; ++y)
        for (int x = 0; x < given.width; ++x) {
            if (!SpikeOver(given, y, x)) continue;
            // Not over 512 x its neighbours' median.
            double own = 0;
            for (int k = 0; k < given.channels; ++k) own += given.At(k, y, x);
            // Over it, only beside a light (or where no variance tells lights).
            bool besideLight = !usable;
            for (int v = y - 1; v <= y + 1; ++v)
                for (int u = x - 1; u <= x + 1; ++u)
                    if (usable && (u != x || v != y) && u >= 0 && v >= 0 && u < given.width &&
                        v < given.height && LightAt(given, *variance, v, u))
                        besideLight = true;
            // Where the median is 0, the median of the neighbours above 0 instead.
            double median = MedianAround(given, -1, y, x);
            if (median == 0) median = MedianAround(given, -1, y, x, true);
            if (!(float(own) > 16 * median)) continue;
            if (!(float(own) <= 512 * median) && (besideLight || !(median > 0))) continue;
            int neighbours = 0;
            for (int v = y - 1; v <= y + 1; ++v)
                for (int u = x - 1; u <= x + 1; ++u)
                    if ((u != x || v != y) && u >= 0 && v >= 0 && u < given.width &&
                        v < given.height && SpikeOver(given, v, u))
                        ++neighbours;
            if (neighbours >= 2) continue;
            // Above each neighbour not over, in the channels' sums as floats.
            bool above = true;
            for (int v = y - 1; v <= y + 1; ++v)
                for (int u = x - 1; u <= x + 1; ++u) {
                    if ((u == x && v == y) || u < 0 || v < 0 || u >= given.width ||
                        v >= given.height || SpikeOver(given, v, u))
                        continue;
                    double a = 0, b = 0;
                    for (int k = 0; k < given.channels; ++k)
                        a += given.At(k, y, x), b += given.At(k, v, u);
                    if (!(float(b) < float(a))) above = false;
                }
            if (!above) continue;
            for (int c = 0; c < given.channels; ++c)
                color->At(c, y, x) = float(MedianAround(given, c, y, x));
            ++count;
        }
    return count;
}

std::vector<size_t> CutLightRims(Image *color, const Image &variance) {
    std::vector<size_t> rims;
    const Image given = *color;
    const int w = given.width, h = given.height;
    if (variance.width != w || variance.height != h ||
        (variance.channels != 1 && variance.channels != given.channels))
        return rims;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            if (LightAt(given, variance, y, x)) continue;
            float own = SumAt(given, y, x);
            double m = MedianAround(given, -1, y, x);
            if (!std::isfinite(own) || !(own > 0) || !std::isfinite(m) || !(own > 16 * m))
                continue;
            bool brighterLight = false, plain = false;
            for (int v = y - 2; v <= y + 2; ++v)
                for (int u = x - 2; u <= x + 2; ++u) {
                    if ((u == x && v == y) || u < 0 || v < 0 || u >= w || v >= h) continue;
                    const bool light = LightAt(given, variance, v, u);
                    if (!light && std::abs(u - x) <= 1 && std::abs(v - y) <= 1) plain = true;
                    if (light && SumAt(given, v, u) > own) brighterLight = true;
                }
            if (!brighterLight || !plain) continue;
            int lights = 0;
            for (int v = y - 4; v <= y + 4; ++v)
                for (int u = x - 4; u <= x + 4; ++u)
                    if (u >= 0 && v >= 0 && u < w && v < h && LightAt(given, variance, v, u))
                        ++lights;
            if (lights > 25) continue;
            rims.push_back(size_t(y) * w + x);
            for (int c = 0; c < given.channels; ++c) {
                std::vector<float> values;
                for (int v = y - 1; v <= y + 1; ++v)
                    for (int u = x - 1; u <= x + 1; ++u)
                        if ((u != x || v != y) && u >= 0 && v >= 0 && u < w && v < h &&
                            !LightAt(given, variance, v, u))
                            values.push_back(given.At(c, v, u));
                std::sort(values.begin(), values.end());
                color->At(c, y, x) = values[(values.size() - 1) / 2];
            }
        }
    return rims;
}

namespace {

// The most samples in a colour's last two bins, -1 without samples.
double BrightAt(const Image &histograms, int y, int x) {
    const int bins = (histograms.channels - 1) / 3;
    if (!(histograms.At(histograms.channels - 1, y, x) > 0)) return -1;
    double most = 0;
    for (int c = 0; c < 3; ++c) {
        double b = double(histograms.At(c * bins + bins - 2, y, x)) +
                   double(histograms.At(c * bins + bins - 1, y, x));
        if (b > most) most = b;
    }
    return most;
}

// Each pixel's group of 8-connected `member` pixels (-1 outside them) and the groups' pixels
// (x, y), labelled by flooding in raster order.
void LabelGroups(const std::vector<char> &member, int w, int h, std::vector<int> *group,
                 std::vector<std::vector<std::pair<int, int>>> *groups) {
    group->assign(size_t(w) * h, -1);
    groups->clear();
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            if (!member[size_t(y) * w + x] || (*group)[size_t(y) * w + x] >= 0) continue;
            std::vector<std::pair<int, int>> members{{x, y}};
            (*group)[size_t(y) * w + x] = int(groups->size());
            for (size_t k = 0; k < members.size(); ++k)
                for (int v = members[k].second - 1; v <= members[k].second + 1; ++v)
                    for (int u = members[k].first - 1; u <= members[k].first + 1; ++u)
                        if (u >= 0 && v >= 0 && u < w && v < h &&
                            (*group)[size_t(v) * w + u] < 0 && member[size_t(v) * w + u]) {
                            (*group)[size_t(v) * w + u] = int(groups->size());
                            members.push_back({u, v});
                        }
            groups->push_back(members);
        }
}

// `over` and the pixels that bridge its groups: a pixel with a bright sample, not over,
// touching two or more groups of 2 pixels or more, each with a bright sample, whose box is
// under 3 (the cluster's span) on each side. `group` and `groups` label `over`.
std::vector<char> JoinBridges(const Image &histograms, const std::vector<char> &over,
                              const std::vector<int> &group,
                              const std::vector<std::vector<std::pair<int, int>>> &groups) {
    const int w = histograms.width, h = histograms.height;
    std::vector<char> member = over;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            if (over[size_t(y) * w + x] || !(BrightAt(histograms, y, x) >= 0.5)) continue;
            std::vector<int> touched;
            for (int v = y - 1; v <= y + 1; ++v)
                for (int u = x - 1; u <= x + 1; ++u) {
                    if (u < 0 || v < 0 || u >= w || v >= h) continue;
                    int g = group[size_t(v) * w + u];
                    if (g < 0 || groups[g].size() < 2) continue;
                    bool bright = true;
                    int x0 = w, x1 = -1, y0 = h, y1 = -1;
                    for (auto [i, j] : groups[g]) {
                        if (!(BrightAt(histograms, j, i) >= 0.5)) bright = false;
                        x0 = std::min(x0, i), x1 = std::max(x1, i);
                        y0 = std::min(y0, j), y1 = std::max(y1, j);
                    }
                    if (bright && x1 - x0 < 2 && y1 - y0 < 2) touched.push_back(g);
                }
            std::sort(touched.begin(), touched.end());
            touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
            member[size_t(y) * w + x] = touched.size() >= 2;
        }
    return member;
}

}  // namespace

std::vector<size_t> CutBrightClusters(const Image &input, const Image &histograms,
                                      int searchHalf, Image *color,
                                      std::vector<size_t> *bridged) {
    const int w = input.width, h = input.height;
    std::vector<size_t> cut;
    if (bridged) bridged->clear();
    if (histograms.width != w || histograms.height != h || histograms.channels < 4) return cut;
    std::vector<char> over(size_t(w) * h, 0);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) over[size_t(y) * w + x] = SpikeOver(input, y, x);
    std::vector<int> group;
    std::vector<std::vector<std::pair<int, int>>> groups;
    LabelGroups(over, w, h, &group, &groups);
    const std::vector<char> member = JoinBridges(histograms, over, group, groups);
    LabelGroups(member, w, h, &group, &groups);
    std::vector<bool> taken(groups.size(), false);
    for (size_t g = 0; g < groups.size(); ++g) {
        const auto &members = groups[g];
        if (members.size() < 3) continue;
        int x0 = w, x1 = -1, y0 = h, y1 = -1;
        double own = 0;
        bool fits = true;
        for (auto [x, y] : members) {
            double b = BrightAt(histograms, y, x);
            if (b < 0 || b > 0.3 * double(histograms.At(histograms.channels - 1, y, x)))
                fits = false;
            own += b;
            x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y),
            y1 = std::max(y1, y);
        }
        if (!fits || x1 - x0 > 2 || y1 - y0 > 2) continue;
        double around = 0;
        int m = 0;
        for (int y = y0 - searchHalf; y <= y1 + searchHalf; ++y)
            for (int x = x0 - searchHalf; x <= x1 + searchHalf; ++x) {
                if (x < 0 || y < 0 || x >= w || y >= h) continue;
                if (x >= x0 - 1 && x <= x1 + 1 && y >= y0 - 1 && y <= y1 + 1) continue;
                around += std::max(0.0, BrightAt(histograms, y, x));
                ++m;
            }
        int64_t k = std::lround(own), t = std::max(k, int64_t(std::lround(own + around)));
        if (k < 2 || m == 0 || around > own) continue;
        // The binomial tail, each term from its log.
        double s = double(members.size()) / double(members.size() + m), tail = 0;
        for (int64_t i = k; i <= t; ++i) {
            double logTerm = std::lgamma(double(t) + 1) - std::lgamma(double(i) + 1) -
                             std::lgamma(double(t - i) + 1) + double(i) * std::log(s) +
                             double(t - i) * std::log(1 - s);
            tail += std::exp(logTerm);
        }
        taken[g] = tail < 1e-4;
    }
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            int g = group[size_t(y) * w + x];
            if (g < 0 || !taken[g]) continue;
            // A group with a pixel under 16 x its neighbours' median was joined.
            bool joined = false;
            for (auto [u, v] : groups[g])
                if (!over[size_t(v) * w + u]) joined = true;
            if (joined) {
                if (bridged) bridged->push_back(size_t(y) * w + x);
            } else {
                cut.push_back(size_t(y) * w + x);
            }
            for (int c = 0; c < input.channels; ++c) {
                std::vector<float> values;
                for (int v = y - 1; v <= y + 1; ++v)
                    for (int u = x - 1; u <= x + 1; ++u)
                        if (u >= 0 && v >= 0 && u < w && v < h && group[size_t(v) * w + u] != g)
                            values.push_back(input.At(c, v, u));
                // A value that is not finite has no order: the pixel keeps its input.
                if (values.empty() || !std::all_of(values.begin(), values.end(),
                                                   [](float v) { return std::isfinite(v); }))
                    continue;
                std::sort(values.begin(), values.end());
                color->At(c, y, x) = values[(values.size() - 1) / 2];
            }
        }
    return cut;
}

double NoiseSpread(const Image &variance, int c, int x, int y) {
    int vc = variance.channels == 1 ? 0 : c;
    double own = variance.At(vc, y, x);
    if (!(own > 0)) return -1;
    // The window's sum in raster order less its largest value: the host's order, so that the
    // two agree to the bit (a sorted sum differs in the last bits).
    double sum = 0, largest = 0;
    int count = 0;
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
            int yy = y + dy, xx = x + dx;
            if (yy < 0 || yy >= variance.height || xx < 0 || xx >= variance.width) continue;
            double v = variance.At(vc, yy, xx);
            if (!std::isfinite(v) || v < 0) return -1;
            sum += v;
            largest = std::max(largest, v);
            ++count;
        }
    double rest = count > 1 ? (sum - largest) / (count - 1) : 0;
    return std::sqrt(std::max(own, rest));
}

size_t BoundToNoise(const Image &input, const Image &variance, double k, Image *output) {
    size_t clamped = 0;
    for (int y = 0; y < input.height; ++y)
        for (int x = 0; x < input.width; ++x) {
            // Each channel's allowed distance from its input (-1: left), and the largest
            // share t of the pixel's move that every channel allows.
            std::vector<double> sd(input.channels, -1);
            double t = 1;
            for (int c = 0; c < input.channels; ++c) {
                double in = input.At(c, y, x), out = output->At(c, y, x);
                double spread = NoiseSpread(variance, c, x, y);
                if (!std::isfinite(in) || !std::isfinite(out)) continue;
                // Without a spread only the floor: not below 0 where the input is not
                // negative, the channel alone.
                if (spread < 0) {
                    if (in >= 0 && out < 0) {
                        output->At(c, y, x) = 0;
                        ++clamped;
                    }
                    continue;
                }
                sd[c] = k * spread;
                // Not below 0 where the input is not negative.
                double low = in >= 0 ? std::max(0.0, in - sd[c]) : in - sd[c];
                double allowed = out < in ? in - low : sd[c];
                if (std::fabs(out - in) > allowed)
                    t = std::min(t, allowed / std::fabs(out - in));
            }
            if (t == 1) continue;
            for (int c = 0; c < input.channels; ++c) {
                if (sd[c] < 0) continue;
                double in = input.At(c, y, x), out = output->At(c, y, x);
                double low = in >= 0 ? std::max(0.0, in - sd[c]) : in - sd[c];
                float moved = float(std::clamp(in + t * (out - in), low, in + sd[c]));
                if (moved != output->At(c, y, x)) {
                    output->At(c, y, x) = moved;
                    ++clamped;
                }
            }
        }
    return clamped;
}

size_t BoundToInputRange(const Image &input, const Image &variance, int radius, double k,
                         Image *output) {
    size_t moved = 0;
    for (int y = 0; y < input.height; ++y)
        for (int x = 0; x < input.width; ++x) {
            // Each channel's range (none where the input or output is not finite, or a
            // variance of the 3x3 window is not), and the largest share t of the pixel's move
            // that keeps every channel in its range.
            std::vector<double> lo(input.channels), hi(input.channels);
            std::vector<bool> bounded(input.channels, false);
            double t = 1;
            for (int c = 0; c < input.channels; ++c) {
                double in = input.At(c, y, x), out = output->At(c, y, x);
                double spread = NoiseSpread(variance, c, x, y);
                if (spread < 0 || !std::isfinite(in) || !std::isfinite(out)) continue;
                bounded[c] = true;
                double least = in, most = in;
                for (int dy = -radius; dy <= radius; ++dy)
                    for (int dx = -radius; dx <= radius; ++dx) {
                        int yy = y + dy, xx = x + dx;
                        if (yy < 0 || yy >= input.height || xx < 0 || xx >= input.width)
                            continue;
                        double q = input.At(c, yy, xx);
                        if (!std::isfinite(q)) continue;
                        if (q < least) least = q;
                        if (q > most) most = q;
                    }
                // Widened by a slack of the window's scale: a pixel that is its window's
                // extreme and a fit a rounding beyond it would otherwise take every channel
                // back to its input.
                double slack = 1e-5 * std::max(std::fabs(least), std::fabs(most));
                lo[c] = least - k * spread - slack;
                hi[c] = most + k * spread + slack;
                if (out > hi[c]) t = std::min(t, (hi[c] - in) / (out - in));
                if (out < lo[c]) t = std::min(t, (in - lo[c]) / (in - out));
            }
            if (t == 1) continue;
            for (int c = 0; c < input.channels; ++c) {
                if (!bounded[c]) continue;
                double in = input.At(c, y, x), out = output->At(c, y, x);
                float value = float(std::clamp(in + t * (out - in), lo[c], hi[c]));
                if (value != output->At(c, y, x)) {
                    output->At(c, y, x) = value;
                    ++moved;
                }
            }
        }
    return moved;
}

Image FrameNoise(const Image &color, const Image *albedo) {
    const int w = color.width, h = color.height;
    Image out(w, h, color.channels);
    for (int c = 0; c < color.channels; ++c) {
        auto a = [&](int x, int y) {
            if (!albedo) return 1.0;
            double v = albedo->At(albedo->channels == 1 ? 0 : c, y, x);
            return v > 0.02 ? v : 1.0;
        };
        // z in float, as a float frame holds it.
        auto z = [&](int x, int y) { return double(color.At(c, y, x) / float(a(x, y))); };
        auto inside = [&](int x, int y) { return x >= 0 && x < w && y >= 0 && y < h; };
        // e at (x, y), or NaN.
        auto e = [&](int x, int y) {
            const int d[4][2] = {{1, 0}, {0, 1}, {1, 1}, {-1, 1}};  // (dx, dy)
            std::vector<double> r2;
            for (const auto &o : d) {
                if (!inside(x - o[0], y - o[1]) || !inside(x + o[0], y + o[1])) continue;
                double r = z(x, y) - (z(x - o[0], y - o[1]) + z(x + o[0], y + o[1])) / 2;
                if (!std::isfinite(r * r)) return std::nan("");
                r2.push_back(r * r / 1.5);
            }
            if (r2.empty()) return std::nan("");
            double m = *std::min_element(r2.begin(), r2.end());
            return m / (r2.size() == 4 ? 0.0504 : 0.4549);
        };
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                std::vector<double> window;
                for (int v = y - 2; v <= y + 2; ++v)
                    for (int u = x - 2; u <= x + 2; ++u)
                        if (inside(u, v) && std::isfinite(float(e(u, v))))
                            window.push_back(float(e(u, v)));
                if (window.empty()) continue;
                std::sort(window.begin(), window.end());
                out.At(c, y, x) =
                    float(window[(window.size() - 1) / 2] / 1.165 * a(x, y) * a(x, y));
            }
    }
    return out;
}

}  // namespace mcd::ref
