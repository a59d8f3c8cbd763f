// The built-in renderer: layers agree with each other, frames are deterministic for any
// thread count, the estimator is unbiased, bad arguments are refused.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "harness/compare.h"
#include "harness/errors.h"
#include "tools/render/renderer.h"

namespace mcd::test {
namespace {

using render::RenderOptions;

const Image &Layer(const render::RenderResult &r, const std::string &name) {
    for (const auto &[n, image] : r.layers)
        if (n == name) return image;
    throw Error("no layer " + name);
}

render::RenderResult RenderCornell(int w, int h, int spp, uint64_t seed, unsigned layers,
                                   int threads = 0) {
    static const render::Scene scene = render::BuildScene("cornell");
    RenderOptions o;
    o.width = w, o.height = h, o.spp = spp, o.seed = seed, o.layers = layers,
    o.threads = threads;
    return render::Render(scene, o);
}

// RHF Algorithm 1 by hand: v -> v^(1/2.2)/2.5, 20 bins, bins 0..18 cover [0,1] linearly.
TEST(RenderHistogram, BinsByHand) {
    float h[60] = {};
    double zero[3] = {0, -5, 0};  // negatives clamp to 0: all weight in bin 0
    render::AddToHistogram(zero, 20, h);
    EXPECT_FLOAT_EQ(h[0], 1.f);
    EXPECT_FLOAT_EQ(h[20], 1.f);
    float g[60] = {};
    // v = 2.5^2.2 compresses to exactly 1: the boundary between the last linear bin and
    // the saturation bin, all weight on bin 18.
    double one[3] = {std::pow(2.5, 2.2), 0, 0};
    render::AddToHistogram(one, 20, g);
    EXPECT_NEAR(g[18], 1.f, 1e-5);
    EXPECT_NEAR(g[19], 0.f, 1e-5);
    float s[60] = {};
    double huge[3] = {1e9, 0, 0};  // saturates at 2: all weight on the last bin
    render::AddToHistogram(huge, 20, s);
    EXPECT_NEAR(s[19], 1.f, 1e-6);
    float m[60] = {};
    double mid[3] = {std::pow(0.5 * 2.5, 2.2), 0, 0};  // compresses to 0.5: fbin 9, bin 9
    render::AddToHistogram(mid, 20, m);
    EXPECT_NEAR(m[9], 1.f, 1e-5);
}

// At 1 spp a pixel's colour is its one sample: hist bins that sample, zhist the sample
// over the pixel's pivot (the sample itself where a channel's pivot is 0). The pivot comes
// with zhist, and the layers are not in "all".
TEST(RenderLayers, ZHistogramsBinColorOverPivot) {
    // fireflies: some pixels there have pivot 0.
    RenderOptions o;
    o.width = 32, o.height = 32, o.spp = 1, o.seed = 3;
    o.layers = render::ParseLayerGroups("hist,zhist");
    render::RenderResult r = render::Render(render::BuildScene("fireflies"), o);
    const Image &color = Layer(r, "color"), &pivot = Layer(r, "pivot"),
                &hist = Layer(r, "hist"), &zhist = Layer(r, "zhist");
    ASSERT_EQ(zhist.channels, hist.channels);
    int zeroPivots = 0;
    for (int y = 0; y < color.height; ++y)
        for (int x = 0; x < color.width; ++x) {
            double c3[3], z3[3];
            for (int c = 0; c < 3; ++c) {
                c3[c] = color.At(c, y, x);
                float a = pivot.At(c, y, x);
                z3[c] = a > 0 ? c3[c] / a : c3[c];
                zeroPivots += a == 0;
            }
            float expected[2][60] = {};
            render::AddToHistogram(c3, 20, expected[0]);
            render::AddToHistogram(z3, 20, expected[1]);
            for (int b = 0; b < 60; ++b) {
                // The colour is the float of the double sample: bins agree to its rounding.
                ASSERT_NEAR(hist.At(b, y, x), expected[0][b], 1e-5) << x << "," << y;
                ASSERT_NEAR(zhist.At(b, y, x), expected[1][b], 1e-5) << x << "," << y;
            }
            EXPECT_EQ(zhist.At(60, y, x), 1.f);
        }
    EXPECT_GT(zeroPivots, 0) << "fireflies should have pixels with pivot 0";
    EXPECT_EQ(render::ParseLayerGroups("all") & render::kLayersZHist, 0u);
}

// The half-buffers split the samples by parity: their mean weighted by ceil(n/2) and
// floor(n/2) is color, and the same seed gives the same color with or without them; at
// 1 spp half0 is the sample and half1 is 0. Not in "all".
TEST(RenderLayers, HalvesSplitTheSamples) {
    for (int spp : {7, 1}) {
        RenderOptions o;
        o.width = 24, o.height = 18, o.spp = spp, o.seed = 5;
        render::RenderResult plain = render::Render(render::BuildScene("cornell"), o);
        o.layers = render::ParseLayerGroups("halves");
        render::RenderResult r = render::Render(render::BuildScene("cornell"), o);
        const Image &color = Layer(r, "color"), &h0 = Layer(r, "half0.color"),
                    &h1 = Layer(r, "half1.color");
        EXPECT_EQ(color.data, Layer(plain, "color").data);
        int even = (spp + 1) / 2, odd = spp / 2;
        for (size_t i = 0; i < color.data.size(); ++i) {
            double mean = (double(even) * h0.data[i] + double(odd) * h1.data[i]) / spp;
            ASSERT_NEAR(mean, color.data[i], 1e-5 * (1 + std::fabs(color.data[i]))) << i;
            if (spp == 1) {
                ASSERT_EQ(h1.data[i], 0.f);
            }
        }
    }
    EXPECT_EQ(render::ParseLayerGroups("all") & render::kLayersHalves, 0u);
}

// From 3 spp on, half0 also has its own layers, of the even samples alone (samples 0 and 2
// at 3 spp). A sample's sums are recovered from renders of 1, 2 and 3 spp (the same seed
// gives sample s the same path at any spp): sample 1 = 2 c2 - c1, sample 2 = 3 c3 - 2 c2.
// The frame's own layers are the same bits with or without the halves; at 2 spp half0 has
// its colour alone.
TEST(RenderLayers, HalvesCarryHalf0sOwnLayersFromTheEvenSamples) {
    static const render::Scene scene = render::BuildScene("dof-arealight");
    auto renderAt = [](int spp, const std::string &groups) {
        RenderOptions o;
        o.width = 13, o.height = 9, o.spp = spp, o.seed = 11;
        o.layers = render::ParseLayerGroups(groups);
        return render::Render(scene, o);
    };
    const std::string groups = "hist,split,gbuffer,halves";
    render::RenderResult r1 = renderAt(1, groups), r2 = renderAt(2, groups),
                         r3 = renderAt(3, groups), plain = renderAt(3, "hist,split,gbuffer");
    for (const auto &[name, image] : plain.layers)
        EXPECT_EQ(Layer(r3, name).data, image.data) << name;
    for (const auto &[name, image] : r2.layers)
        EXPECT_FALSE(name.rfind("half0.", 0) == 0 && name != "half0.color") << name;
    EXPECT_THROW(Layer(r3, "half0.objectId"), Error);
    EXPECT_THROW(Layer(r3, "half0.pivot"), Error);
    // The mean of samples 0 and 2, from the three renders' means (or sums for hist).
    auto evenMean = [&](const std::string &name, size_t i) {
        double c1 = Layer(r1, name).data[i], c2 = Layer(r2, name).data[i],
               c3 = Layer(r3, name).data[i];
        return (c1 + (3 * c3 - 2 * c2)) / 2;
    };
    for (const char *name : {"color", "albedo", "normal", "depth", "direct", "indirect"}) {
        const Image &own = Layer(r3, fmt::format("half0.{}", name));
        for (size_t i = 0; i < own.data.size(); ++i) {
            double expected = evenMean(name, i);
            ASSERT_NEAR(own.data[i], expected, 1e-4 * (1 + std::fabs(expected)))
                << name << " " << i;
        }
    }
    const Image &variance = Layer(r3, "half0.variance"), &mn = Layer(r3, "half0.min"),
                &mx = Layer(r3, "half0.max"), &spp = Layer(r3, "half0.spp");
    for (size_t i = 0; i < variance.data.size(); ++i) {
        // Two samples a and b: the variance of their mean is (a - b)^2 / 4.
        double a = Layer(r1, "color").data[i];
        double b = 3.0 * Layer(r3, "color").data[i] - 2.0 * Layer(r2, "color").data[i];
        double scale = 1 + a * a + b * b;
        ASSERT_NEAR(variance.data[i], (a - b) * (a - b) / 4, 1e-4 * scale) << i;
        ASSERT_NEAR(mn.data[i], std::min(a, b), 1e-4 * (1 + std::fabs(a) + std::fabs(b)));
        ASSERT_NEAR(mx.data[i], std::max(a, b), 1e-4 * (1 + std::fabs(a) + std::fabs(b)));
    }
    for (float v : spp.data) ASSERT_EQ(v, 2.f);
    for (const char *name : {"direct", "indirect"}) {
        const Image &own = Layer(r3, fmt::format("half0.{}.variance", name));
        ASSERT_EQ(own.data.size(), variance.data.size()) << name;
        for (size_t i = 0; i < own.data.size(); ++i) {
            double a = Layer(r1, name).data[i];
            double b = 3.0 * Layer(r3, name).data[i] - 2.0 * Layer(r2, name).data[i];
            ASSERT_NEAR(own.data[i], (a - b) * (a - b) / 4, 1e-4 * (1 + a * a + b * b))
                << name << " " << i;
        }
    }
    const Image &hist = Layer(r3, "half0.hist");
    for (size_t i = 0; i < hist.data.size(); ++i) {
        double expected = double(Layer(r1, "hist").data[i]) + Layer(r3, "hist").data[i] -
                          Layer(r2, "hist").data[i];
        ASSERT_NEAR(hist.data[i], expected, 1e-5) << i;
    }
}

TEST(RenderLayers, AgreeWithEachOther) {
    render::RenderResult r = RenderCornell(24, 18, 8, 7, render::kLayersAll);
    const Image &color = Layer(r, "color"), &mn = Layer(r, "min"), &mx = Layer(r, "max");
    const Image &direct = Layer(r, "direct"), &indirect = Layer(r, "indirect");
    const Image &hist = Layer(r, "hist"), &spp = Layer(r, "spp"),
                &variance = Layer(r, "variance");
    ASSERT_EQ(hist.channels, 61);
    for (int y = 0; y < color.height; ++y)
        for (int x = 0; x < color.width; ++x) {
            EXPECT_EQ(spp.At(0, y, x), 8.f);
            EXPECT_EQ(hist.At(60, y, x), 8.f);
            for (int c = 0; c < 3; ++c) {
                float v = color.At(c, y, x);
                EXPECT_TRUE(std::isfinite(v));
                EXPECT_LE(mn.At(c, y, x), v * (1 + 1e-6f) + 1e-7f);
                EXPECT_GE(mx.At(c, y, x), v * (1 - 1e-6f) - 1e-7f);
                EXPECT_GE(variance.At(c, y, x), 0.f);
                // Split sample by sample: the means add up to float round-off.
                EXPECT_NEAR(direct.At(c, y, x) + indirect.At(c, y, x), v, 1e-5f * (1 + v));
                double bins = 0;
                for (int b = 0; b < 20; ++b) bins += hist.At(c * 20 + b, y, x);
                EXPECT_NEAR(bins, 8.0, 1e-4) << x << "," << y << " channel " << c;
            }
        }
    EXPECT_EQ(r.nonFiniteSamples, 0u);
}

// direct.variance and indirect.variance are the variances of the parts' means: over 1024
// renders with other seeds the spread of each pixel's direct and indirect matches their
// mean within 10% (measured 0.96 and 1.00; 4096 renders: 1.006 and 1.002; the light's
// heavy tail makes the spread of a sample variance wider than chi-square's), where a
// variance over n instead of n - 1 would give 0.75, and of the samples instead of the mean
// 0.25; and with the colour's they form a covariance (|v - v_D - v_I| <= 2 sqrt(v_D v_I)).
TEST(RenderLayers, SplitVariancesAreOfTheMeans) {
    const int w = 8, h = 8, spp = 4, renders = 1024;
    const size_t values = 3 * w * h;
    std::vector<double> sum[2], sumSq[2], layerMean[2];
    for (int part = 0; part < 2; ++part)
        sum[part].assign(values, 0), sumSq[part].assign(values, 0),
            layerMean[part].assign(values, 0);
    for (int k = 0; k < renders; ++k) {
        render::RenderResult r = RenderCornell(w, h, spp, 1000 + k, render::kLayersSplit);
        const Image &v = Layer(r, "variance"), &vD = Layer(r, "direct.variance"),
                    &vI = Layer(r, "indirect.variance");
        for (size_t i = 0; i < values; ++i) {
            double slack = 1e-5 * (v.data[i] + vD.data[i] + vI.data[i]) + 1e-12;
            ASSERT_LE(std::fabs(v.data[i] - vD.data[i] - vI.data[i]),
                      2 * std::sqrt(double(vD.data[i]) * vI.data[i]) + slack)
                << "value " << i << " of render " << k;
        }
        for (int part = 0; part < 2; ++part) {
            const Image &mean = Layer(r, part == 0 ? "direct" : "indirect");
            const Image &variance =
                Layer(r, part == 0 ? "direct.variance" : "indirect.variance");
            for (size_t i = 0; i < values; ++i) {
                sum[part][i] += mean.data[i],
                    sumSq[part][i] += double(mean.data[i]) * mean.data[i];
                layerMean[part][i] += variance.data[i] / renders;
            }
        }
    }
    for (int part = 0; part < 2; ++part) {
        double spread = 0, layers = 0;
        for (size_t i = 0; i < values; ++i) {
            double mean = sum[part][i] / renders;
            spread += (sumSq[part][i] - renders * mean * mean) / (renders - 1);
            layers += layerMean[part][i];
        }
        ASSERT_GT(layers, 0);
        EXPECT_NEAR(spread / layers, 1.0, 0.1) << (part == 0 ? "direct" : "indirect");
    }
}

TEST(RenderDeterminism, SameFrameForAnyThreadCount) {
    render::RenderResult one = RenderCornell(20, 14, 4, 3, render::kLayersAll, 1);
    render::RenderResult two = RenderCornell(20, 14, 4, 3, render::kLayersAll, 2);
    ASSERT_EQ(one.layers.size(), two.layers.size());
    for (size_t i = 0; i < one.layers.size(); ++i)
        EXPECT_TRUE(BitIdentical(one.layers[i].second, two.layers[i].second))
            << one.layers[i].first;
}

TEST(RenderDeterminism, PivotDoesNotDependOnTheSeed) {
    render::RenderResult a = RenderCornell(20, 14, 2, 1, render::kLayersPivot);
    render::RenderResult b = RenderCornell(20, 14, 2, 99, render::kLayersPivot);
    EXPECT_TRUE(BitIdentical(Layer(a, "pivot"), Layer(b, "pivot")));
    EXPECT_FALSE(BitIdentical(Layer(a, "color"), Layer(b, "color")));
}

// Unbiased: the squared error against a converged render falls like 1/N (a biased
// estimator would level off at its bias). The MSE of a few hundred pixels is itself
// heavy-tailed, so average it over seeds and allow a factor of 2 either side of 16.
TEST(RenderEstimator, ErrorFallsLikeOneOverN) {
    const int w = 16, h = 12;
    Image reference = Layer(RenderCornell(w, h, 16384, 1000, 0), "color");
    auto mse = [&](int spp, uint64_t seed) {
        Image img = Layer(RenderCornell(w, h, spp, seed, 0), "color");
        double sum = 0;
        for (size_t i = 0; i < img.Size(); ++i) {
            double d = img.data[i] - reference.data[i];
            sum += d * d;
        }
        return sum / img.Size();
    };
    double low = 0, high = 0;
    for (uint64_t seed = 1; seed <= 8; ++seed)
        low += mse(16, seed), high += mse(256, seed + 100);
    double ratio = low / high;
    std::fprintf(stderr, "[mcd] 16x the samples: %.1fx lower squared error\n", ratio);
    EXPECT_GT(ratio, 8.0);
    EXPECT_LT(ratio, 32.0);
}

// Every built-in scene renders: finite, some light, direct + indirect = color, the same
// frame twice, and a pivot with no zeros where the camera sees a surface.
TEST(RenderScenes, EveryOneRendersConsistently) {
    for (const std::string &name : render::SceneNames()) {
        SCOPED_TRACE(name);
        render::Scene scene = render::BuildScene(name);
        RenderOptions o;
        o.width = 16, o.height = 12, o.spp = 4, o.seed = 5, o.layers = render::kLayersAll;
        render::RenderResult a = render::Render(scene, o), b = render::Render(scene, o);
        EXPECT_EQ(a.nonFiniteSamples, 0u);
        const Image &color = Layer(a, "color"), &direct = Layer(a, "direct"),
                    &indirect = Layer(a, "indirect");
        double sum = 0;
        for (size_t i = 0; i < color.Size(); ++i) {
            ASSERT_TRUE(std::isfinite(color.data[i]));
            EXPECT_GE(color.data[i], 0.f);
            EXPECT_NEAR(direct.data[i] + indirect.data[i], color.data[i],
                        1e-5f * (1 + color.data[i]));
            sum += color.data[i];
        }
        EXPECT_GT(sum / color.Size(), 1e-3) << "a black frame";
        for (size_t i = 0; i < a.layers.size(); ++i)
            EXPECT_TRUE(BitIdentical(a.layers[i].second, b.layers[i].second))
                << a.layers[i].first;
    }
}

TEST(RenderArguments, BadOnesAreRefused) {
    // An unknown scene's message lists the scenes there are.
    EXPECT_TRUE(ThrowsError(
        ErrorKind::InvalidArgument, [] { render::BuildScene("nope"); }, "cornell"));
    EXPECT_TRUE(ThrowsError(ErrorKind::InvalidArgument, [] { RenderCornell(0, 4, 1, 1, 0); }));
    EXPECT_TRUE(ThrowsError(ErrorKind::InvalidArgument, [] { RenderCornell(4, 4, 0, 1, 0); }));
    EXPECT_TRUE(
        ThrowsError(ErrorKind::InvalidArgument, [] { RenderCornell(4, 4, 1 << 24, 1, 0); }));
    // More threads than rows, or than can start, still give the frame.
    EXPECT_TRUE(BitIdentical(Layer(RenderCornell(6, 3, 2, 1, 0, 64), "color"),
                             Layer(RenderCornell(6, 3, 2, 1, 0, 1), "color")));
    EXPECT_TRUE(ThrowsError(
        ErrorKind::InvalidArgument, [] { render::ParseLayerGroups("hist,nope"); }, "'nope'"));
    EXPECT_EQ(render::ParseLayerGroups("hist,pivot"),
              render::kLayersHist | render::kLayersPivot);
}

// The sample source gives the same sample for the same (x, y, key), another for another key.
TEST(RenderSampleSource, KeyedAndRepeatable) {
    render::Scene scene = render::BuildScene("cornell");
    render::SampleSource source(scene, 32, 32, 5);
    render::PathSample a = source.Trace(10.5, 20.25, 77), b = source.Trace(10.5, 20.25, 77);
    EXPECT_EQ(a.color.x, b.color.x);
    EXPECT_EQ(a.color.y, b.color.y);
    double differ = 0;
    for (uint64_t k = 0; k < 64; ++k)
        differ += std::fabs(source.Trace(10.5, 20.25, k).color.x - a.color.x);
    EXPECT_GT(differ, 0);
}

}  // namespace
}  // namespace mcd::test
