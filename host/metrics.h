// Error metrics of ARCHITECTURE.md ("Frames, layers and error"), over the first three channels
// (or one).
#pragma once

#include "host/image.h"

namespace mcd {

struct ErrorMetrics {
    double relMse = 0;  // mean((x - r)^2 / (r^2 + 0.01)), every channel
    double psnr = 0;    // dB, on [0,1]-clamped sRGB-encoded values; +inf when equal
    double ssim = 0;    // mean SSIM of the luminance of those values (Gaussian window 1.5)
    // Mean linear luminance (Rec. 709 weights; one channel: itself) of x over r's, over the
    // pixels finite in x: relMSE alone can be bought by darkening. NaN when r's is not > 0.
    double brightness = 0;
    size_t nonFinite = 0;  // elements of x that are NaN/Inf: then relMSE inf, PSNR 0, SSIM 0
};

// Linear luminance of a pixel, Rec. 709 weights (one channel: itself), as `brightness` sums.
double Luminance(const Image &image, int y, int x);

// Throws mcd::Error when the sizes or channel counts differ (3 or more compare the first
// three) or the reference has non-finite values.
ErrorMetrics CompareImages(const Image &image, const Image &reference);

// Element-wise distance of a computed image from its reference (a GPU stage from the CPU
// reference's), over every channel, for `mcdenoise diff` and the tests.
struct ElementDifference {
    // Normalised MSE: sum (x - r)^2 / sum r^2 over the elements finite on both sides (the
    // numerator alone when the reference is all 0).
    double nmse = 0;
    double maxRel = 0;  // max |x - r| / max |r| over the same elements (or max |x - r|)
    size_t parity = 0;  // elements finite on one side only
};

// Throws mcd::Error when the element counts differ.
ElementDifference MeasureDifference(const Image &image, const Image &reference);

}  // namespace mcd
