// The error estimate's denominator floor (--auto-noise-cap, cpu_reference/auto_combine.h):
// a case where it helps. At a firefly (one pixel of a huge variance) under a dark guide,
// SURE's terms are of the order of v / (g^2 + 0.01); averaged over the window they swamp
// the candidates' errors everywhere around it and set the weights by that one pixel's
// noisy estimate. With the floor v / cap its terms are of the order of cap.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "cpu_reference/auto_combine.h"
#include "harness/inputs.h"
#include "host/metrics.h"

namespace mcd {
namespace {

using test::SeedFromName;

// auto's steps on the CPU reference: each candidate's SURE against a guide, averaged over
// 25x25 windows, combined by the relative rule (auto's defaults).
Image Combine(const Image &color, const Image &variance, const std::vector<Image> &outputs,
              const std::vector<Image> &perturbed, const Image &probe, const Image &guide,
              double epsilon, double noiseCap) {
    Image errors(color.width, color.height, int(outputs.size()));
    for (size_t k = 0; k < outputs.size(); ++k) {
        Image e = ref::AutoEstimate(color, variance, probe, guide, outputs[k], perturbed[k],
                                    epsilon, noiseCap);
        for (size_t p = 0; p < e.PixelCount(); ++p)
            errors.data[k * e.PixelCount() + p] = e.data[p];
    }
    Image smooth = ref::AutoSmooth(errors, 12);
    return ref::AutoCombineRelative(color, outputs, smooth, variance, 2, 1e-5, 30, 4).color;
}

// A wall of 0.5 with noise of standard deviation 1 (a low-spp frame) and, at its centre,
// one sample of a small light: the pixel reads 300 with a variance of 1e4 (its mean is 0.5,
// a 3-sigma draw). Candidate "smooth" is the truth, as a filter that removed the noise and
// the firefly would give, with no divergence; candidate "half" keeps half the noise
// (divergence 1/2). The guide is the truth, dark at the firefly. The firefly's SURE terms
// (3.1e5 for smooth, 8.6e4 for half) raise both candidates' window errors to hundreds and
// "half" takes most of the weight in the 25x25 windows around it; with the floor (cap 100)
// they are 797 and 224, of the order of the wall's own errors (1 for half), and smooth
// keeps a larger share. The floor scales the pixel's terms of every candidate alike, so it
// helps only where they would otherwise outweigh the window's ordinary errors, as here.
TEST(AutoNoiseCap, KeepsOneFireflyFromSwampingItsWindow) {
    const int w = 41, h = 41, cx = 20, cy = 20;
    std::mt19937_64 rng(SeedFromName("auto noise cap"));
    std::normal_distribution<double> unit(0, 1);
    std::bernoulli_distribution coin(0.5);
    const double epsilon = 0.5;
    Image truth(w, h, 3), color(w, h, 3), variance(w, h, 3), probe(w, h, 3);
    for (size_t i = 0; i < color.data.size(); ++i) {
        truth.data[i] = 0.5f;
        variance.data[i] = 1.f;
        color.data[i] = float(0.5 + unit(rng));
        probe.data[i] = coin(rng) ? 1.f : -1.f;
    }
    for (int c = 0; c < 3; ++c) color.At(c, cy, cx) = 300, variance.At(c, cy, cx) = 1e4f;
    Image half = color, halfPerturbed = color;
    for (size_t i = 0; i < color.data.size(); ++i) {
        half.data[i] = 0.5f * (truth.data[i] + color.data[i]);
        halfPerturbed.data[i] =
            half.data[i] + float(0.5 * epsilon * std::sqrt(variance.data[i]) * probe.data[i]);
    }
    std::vector<Image> outputs = {truth, half}, perturbed = {truth, halfPerturbed};
    const Image &guide = truth;
    Image capped = Combine(color, variance, outputs, perturbed, probe, guide, epsilon, 100);
    Image uncapped = Combine(color, variance, outputs, perturbed, probe, guide, epsilon, 0);
    double withCap = CompareImages(capped, truth).relMse;
    double without = CompareImages(uncapped, truth).relMse;
    double halfError = CompareImages(half, truth).relMse;
    fmt::print("relMSE: with the cap {:.4g}, without {:.4g}; candidate half alone {:.4g}\n",
               withCap, without, halfError);
    EXPECT_LT(withCap, 0.8 * without);
}

}  // namespace
}  // namespace mcd
