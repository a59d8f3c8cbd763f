#include "host/metrics.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "host/error.h"

namespace mcd {
namespace {

double Srgb(double v) {
    v = std::clamp(v, 0.0, 1.0);
    return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1 / 2.4) - 0.055;
}

// Luminance of the display-encoded image, one plane.
std::vector<double> DisplayLuminance(const Image &image) {
    std::vector<double> y(image.PixelCount());
    for (int py = 0; py < image.height; ++py)
        for (int px = 0; px < image.width; ++px) {
            size_t i = size_t(py) * image.width + px;
            if (image.channels >= 3) {
                double r = image.At(0, py, px), g = image.At(1, py, px),
                       b = image.At(2, py, px);
                y[i] = 0.2126 * Srgb(std::isfinite(r) ? r : 0) +
                       0.7152 * Srgb(std::isfinite(g) ? g : 0) +
                       0.0722 * Srgb(std::isfinite(b) ? b : 0);
            } else {
                double v = image.At(0, py, px);
                y[i] = Srgb(std::isfinite(v) ? v : 0);
            }
        }
    return y;
}

// Mean luminance of the image over the reference's, over the pixels finite in the image.
double BrightnessRatio(const Image &image, const Image &reference) {
    double sumImage = 0, sumReference = 0;
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) {
            double v = Luminance(image, y, x);
            if (!std::isfinite(v)) continue;
            sumImage += v;
            sumReference += Luminance(reference, y, x);
        }
    return sumReference > 0 ? sumImage / sumReference
                            : std::numeric_limits<double>::quiet_NaN();
}

// Separable Gaussian blur (sigma 1.5, radius 5), clamped at the borders.
std::vector<double> Blur(const std::vector<double> &in, int w, int h) {
    double taps[11], sum = 0;
    for (int k = -5; k <= 5; ++k) sum += taps[k + 5] = std::exp(-k * k / (2 * 1.5 * 1.5));
    for (double &t : taps) t /= sum;
    std::vector<double> tmp(in.size()), out(in.size());
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            double s = 0;
            for (int k = -5; k <= 5; ++k)
                s += taps[k + 5] * in[size_t(y) * w + std::clamp(x + k, 0, w - 1)];
            tmp[size_t(y) * w + x] = s;
        }
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            double s = 0;
            for (int k = -5; k <= 5; ++k)
                s += taps[k + 5] * tmp[size_t(std::clamp(y + k, 0, h - 1)) * w + x];
            out[size_t(y) * w + x] = s;
        }
    return out;
}

}  // namespace

double Luminance(const Image &image, int y, int x) {
    if (image.channels < 3) return image.At(0, y, x);
    return 0.2126 * image.At(0, y, x) + 0.7152 * image.At(1, y, x) + 0.0722 * image.At(2, y, x);
}

ErrorMetrics CompareImages(const Image &image, const Image &reference) {
    if (image.width != reference.width || image.height != reference.height)
        throw Error(fmt::format("cannot compare a {}x{} image with a {}x{} reference",
                                image.width, image.height, reference.width, reference.height),
                    ErrorKind::InvalidArgument);
    if (image.channels != reference.channels && (image.channels < 3 || reference.channels < 3))
        throw Error(fmt::format("cannot compare a {}-channel image with a {}-channel reference",
                                image.channels, reference.channels),
                    ErrorKind::InvalidArgument);
    int channels = std::min(std::min(image.channels, reference.channels), 3);
    if (channels < 1)
        throw Error("cannot compare images without channels", ErrorKind::InvalidArgument);
    ErrorMetrics m;
    double rel = 0, sq = 0;
    size_t count = 0;
    for (int c = 0; c < channels; ++c)
        for (int y = 0; y < image.height; ++y)
            for (int x = 0; x < image.width; ++x) {
                double v = image.At(c, y, x), r = reference.At(c, y, x);
                if (!std::isfinite(r))
                    throw Error(
                        fmt::format("the reference has a non-finite value at ({}, {})", x, y),
                        ErrorKind::NonFiniteInput);
                if (!std::isfinite(v)) {
                    ++m.nonFinite;
                    continue;
                }
                rel += (v - r) * (v - r) / (r * r + 0.01);
                double d = Srgb(v) - Srgb(r);
                sq += d * d;
                ++count;
            }
    m.brightness = BrightnessRatio(image, reference);
    m.relMse = count ? rel / count : 0;
    double mse = count ? sq / count : 0;
    m.psnr = mse > 0 ? 10 * std::log10(1 / mse) : std::numeric_limits<double>::infinity();
    if (m.nonFinite > 0) {
        // A result with NaN/Inf in it is as wrong as it gets: it must never score well.
        m.relMse = std::numeric_limits<double>::infinity();
        m.psnr = 0;
        m.ssim = 0;
        return m;
    }

    // SSIM (Wang et al. 2004) on display luminance, Gaussian-weighted local statistics.
    int w = image.width, h = image.height;
    std::vector<double> a = DisplayLuminance(image), b = DisplayLuminance(reference);
    std::vector<double> aa(a.size()), bb(a.size()), ab(a.size());
    for (size_t i = 0; i < a.size(); ++i)
        aa[i] = a[i] * a[i], bb[i] = b[i] * b[i], ab[i] = a[i] * b[i];
    std::vector<double> ma = Blur(a, w, h), mb = Blur(b, w, h), saa = Blur(aa, w, h),
                        sbb = Blur(bb, w, h), sab = Blur(ab, w, h);
    const double c1 = 0.01 * 0.01, c2 = 0.03 * 0.03;
    double ssim = 0;
    for (size_t i = 0; i < a.size(); ++i) {
        double va = saa[i] - ma[i] * ma[i], vb = sbb[i] - mb[i] * mb[i],
               cov = sab[i] - ma[i] * mb[i];
        ssim += (2 * ma[i] * mb[i] + c1) * (2 * cov + c2) /
                ((ma[i] * ma[i] + mb[i] * mb[i] + c1) * (va + vb + c2));
    }
    m.ssim = ssim / double(a.size());
    return m;
}

ElementDifference MeasureDifference(const Image &image, const Image &reference) {
    if (image.Size() != reference.Size())
        throw Error(fmt::format("difference: {} elements against a reference of {}",
                                image.Size(), reference.Size()),
                    ErrorKind::InvalidArgument);
    ElementDifference d;
    double num = 0, den = 0, maxDiff = 0, maxRef = 0;
    for (size_t i = 0; i < reference.data.size(); ++i) {
        double x = image.data[i], r = reference.data[i];
        if (std::isfinite(x) != std::isfinite(r)) {
            ++d.parity;
            continue;
        }
        if (!std::isfinite(r)) continue;
        num += (x - r) * (x - r);
        den += r * r;
        maxDiff = std::max(maxDiff, std::fabs(x - r));
        maxRef = std::max(maxRef, std::fabs(r));
    }
    d.nmse = den > 0 ? num / den : num;
    d.maxRel = maxRef > 0 ? maxDiff / maxRef : maxDiff;
    return d;
}

}  // namespace mcd
