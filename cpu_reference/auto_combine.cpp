#include "cpu_reference/auto_combine.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace mcd::ref {

Image AutoEstimate(const Image &color, const Image &variance, const Image &probe,
                   const Image &guide, const Image &output, const Image &perturbed,
                   double epsilon, double noiseCap, const Image *offset) {
    int w = color.width, h = color.height, channels = color.channels;
    Image error(w, h, 1);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            double sum = 0;
            for (int c = 0; c < channels; ++c) {
                double f = output.At(c, y, x), noisy = color.At(c, y, x);
                double v = variance.At(c, y, x);
                // SURE: the residual, less the noise, plus twice the noise times the
                // divergence (its Monte Carlo estimate from the perturbed run).
                double divergence = probe.At(c, y, x) * (perturbed.At(c, y, x) - f) /
                                    (epsilon * std::sqrt(std::max(v, 0.0)));
                double term = (f - noisy) * (f - noisy) - v;
                if (offset) term += offset->At(c, y, x);
                if (v > 0) term += 2 * v * divergence;
                double g = guide.At(c, y, x);
                double d = g * g + kAutoRelOffset;
                // A pixel whose mean is mostly noise weighs at most noiseCap / v (a NaN
                // guide stays NaN).
                double floorD = (v > 0 ? v : 0.0) / noiseCap;
                if (noiseCap > 0 && floorD > d) d = floorD;
                sum += term / d;
            }
            error.At(0, y, x) = float(sum / channels);
        }
    return error;
}

Image AutoNoise(const Image &color, const Image *albedo, int radius) {
    int w = color.width, h = color.height, channels = color.channels;
    constexpr float kAlbedoFloor = 0.02f;
    // E[min over the 4 directions of r^2 / 1.5] for unit Gaussian noise (simulated).
    constexpr double kMinMean = 0.27848;
    // Neighbours whose albedos differ by more than this factor are not averaged together.
    constexpr float kDivisorRatio = 1.25f;
    const int directions[4][2] = {{1, 0}, {0, 1}, {1, 1}, {1, -1}};
    Image out(w, h, channels);
    for (int c = 0; c < channels; ++c) {
        // The demodulation's divisor and z at every pixel of this channel.
        Image divisor(w, h, 1), z(w, h, 1);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                float a = albedo ? albedo->At(std::min(c, albedo->channels - 1), y, x) : 1.f;
                divisor.At(0, y, x) = std::isfinite(a) && a > kAlbedoFloor ? a : 1.f;
                z.At(0, y, x) = float(double(color.At(c, y, x)) / divisor.At(0, y, x));
            }
        // Whether each pixel is divided by its albedo.
        auto divided = [&](int x, int y) {
            float a = albedo ? albedo->At(std::min(c, albedo->channels - 1), y, x) : 1.f;
            return albedo && std::isfinite(a) && a > kAlbedoFloor;
        };
        // Each pixel's smallest squared second difference, scaled to v_z's units.
        Image smallest(w, h, 1);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                double best = std::numeric_limits<double>::quiet_NaN();
                int fit = 0;
                for (const auto &d : directions) {
                    int x0 = x - d[0], y0 = y - d[1], x1 = x + d[0], y1 = y + d[1];
                    if (x0 < 0 || x1 >= w || std::min(y0, y1) < 0 || std::max(y0, y1) >= h)
                        continue;
                    ++fit;
                    double r =
                        double(z.At(0, y, x)) - (double(z.At(0, y0, x0)) + z.At(0, y1, x1)) / 2;
                    double q = r * r / 1.5;
                    if (std::isnan(best) || q < best) best = q;
                }
                // Over its mean for unit Gaussian noise: the minimum of 4 (inside), or one
                // value (the border rows and columns have one direction).
                smallest.At(0, y, x) = float(fit == 4 ? best / kMinMean : best);
            }
        // Its mean over the window's pixels demodulated alike (both divided, by albedos
        // within a factor kDivisorRatio, or both not): each is in its own z's units.
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                double sum = 0;
                int n = 0;
                float a = divisor.At(0, y, x);
                for (int v = std::max(0, y - radius); v <= std::min(h - 1, y + radius); ++v)
                    for (int u = std::max(0, x - radius); u <= std::min(w - 1, x + radius);
                         ++u) {
                        float b = divisor.At(0, v, u);
                        if (divided(u, v) != divided(x, y) || b > a * kDivisorRatio ||
                            b * kDivisorRatio < a)
                            continue;
                        if (std::isfinite(smallest.At(0, v, u))) {
                            sum += smallest.At(0, v, u);
                            ++n;
                        }
                    }
                out.At(c, y, x) = n > 0 ? float(sum / n * a * a) : 0.f;
            }
    }
    return out;
}

Image AutoSmooth(const Image &errors, int radius) {
    int w = errors.width, h = errors.height;
    Image smooth(w, h, errors.channels);
    for (int p = 0; p < errors.channels; ++p)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                double sum = 0, n = 0;
                for (int v = std::max(0, y - radius); v <= std::min(h - 1, y + radius); ++v)
                    for (int u = std::max(0, x - radius); u <= std::min(w - 1, x + radius);
                         ++u) {
                        double e = errors.At(p, v, u);
                        if (!std::isfinite(e)) continue;
                        // The tent: 1 at the window's edge, radius + 1 at its centre.
                        double weight = double(radius + 1 - std::abs(u - x)) *
                                        double(radius + 1 - std::abs(v - y));
                        sum += weight * e;
                        n += weight;
                    }
                smooth.At(p, y, x) =
                    n > 0 ? float(sum / n) : std::numeric_limits<float>::quiet_NaN();
            }
    return smooth;
}

double AutoGuideDistance(const Image &guide, int y, int x, int v, int u) {
    double sum = 0;
    for (int c = 0; c < guide.channels; ++c) {
        double a = guide.At(c, y, x), b = guide.At(c, v, u);
        double top = (a - b) * (a - b), bottom = a * a + b * b + kAutoRelOffset;
        // A value that is not finite tells nothing: the tent alone. So does one whose
        // squares overflow the kernel's float (a guide above about 1.8e19).
        if (!std::isfinite(float(top)) || !std::isfinite(float(bottom))) continue;
        double d = top / bottom;
        if (std::isfinite(d)) sum += d;
    }
    return sum / guide.channels;
}

Image AutoSmoothGuided(const Image &errors, const Image &guide, int radius, double bandwidth) {
    int w = errors.width, h = errors.height;
    Image smooth(w, h, errors.channels);
    std::vector<double> sum(errors.channels), n(errors.channels);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            std::fill(sum.begin(), sum.end(), 0.0);
            std::fill(n.begin(), n.end(), 0.0);
            for (int v = std::max(0, y - radius); v <= std::min(h - 1, y + radius); ++v)
                for (int u = std::max(0, x - radius); u <= std::min(w - 1, x + radius); ++u) {
                    // At least exp(-40): the kernel's float products keep it.
                    double exponent = std::min(
                        AutoGuideDistance(guide, y, x, v, u) / (bandwidth * bandwidth), 40.0);
                    double weight = double(radius + 1 - std::abs(u - x)) *
                                    double(radius + 1 - std::abs(v - y)) * std::exp(-exponent);
                    for (int p = 0; p < errors.channels; ++p) {
                        double e = errors.At(p, v, u);
                        if (!std::isfinite(e)) continue;
                        sum[p] += weight * e;
                        n[p] += weight;
                    }
                }
            for (int p = 0; p < errors.channels; ++p)
                smooth.At(p, y, x) =
                    n[p] > 0 ? float(sum[p] / n[p]) : std::numeric_limits<float>::quiet_NaN();
        }
    return smooth;
}

AutoCombined AutoCombine(const Image &color, const std::vector<Image> &candidates,
                         const Image &errors, bool select, double power, double floorError,
                         bool medianUnderFloor) {
    int w = color.width, h = color.height, channels = color.channels;
    int count = int(candidates.size());
    AutoCombined out{Image(w, h, channels), Image(w, h, count)};
    std::vector<double> weight(count);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            // The candidates with a finite estimate and output here, and the best of them.
            int best = -1;
            std::vector<bool> usable(count);
            for (int k = 0; k < count; ++k) {
                usable[k] = std::isfinite(errors.At(k, y, x));
                for (int c = 0; c < channels; ++c)
                    usable[k] = usable[k] && std::isfinite(candidates[k].At(c, y, x));
                if (usable[k] && (best < 0 || errors.At(k, y, x) < errors.At(best, y, x)))
                    best = k;
            }
            double total = 0;
            for (int k = 0; k < count; ++k) {
                if (select)
                    weight[k] = k == best ? 1 : 0;
                else
                    weight[k] =
                        usable[k]
                            ? std::pow(std::max(double(errors.At(k, y, x)), floorError), -power)
                            : 0;
                total += weight[k];
            }
            // No weights where their total is 0 or beyond a float (the kernel sums floats).
            bool none = !(total > 0) || !std::isfinite(float(total));
            // The estimates tell nothing where all are under the floor: the median.
            bool allUnder = medianUnderFloor && !select;
            int usableCount = 0;
            for (int k = 0; k < count; ++k)
                if (usable[k]) {
                    ++usableCount;
                    allUnder = allUnder && errors.At(k, y, x) < float(floorError);
                }
            // The median needs no weights: it holds even where their total overflows.
            bool median = allUnder && usableCount > 0;
            for (int k = 0; k < count; ++k)
                out.weights.At(k, y, x) = none ? 0.f : float(weight[k] / total);
            for (int c = 0; c < channels; ++c) {
                if (median) {
                    std::vector<float> values;
                    for (int k = 0; k < count; ++k)
                        if (usable[k]) values.push_back(candidates[k].At(c, y, x));
                    std::sort(values.begin(), values.end());
                    size_t n = values.size();
                    out.color.At(c, y, x) =
                        n % 2 ? values[n / 2] : 0.5f * (values[n / 2 - 1] + values[n / 2]);
                    continue;
                }
                double sum = 0;
                for (int k = 0; k < count; ++k)
                    if (!none && weight[k] > 0)
                        sum += weight[k] / total * candidates[k].At(c, y, x);
                out.color.At(c, y, x) = none ? color.At(c, y, x) : float(sum);
            }
        }
    return out;
}

AutoCombined AutoCombineRelative(const Image &color, const std::vector<Image> &candidates,
                                 const Image &errors, const Image &variance, double power,
                                 double floorError, double noiseLimit, double darkLimit) {
    int w = color.width, h = color.height, channels = color.channels;
    int count = int(candidates.size());
    AutoCombined out{Image(w, h, channels), Image(w, h, count)};
    std::vector<double> weight(count);
    std::vector<bool> usable(count);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            int usableCount = 0;
            bool allUnder = true;
            double total = 0;
            for (int k = 0; k < count; ++k) {
                double e = errors.At(k, y, x);
                usable[k] = std::isfinite(e);
                for (int c = 0; c < channels; ++c)
                    usable[k] = usable[k] && std::isfinite(candidates[k].At(c, y, x));
                weight[k] = usable[k] ? std::pow(std::max(e, floorError), -power) : 0;
                total += weight[k];
                if (usable[k]) {
                    ++usableCount;
                    allUnder = allUnder && e < float(floorError);
                }
            }
            bool none = !(total > 0) || !std::isfinite(float(total));
            // Channel c's value of least weighted relative squared error.
            auto value = [&](int c, bool equal, double limit) {
                double num = 0, den = 0, mean = 0;
                for (int k = 0; k < count; ++k) {
                    double wk = equal ? (usable[k] ? 1.0 : 0.0) : weight[k];
                    if (wk > 0)
                        mean += wk / (equal ? usableCount : total) * candidates[k].At(c, y, x);
                }
                double floorSquare = limit > 0 ? mean * mean / limit : 0;
                for (int k = 0; k < count; ++k) {
                    double wk = equal ? (usable[k] ? 1.0 : 0.0) : weight[k];
                    if (!(wk > 0)) continue;
                    double v = candidates[k].At(c, y, x);
                    double square = std::max(v * v, floorSquare);
                    if (!std::isfinite(float(square))) continue;
                    double a = wk / (square + kAutoRelOffset);
                    num += a * v;
                    den += a;
                }
                return den > 0 && std::isfinite(float(den)) ? num / den : mean;
            };
            bool equal = usableCount > 0 && allUnder, noisy = false;
            if (usableCount > 0 && !equal) {
                double ratio = 0;
                for (int c = 0; c < channels; ++c) {
                    double u = value(c, true, 0);
                    ratio += variance.At(c, y, x) / (u * u + kAutoRelOffset);
                }
                noisy = equal = ratio / channels > noiseLimit;
            }
            for (int k = 0; k < count; ++k)
                out.weights.At(k, y, x) = equal  ? (usable[k] ? 1.f / usableCount : 0.f)
                                          : none ? 0.f
                                                 : float(weight[k] / total);
            for (int c = 0; c < channels; ++c)
                out.color.At(c, y, x) = equal || !none
                                            ? float(value(c, equal, noisy ? 0 : darkLimit))
                                            : color.At(c, y, x);
        }
    return out;
}

}  // namespace mcd::ref
