// Method bayes (Xu & Pattanaik): the model of the CPU reference (moment solver, posterior
// mean), every GPU stage against the reference fed with the same input, the whole method
// on edge sizes, bit-identical reruns, and extreme inputs.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "bayes/bayes.h"
#include "cpu_reference/bayes_denoise.h"
#include "cpu_reference/bayes_model.h"
#include "cpu_reference/wavelet_analyze.h"
#include "harness/bayes_paper.h"
#include "harness/compare.h"
#include "harness/errors.h"
#include "harness/gpu_fixture.h"
#include "harness/inputs.h"
#include "host/api/device.h"
#include "host/common/parallel.h"
#include "host/kernels/bayes_exp.h"
#include "host/kernels/bayes_log.h"
#include "host/kernels/bayes_mix.h"
#include "host/kernels/bayes_moments.h"
#include "host/kernels/bayes_shrink.h"
#include "host/kernels/bayes_solve.h"
#include "host/kernels/bayes_table.h"
#include "host/methods/bayes.h"
#include "host/vk/buffer.h"
#include "mcdenoise/mcdenoise.h"

namespace mcd::test {
namespace {

constexpr double kUnitRoundoff = 0x1p-24;

// n samples of the generalised Laplacian f(x; s, p): |x| = s G^(1/p), G ~ Gamma(1/p, 1),
// with a random sign.
std::vector<double> SampleGl(double s, double p, size_t n, std::mt19937_64 &rng) {
    std::gamma_distribution<double> gamma(1 / p, 1.0);
    std::bernoulli_distribution sign(0.5);
    std::vector<double> x(n);
    for (double &v : x) v = s * std::pow(gamma(rng), 1 / p) * (sign(rng) ? 1 : -1);
    return x;
}

// A number in a case's name: gtest names take [A-Za-z0-9_] only, so 0.8 is "0p8" and
// 1e-30 is "1em30". Floats print as floats (0.01f is "0p01").
template <typename Float>
std::string NameOf(Float v) {
    std::string name;
    for (char ch : fmt::format("{}", v)) {
        if (ch == '.')
            name += 'p';
        else if (ch == '-')
            name += 'm';
        else if (ch != '+')
            name += ch;
    }
    return name;
}

std::string SizeName(const testing::TestParamInfo<std::pair<int, int>> &info) {
    return fmt::format("{}x{}", info.param.first, info.param.second);
}

// ---------------------------------------------------------------- the reference's model

TEST(BayesModel, KurtosisIsMonotoneOverTheBracket) {
    double previous = INFINITY;
    for (double p = BAYES_P_LO; p <= BAYES_P_HI; p += 0.01) {
        double k = ref::GlKurtosis(p);
        EXPECT_LT(k, previous) << "p " << p;
        previous = k;
    }
    EXPECT_NEAR(ref::GlKurtosis(2), 3, 1e-12);
    EXPECT_NEAR(ref::GlKurtosis(1), 6, 1e-12);
}

// Each case is a test of its own, named by its parameters, so a failing one re-runs alone.
struct ShapeCase {
    double p, s;
};

std::string ShapeCaseName(const testing::TestParamInfo<ShapeCase> &info) {
    return fmt::format("p{}_s{}", NameOf(info.param.p), NameOf(info.param.s));
}

// Exact moments of c + n (eqs. 17-18) give back (s_c, p_c) to the bisection's precision.
class BayesModelExactMoments : public testing::TestWithParam<ShapeCase> {};

TEST_P(BayesModelExactMoments, SolverInvertsThem) {
    const auto [p, s] = GetParam();
    const double sn = 0.19, pn = 1.5;
    double sN = s * 0.05;  // noise well below the signal, scaled with it
    double var = ref::GlSecondMoment(s, p), varN = ref::GlSecondMoment(sN, pn);
    double m2 = var + varN;
    double m4 = ref::GlFourthMoment(s, p) + ref::GlFourthMoment(sN, pn) + 6 * var * varN;
    ref::BandFit fit = ref::SolveBand(m2, m4, 1000, sN, pn);
    EXPECT_EQ(fit.fit, BAYES_FIT_SOLVED) << s << " " << p;
    EXPECT_NEAR(fit.pc, p, 1e-9 * p) << s << " " << p;
    EXPECT_NEAR(fit.sc, s, 1e-8 * s) << s << " " << p;
    (void)sn;
}

std::vector<ShapeCase> ExactMomentCases() {
    std::vector<ShapeCase> cases;
    for (double p : {0.5, 0.7, 1.0, 1.5, 2.0})
        for (double s : {1e-3, 1e-1, 1.0, 30.0}) cases.push_back({p, s});
    return cases;
}

INSTANTIATE_TEST_SUITE_P(Cases, BayesModelExactMoments, testing::ValuesIn(ExactMomentCases()),
                         ShapeCaseName);

// Sampled moments of synthetic c + n: (s, p) recovered for p in [0.5, 2] and s over four
// decades. The tolerance is the sampling error: E[x^4] of 400k samples of p = 0.5 has a
// relative standard deviation of sqrt((Gamma(18) Gamma(2) / Gamma(10)^2 - 1) / 4e5) = 8%,
// which moves p by about 0.03; tighter shapes do much better.
std::vector<ShapeCase> SampledCases() {
    std::vector<ShapeCase> cases;
    for (double p : {0.5, 0.8, 1.2, 2.0})
        for (double s : {1e-3, 1e-1, 10.0}) cases.push_back({p, s});
    return cases;
}

// The fits of every case, in the cases' order, computed once: the cases draw from one
// generator, so each case's samples depend on the cases before it.
const std::vector<ref::BandFit> &SampledFits() {
    static const std::vector<ref::BandFit> fits = [] {
        std::mt19937_64 rng(SeedFromName("bayes solver samples"));
        const size_t n = 400000;
        const double pn = 1.5;
        std::vector<ref::BandFit> all;
        for (auto [p, s] : SampledCases()) {
            double sN = 0.2 * s;
            std::vector<double> c = SampleGl(s, p, n, rng), noise = SampleGl(sN, pn, n, rng);
            double m2 = 0, m4 = 0;
            for (size_t i = 0; i < n; ++i) {
                double y = c[i] + noise[i];
                m2 += y * y;
                m4 += y * y * y * y;
            }
            all.push_back(ref::SolveBand(m2 / n, m4 / n, int64_t(n), sN, pn));
        }
        return all;
    }();
    return fits;
}

class BayesModelSampled : public testing::TestWithParam<ShapeCase> {};

TEST_P(BayesModelSampled, SolverRecoversTheParameters) {
    const ShapeCase k = GetParam();
    const double p = k.p, s = k.s;
    std::vector<ShapeCase> cases = SampledCases();
    size_t index = std::find_if(cases.begin(), cases.end(),
                                [&](const ShapeCase &c) { return c.p == k.p && c.s == k.s; }) -
                   cases.begin();
    ASSERT_LT(index, cases.size());
    const ref::BandFit &fit = SampledFits()[index];
    SCOPED_TRACE(fmt::format("s {} p {}: got s_c {:.4g} p_c {:.4g}", s, p, fit.sc, fit.pc));
    EXPECT_EQ(fit.fit, BAYES_FIT_SOLVED);
    EXPECT_NEAR(fit.pc, p, 0.12 * p);
    EXPECT_NEAR(fit.sc, s, 0.25 * s);
}

INSTANTIATE_TEST_SUITE_P(Cases, BayesModelSampled, testing::ValuesIn(SampledCases()),
                         ShapeCaseName);

TEST(BayesModel, SolverFallbacksAreDocumentedAndFinite) {
    const double sn = 0.2, pn = 1.5;
    double varN = ref::GlSecondMoment(sn, pn), m4N = ref::GlFourthMoment(sn, pn);
    EXPECT_EQ(ref::SolveBand(0.5 * varN, m4N, 10, sn, pn).fit, BAYES_FIT_NO_SIGNAL);
    EXPECT_EQ(ref::SolveBand(varN, m4N, 10, sn, pn).fit, BAYES_FIT_NO_SIGNAL);
    EXPECT_EQ(ref::SolveBand(NAN, m4N, 10, sn, pn).fit, BAYES_FIT_NO_SIGNAL);
    EXPECT_EQ(ref::SolveBand(INFINITY, INFINITY, 10, sn, pn).fit, BAYES_FIT_NO_SIGNAL);
    EXPECT_EQ(ref::SolveBand(1, 1, 0, sn, pn).fit, BAYES_FIT_EMPTY);
    EXPECT_EQ(ref::SolveBand(1, 1, 10, 0, pn).fit, BAYES_FIT_NO_NOISE);
    EXPECT_EQ(ref::SolveBand(1, 1, 10, 0.5 * BAYES_MIN_NOISE_S, pn).fit, BAYES_FIT_NO_NOISE);
    EXPECT_NE(ref::SolveBand(1, 1, 10, 2 * BAYES_MIN_NOISE_S, pn).fit, BAYES_FIT_NO_NOISE);
    // Signal variance 1: a fourth moment far above any p's reach, and one below the noise's.
    ref::BandFit low = ref::SolveBand(1 + varN, 1e6, 10, sn, pn);
    EXPECT_EQ(low.fit, BAYES_FIT_P_LOW);
    EXPECT_EQ(low.pc, BAYES_P_LO);
    ref::BandFit high = ref::SolveBand(1 + varN, 0.5, 10, sn, pn);
    EXPECT_EQ(high.fit, BAYES_FIT_P_HIGH);
    EXPECT_EQ(high.pc, BAYES_P_HI);
    ref::BandFit flat = ref::SolveBand(1 + varN, 2.0, 10, sn, pn);  // kurtosis ~2 < 2.42
    EXPECT_EQ(flat.fit, BAYES_FIT_P_HIGH);
    for (const ref::BandFit &f : {low, high, flat}) {
        EXPECT_TRUE(std::isfinite(f.sc) && f.sc > 0);
        EXPECT_NEAR(ref::GlSecondMoment(f.sc, f.pc), 1, 1e-9);  // the variance still holds
        for (double y : {0.0, 0.1, 1.0, 100.0})
            EXPECT_TRUE(std::isfinite(ref::PosteriorMean(y, f, sn, pn)));
    }
}

// The posterior mean is odd, monotone, inside [0, y] for y > 0, and shrinks small
// coefficients (relative to y) more than large ones; finite at extreme scales. Monotone
// needs a prior whose tails are at least as heavy as the noise's (p_c < p_n, or p_c = p_n
// and s_c >= s_n): otherwise a very large y is better explained by noise and c^ falls
// back toward 0 (true of eq. 11 itself; checked in PosteriorMeanTakesLargeYForNoise).
struct ModelCase {
    double sc, pc, sn, pn;
};

std::string ModelName(const ModelCase &k) {
    return fmt::format("sc{}_pc{}_sn{}_pn{}", NameOf(k.sc), NameOf(k.pc), NameOf(k.sn),
                       NameOf(k.pn));
}

class BayesModelPosteriorMean : public testing::TestWithParam<ModelCase> {};

TEST_P(BayesModelPosteriorMean, Properties) {
    const ModelCase &k = GetParam();
    SCOPED_TRACE(fmt::format("s_c {} p_c {} s_n {} p_n {}", k.sc, k.pc, k.sn, k.pn));
    ref::BandFit fit{BAYES_FIT_SOLVED, k.sc, k.pc};
    // "Small" is y < s_n, "large" y > 4 s_n: every small y keeps a smaller fraction of
    // itself than any large one (near 0 the fraction may dip slightly: the cubic term).
    double previous = 0, maxSmallRatio = 0, minLargeRatio = INFINITY;
    for (int i = 1; i <= 120; ++i) {
        double y = k.sn * 0.05 * i * (1 + i / 10.0);
        double c = ref::PosteriorMean(y, fit, k.sn, k.pn);
        ASSERT_TRUE(std::isfinite(c)) << y;
        EXPECT_EQ(ref::PosteriorMean(-y, fit, k.sn, k.pn), -c) << y;
        EXPECT_GE(c, previous - 1e-12 * y) << "monotone at y " << y;
        EXPECT_GE(c, -1e-12 * y);
        EXPECT_LE(c, y * (1 + 1e-9)) << y;
        if (y < k.sn) maxSmallRatio = std::max(maxSmallRatio, c / y);
        if (y > 4 * k.sn) minLargeRatio = std::min(minLargeRatio, c / y);
        previous = c;
    }
    // (Equal for Gaussian prior and noise: the Wiener gain. A prior far narrower than
    // the noise, s_c = 1e-4 s_n, only lets go beyond y ~ 100 s_n: not "large" here.)
    if (k.sc >= 0.1 * k.sn) {
        EXPECT_LE(maxSmallRatio, minLargeRatio * (1 + 1e-9));
    }
    EXPECT_EQ(ref::PosteriorMean(0, fit, k.sn, k.pn), 0);
}

INSTANTIATE_TEST_SUITE_P(
    Cases, BayesModelPosteriorMean,
    testing::Values(ModelCase{1, 0.7, 0.2, 1.5}, ModelCase{0.1, 1.0, 0.3, 1.5},
                    ModelCase{2, 2.0, 0.5, 2.0}, ModelCase{1e-4, 0.5, 1, 1.5},
                    ModelCase{1e3, 0.6, 1e-3, 0.8}, ModelCase{0.5, 0.6, 0.19, 0.6}),
    [](const testing::TestParamInfo<ModelCase> &info) { return ModelName(info.param); });

TEST(BayesModel, PosteriorMeanTakesLargeYForNoise) {
    ref::BandFit light{BAYES_FIT_SOLVED, 0.05, 1.3};
    double mid = ref::PosteriorMean(1.0, light, 0.19, 0.6);
    double far = ref::PosteriorMean(15.0, light, 0.19, 0.6);
    EXPECT_LT(far, mid) << "p_c > p_n: large y is taken for noise";
    EXPECT_TRUE(std::isfinite(far) && far > 0);
}

// The sinh-grid quadrature against a plain composite Simpson rule on a uniform grid fine
// enough to resolve both densities (step min(s_n, s_c) / 200 over the same range).
struct QuadratureCase {
    ModelCase model;
    double y;
};

class BayesModelQuadrature : public testing::TestWithParam<QuadratureCase> {};

TEST_P(BayesModelQuadrature, MatchesAFineUniformIntegral) {
    const ModelCase &k = GetParam().model;
    const double y = GetParam().y;
    ref::BandFit fit{BAYES_FIT_SOLVED, k.sc, k.pc};
    double reach = std::max(k.sn * std::pow(40.0, 1 / k.pn), k.sc * std::pow(40.0, 1 / k.pc));
    double lo = -reach, hi = y + reach, h = std::min(k.sn, k.sc) / 200;
    int n = int(std::ceil((hi - lo) / h / 2)) * 2;
    h = (hi - lo) / n;
    double num = 0, den = 0;
    for (int i = 0; i <= n; ++i) {
        double c = lo + i * h;
        double w = (i == 0 || i == n) ? 1 : (i % 2 ? 4 : 2);
        double f = std::exp(-std::pow(std::fabs(y - c) / k.sn, k.pn) -
                            std::pow(std::fabs(c) / k.sc, k.pc));
        num += w * f * c;
        den += w * f;
    }
    double expected = num / den;
    EXPECT_NEAR(ref::PosteriorMean(y, fit, k.sn, k.pn), expected, 2e-4 * k.sn)
        << fmt::format("s_c {} p_c {} s_n {} p_n {} y {}", k.sc, k.pc, k.sn, k.pn, y);
}

std::vector<QuadratureCase> QuadratureCases() {
    std::vector<QuadratureCase> cases;
    for (ModelCase k : {ModelCase{1, 0.8, 0.2, 1.5}, ModelCase{0.3, 1.6, 0.4, 1.2},
                        ModelCase{0.05, 0.6, 0.1, 2.0}})
        for (double y : {0.05, 0.3, 1.0, 3.0}) cases.push_back({k, y});
    return cases;
}

INSTANTIATE_TEST_SUITE_P(Cases, BayesModelQuadrature, testing::ValuesIn(QuadratureCases()),
                         [](const testing::TestParamInfo<QuadratureCase> &info) {
                             return fmt::format("{}_y{}", ModelName(info.param.model),
                                                NameOf(info.param.y));
                         });

// ---------------------------------------------------------------- GPU stages vs reference

class BayesKernel : public GpuTest {
  protected:
    vk::Buffer Floats(const std::vector<float> &values, const char *name) {
        vk::Buffer b(Ctx(), std::max<size_t>(values.size(), 1) * sizeof(float), name);
        if (!values.empty()) b.UploadFloats(values);
        return b;
    }
};

template <typename Param>
class BayesKernelWithParam : public BayesKernel, public testing::WithParamInterface<Param> {};

// An image with zeros, negatives, tiny values, NaN/Inf and fireflies.
Image AwkwardInput(int w, int h, int channels, uint64_t seed) {
    Image image = MakeInput(InputKind::LogNormalFireflies, w, h, channels, seed);
    Image special = MakeInput(InputKind::NonFinite, w, h, channels, seed + 1);
    std::mt19937_64 rng(seed + 2);
    for (size_t i = 0; i < image.Size(); ++i) {
        if (!std::isfinite(special.data[i])) image.data[i] = special.data[i];
        switch (rng() % 16) {
            case 0:
                image.data[i] = 0;
                break;
            case 1:
                image.data[i] = -0.5f;
                break;
            case 2:
                image.data[i] = 1e-9f;
                break;
            default:
                break;
        }
    }
    return image;
}

const std::vector<std::pair<int, int>> kSizes = {{1, 1},   {2, 1},  {1, 5}, {3, 3},
                                                 {37, 23}, {64, 7}, {3, 70}};

// GLSL log: within 3 ulp of |log v| outside [0.5, 2], 2^-21 absolute inside; the reference
// rounds once more (0.5 ulp). A dark pixel among lit pixels takes the mean of up to 8 such
// logs, summed in float: within 12 ulp of the largest of them.
class BayesLogKernel : public BayesKernelWithParam<std::pair<int, int>> {};

TEST_P(BayesLogKernel, MatchesReference) {
    const auto [w, h] = GetParam();
    SCOPED_TRACE(fmt::format("{}x{}", w, h));
    Image color = AwkwardInput(w, h, 3, SeedFromName(fmt::format("bayeslog{}x{}", w, h)));
    std::vector<float> floors = BayesFloors(color, 1e-3f);
    std::vector<double> refFloors = ref::BayesFloors(color, double(1e-3f));
    for (int c = 0; c < 3; ++c) EXPECT_EQ(double(floors[c]), refFloors[c]) << "channel " << c;
    vk::GpuImage in(Ctx(), w, h, 3, "color"), out(Ctx(), w, h, 3, "log");
    in.Upload(color);
    vk::Buffer floorsGpu = Floats(floors, "floors");
    for (bool fillMissed : {false, true}) {
        SCOPED_TRACE(fillMissed ? "missed samples filled" : "the floor");
        Image expected = ref::BayesLog(color, refFloors, fillMissed);
        auto run = [&] {
            vk::Recorder recorder(Ctx());
            RecordBayesLog(Ctx(), recorder, in, floorsGpu, out, fillMissed);
            recorder.Submit();
            return out.Download();
        };
        Image scale(w, h, 3);
        for (int c = 0; c < 3; ++c)
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) {
                    float &s = scale.At(c, y, x);
                    s = std::fabs(expected.At(c, y, x));
                    if (!(color.At(c, y, x) >= 0 && color.At(c, y, x) <= floors[c])) continue;
                    for (int ny = std::max(y - 1, 0); ny <= std::min(y + 1, h - 1); ++ny)
                        for (int nx = std::max(x - 1, 0); nx <= std::min(x + 1, w - 1); ++nx) {
                            float n = color.At(c, ny, nx);
                            bool lit = std::isfinite(n) && n > floors[c];
                            s = std::max(s, 3 * std::fabs(std::log(lit ? n : floors[c])));
                        }
                }
        Image logGpu = run();
        EXPECT_TRUE(ImagesMatch(expected, logGpu, scale, {4 * kUnitRoundoff, 0x1p-21, 1e-9}));
        EXPECT_TRUE(BitIdentical(logGpu, run()));
    }
}

// With --zeros restore, a zero lone among lit pixels takes the mean log of its lit neighbours;
// a zero inside black or on a black line takes the floor's, and every zero does without it.
TEST_F(BayesKernel, LogFillsMissedSamplesFromTheirNeighbours) {
    const int w = 10, h = 8;
    Image color(w, h, 1);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) color.At(0, y, x) = 0.25f * float(1 + (x + y) % 3);
    for (int x = 0; x < w; ++x) color.At(0, 6, x) = 0;  // a black line
    color.At(0, 2, 3) = 0;                              // a lone zero
    color.At(0, 7, 9) = 0;                              // in the corner, beside the line
    std::vector<float> floors = {0.01f};
    vk::GpuImage in(Ctx(), w, h, 1, "color"), out(Ctx(), w, h, 1, "log");
    in.Upload(color);
    vk::Buffer floorsGpu = Floats(floors, "floors");
    auto run = [&](bool fillMissed) {
        vk::Recorder recorder(Ctx());
        RecordBayesLog(Ctx(), recorder, in, floorsGpu, out, fillMissed);
        recorder.Submit();
        return out.Download();
    };
    Image got = run(true), expected = ref::BayesLog(color, {0.01f}, true);
    for (const Image &image : {run(false), ref::BayesLog(color, {0.01f}, false)})
        EXPECT_NEAR(image.At(0, 2, 3), std::log(0.01), 1e-5) << "the floor without the fill";
    double mean = 0;
    for (int y = 1; y <= 3; ++y)
        for (int x = 2; x <= 4; ++x)
            if (x != 3 || y != 2) mean += std::log(double(color.At(0, y, x))) / 8;
    for (const Image *image : {&got, &expected}) {
        SCOPED_TRACE(image == &got ? "kernel" : "CPU twin");
        EXPECT_NEAR(image->At(0, 2, 3), mean, 1e-5);
        for (int x = 0; x < w; ++x) EXPECT_NEAR(image->At(0, 6, x), std::log(0.01), 1e-5);
        EXPECT_NEAR(image->At(0, 7, 9), std::log(0.01), 1e-5);
    }
    EXPECT_TRUE(BitIdentical(got, run(true)));
}

// In colour: a pixel with one lit channel is no missed sample (its zeros take the floor), and
// a missed sample's channels average the same neighbour pixels, every one not dark, each
// channel at least its floor.
TEST_F(BayesKernel, LogFillsEveryChannelFromTheSameNeighbours) {
    const int w = 9, h = 7;
    Image color(w, h, 3);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                color.At(c, y, x) = 0.1f * float(1 + c + (x + 2 * y) % 4);
    for (int c = 0; c < 3; ++c) color.At(c, 2, 3) = 0, color.At(c, 2, 2) = 0;  // missed
    color.At(1, 2, 4) = 0, color.At(2, 2, 4) = 0;  // lit in channel 0 only: a neighbour
    color.At(0, 4, 6) = 0, color.At(1, 4, 6) = 0;  // lit in channel 2 only: not missed
    std::vector<float> floors = {0.01f, 0.02f, 0.03f};
    vk::GpuImage in(Ctx(), w, h, 3, "color"), out(Ctx(), w, h, 3, "log");
    in.Upload(color);
    vk::Buffer floorsGpu = Floats(floors, "floors");
    auto run = [&] {
        vk::Recorder recorder(Ctx());
        RecordBayesLog(Ctx(), recorder, in, floorsGpu, out, true);
        recorder.Submit();
        return out.Download();
    };
    Image got = run(), expected = ref::BayesLog(color, {0.01f, 0.02f, 0.03f}, true);
    EXPECT_TRUE(BitIdentical(got, run()));
    for (const Image *image : {&got, &expected}) {
        SCOPED_TRACE(image == &got ? "kernel" : "CPU twin");
        for (int c = 0; c < 3; ++c) {
            double mean = 0;  // (3, 2)'s neighbours less (2, 2), dark itself
            for (int y = 1; y <= 3; ++y)
                for (int x = 2; x <= 4; ++x)
                    if ((x != 3 || y != 2) && (x != 2 || y != 2))
                        mean +=
                            std::log(std::max(double(color.At(c, y, x)), double(floors[c]))) /
                            7;
            EXPECT_NEAR(image->At(c, 2, 3), mean, 1e-5) << "channel " << c;
            if (c < 2) {
                EXPECT_NEAR(image->At(c, 4, 6), std::log(floors[c]), 1e-5);
            }
        }
        EXPECT_NEAR(image->At(2, 4, 6), std::log(color.At(2, 4, 6)), 1e-5);
    }
}

INSTANTIATE_TEST_SUITE_P(Cases, BayesLogKernel, testing::ValuesIn(kSizes), SizeName);

// exp: (3 + 2 |z|) ulp, plus the reference's rounding, on the reference's log of an awkward
// image (zeros, negatives, NaN/Inf: exact zeros where restored).
class BayesExpKernel : public BayesKernelWithParam<std::pair<int, int>> {};

TEST_P(BayesExpKernel, MatchesReference) {
    const auto [w, h] = GetParam();
    SCOPED_TRACE(fmt::format("{}x{}", w, h));
    Image color = AwkwardInput(w, h, 3, SeedFromName(fmt::format("bayesexp{}x{}", w, h)));
    Image logImage = ref::BayesLog(color, ref::BayesFloors(color, 1e-3), true);
    vk::GpuImage in(Ctx(), w, h, 3, "color"), log(Ctx(), w, h, 3, "log"),
        back(Ctx(), w, h, 3, "exp");
    in.Upload(color);
    log.Upload(logImage);
    auto run = [&](bool restoreZeros) {
        vk::Recorder recorder(Ctx());
        RecordBayesExp(Ctx(), recorder, log, in, back, restoreZeros);
        recorder.Submit();
        return back.Download();
    };
    for (bool restoreZeros : {true, false}) {
        SCOPED_TRACE(restoreZeros ? "zeros restored" : "zeros denoised");
        Image expected = ref::BayesExp(logImage, color, restoreZeros);
        Image scale(w, h, 3);
        for (size_t i = 0; i < scale.Size(); ++i)
            scale.data[i] = std::fabs(expected.data[i]) * (4 + 2 * std::fabs(logImage.data[i]));
        Image got = run(restoreZeros);
        EXPECT_TRUE(ImagesMatch(expected, got, scale, {kUnitRoundoff, 0, 1e-9}));
        EXPECT_TRUE(BitIdentical(got, run(restoreZeros)));
        // NaN/Inf/negatives give 0; zeros take exp of their log unless restored, and a zero
        // whose in-frame neighbours are all lit is a missed sample, never restored.
        for (int c = 0; c < 3; ++c)
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) {
                    float v = color.At(c, y, x), out = got.At(c, y, x);
                    bool lit = true;
                    for (int ny = std::max(y - 1, 0); ny <= std::min(y + 1, h - 1); ++ny)
                        for (int nx = std::max(x - 1, 0); nx <= std::min(x + 1, w - 1); ++nx) {
                            float n = color.At(c, ny, nx);
                            if ((nx != x || ny != y) && !(std::isfinite(n) && n > 0))
                                lit = false;
                        }
                    if (!std::isfinite(v) || v < 0) {
                        EXPECT_EQ(out, 0.f) << x << "," << y << "," << c;
                    } else if (v == 0 && (!restoreZeros || (lit && w > 1 && h > 1))) {
                        EXPECT_GT(out, 0.f) << "zero at " << x << "," << y << "," << c;
                    }
                }
    }
}

// The exp kernel's output with --zeros restore on `color` and a log image of log(0.5)
// everywhere, and its CPU twin's in `expected`; expects a rerun to give the same bits.
Image ExpRestoringZeros(vk::Context &context, const Image &color, Image *expected) {
    const int w = color.width, h = color.height, channels = color.channels;
    Image logImage(w, h, channels);
    for (float &v : logImage.data) v = std::log(0.5f);
    vk::GpuImage in(context, w, h, channels, "color"), log(context, w, h, channels, "log"),
        back(context, w, h, channels, "exp");
    in.Upload(color);
    log.Upload(logImage);
    auto run = [&] {
        vk::Recorder recorder(context);
        RecordBayesExp(context, recorder, log, in, back, true);
        recorder.Submit();
        return back.Download();
    };
    Image got = run();
    *expected = ref::BayesExp(logImage, color, true);
    EXPECT_TRUE(BitIdentical(got, run()));
    return got;
}

// --zeros restore keeps black regions, black lines and black at the frame's edge exactly 0,
// and denoises zeros lone among lit pixels (low-spp samples that missed the light), on the
// kernel and its CPU twin alike.
TEST_F(BayesKernel, ExpRestoresBlackButNotLoneZeros) {
    const int w = 12, h = 9;
    Image color(w, h, 1);
    for (float &v : color.data) v = 0.5f;
    for (int y = 0; y < 3; ++y)
        for (int x = 0; x < 3; ++x) color.At(0, y, x) = 0;  // a black corner region
    for (int x = 0; x < w; ++x) color.At(0, 6, x) = 0;      // a black line
    color.At(0, 3, 7) = 0;                                  // lone zeros
    color.At(0, 8, 10) = 0;                                 // on the bottom edge
    color.At(0, 3, 10) = 0, color.At(0, 2, 10) = 0;         // a pair
    color.At(0, 4, 5) = 0, color.At(0, 3, 4) = 0;           // a diagonal pair
    Image expected;
    Image got = ExpRestoringZeros(Ctx(), color, &expected);
    for (const Image *image : {&got, &expected}) {
        SCOPED_TRACE(image == &got ? "kernel" : "CPU twin");
        // The region's convex corner has no black pair through it: denoised like a lone zero.
        for (int y = 0; y < 3; ++y)
            for (int x = 0; x < 3; ++x)
                if (x < 2 || y < 2) {
                    EXPECT_EQ(image->At(0, y, x), 0.f) << x << "," << y;
                }
        EXPECT_GT(image->At(0, 2, 2), 0.4f);
        for (int x = 0; x < w; ++x) EXPECT_EQ(image->At(0, 6, x), 0.f) << "line at " << x;
        for (auto [x, y] : {std::pair{7, 3}, {10, 8}, {10, 3}, {10, 2}, {5, 4}, {4, 3}})
            EXPECT_GT(image->At(0, y, x), 0.4f) << "lone zero at " << x << "," << y;
    }
    for (size_t i = 0; i < got.Size(); ++i)
        EXPECT_EQ(got.data[i] == 0, expected.data[i] == 0) << "the same zeros, pixel " << i;
}

// Black is decided per channel: a pure red region's green and blue stay 0 with --zeros
// restore, and so do a missed sample's inside it, while its red is denoised.
TEST_F(BayesKernel, ExpKeepsPrimaryColoursClean) {
    const int w = 10, h = 8;
    Image color(w, h, 3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c) color.At(c, y, x) = c == 0 || x >= 5 ? 0.5f : 0.f;
    for (int c = 0; c < 3; ++c) color.At(c, 4, 2) = 0, color.At(c, 3, 7) = 0;  // missed
    Image expected;
    Image got = ExpRestoringZeros(Ctx(), color, &expected);
    for (const Image *image : {&got, &expected}) {
        SCOPED_TRACE(image == &got ? "kernel" : "CPU twin");
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                for (int c = 0; c < 3; ++c)
                    if (c > 0 && x < 5) {
                        EXPECT_EQ(image->At(c, y, x), 0.f) << x << "," << y << "," << c;
                    } else {
                        EXPECT_GT(image->At(c, y, x), 0.4f) << x << "," << y << "," << c;
                    }
    }
}

INSTANTIATE_TEST_SUITE_P(Cases, BayesExpKernel, testing::ValuesIn(kSizes), SizeName);

// Sums of positive terms in float: lane l adds count/256 terms, then 8 tree levels, then
// one division; v^2 and v^4 round twice. Relative error <= (count/256 + 8 + 4) u.
struct LevelsCase {
    int w, h, levels;
};

// The sizes' cases at each level count the size allows.
std::vector<LevelsCase> MomentCases() {
    std::vector<LevelsCase> cases;
    for (auto [w, h] : kSizes)
        for (int levels : {1, 3})
            if (levels <= MaxWaveletLevels(w, h)) cases.push_back({w, h, levels});
    return cases;
}

class BayesMomentsKernel : public BayesKernelWithParam<LevelsCase> {};

TEST_P(BayesMomentsKernel, MatchReference) {
    const auto [w, h, levels] = GetParam();
    SCOPED_TRACE(fmt::format("{}x{} levels {}", w, h, levels));
    Image coef = MakeInput(InputKind::Uniform, w, h, 2,
                           SeedFromName(fmt::format("bayesmom{}x{}", w, h)));
    int bands = BayesBandCount(2, levels);
    vk::GpuImage c(Ctx(), w, h, 2, "coef");
    c.Upload(coef);
    vk::Buffer moments(Ctx(), bands * BAYES_MOMENT_STRIDE * sizeof(float), "moments");
    vk::Recorder recorder(Ctx());
    RecordBayesMoments(Ctx(), recorder, c, levels, moments);
    recorder.Submit();
    std::vector<float> got = moments.DownloadFloats(bands * BAYES_MOMENT_STRIDE);
    std::vector<ref::BayesBand> refBands = ref::BayesBands(w, h, 2, levels);
    ASSERT_EQ(int(refBands.size()), bands);
    for (int b = 0; b < bands; ++b) {
        ref::BandMoments m = ref::MeasureBand(coef, refBands[b]);
        double tol = (double(m.count) / 256 + 12) * kUnitRoundoff;
        EXPECT_NEAR(got[b * 4 + 0], m.m2, tol * m.m2) << "band " << b;
        EXPECT_NEAR(got[b * 4 + 1], m.m4, tol * m.m4) << "band " << b;
        EXPECT_EQ(got[b * 4 + 2], float(m.maxAbs)) << "band " << b;
        EXPECT_EQ(got[b * 4 + 3], float(m.count)) << "band " << b;
    }
}

INSTANTIATE_TEST_SUITE_P(Cases, BayesMomentsKernel, testing::ValuesIn(MomentCases()),
                         [](const testing::TestParamInfo<LevelsCase> &info) {
                             return fmt::format("{}x{}_L{}", info.param.w, info.param.h,
                                                info.param.levels);
                         });

struct SolveCase {
    double m2, m4, count;
    int level;
};

// The GPU solver in float against ref::SolveBand on the same (float) moments. The error
// budget: the float subtractions of eq. 17-18 (4 u of each term over the difference),
// float lgamma (about 2^-20 absolute per call, 6 calls per log kurtosis), propagated to
// p_c through the slope of log kurtosis(p) and to s_c through sigma_c^2 and p_c.
class BayesSolveKernel : public BayesKernel {};

TEST_F(BayesSolveKernel, MatchesReference) {
    const float sn = 0.19f, pn = 1.5f, snFinest = 0.38f;
    const int levels = 2;
    std::vector<SolveCase> cases;
    // Well-conditioned bands from known (s, p) plus the band's noise, and every fallback.
    for (double p : {0.4, 0.6, 1.0, 1.5, 2.5})
        for (double s : {0.05, 1.0, 20.0})
            for (int level : {0, 1}) {
                double sN = level == 0 ? snFinest : sn;
                double var = ref::GlSecondMoment(s, p), varN = ref::GlSecondMoment(sN, pn);
                cases.push_back(
                    {var + varN,
                     ref::GlFourthMoment(s, p) + ref::GlFourthMoment(sN, pn) + 6 * var * varN,
                     100, level});
            }
    double varN = ref::GlSecondMoment(sn, pn);
    cases.push_back({0.5 * varN, 1, 100, 1});  // no signal
    cases.push_back({1 + varN, 1e7, 100, 1});  // kurtosis too high
    cases.push_back({1 + varN, 0.5, 100, 1});  // 4th moment below the noise's
    cases.push_back({1 + varN, 2.0, 100, 1});  // kurtosis too low
    cases.push_back({0, 0, 0, 1});             // empty
    cases.push_back({NAN, 1, 100, 1});         // non-finite
    // Bands laid out as 3 per level: put case k at band (k / 3 levels) ... just use the
    // band index's level: band b has level (b % (3 levels)) / 3.
    std::vector<float> moments;
    std::vector<int> caseOfBand;
    int bands = 0;
    for (size_t k = 0; k < cases.size(); ++k) {
        // Find the next band index with the case's level.
        while (((bands % (3 * levels)) / 3) != cases[k].level) {
            moments.insert(moments.end(), {0, 0, 0, 0});
            caseOfBand.push_back(-1);
            ++bands;
        }
        moments.insert(moments.end(),
                       {float(cases[k].m2), float(cases[k].m4), 3.f, float(cases[k].count)});
        caseOfBand.push_back(int(k));
        ++bands;
    }
    vk::Buffer momentsGpu = Floats(moments, "moments");
    vk::Buffer params(Ctx(), bands * BAYES_PARAM_STRIDE * sizeof(float), "params");
    vk::Recorder recorder(Ctx());
    std::vector<float> noise(bands);
    for (int b = 0; b < bands; ++b) noise[b] = (b % (3 * levels)) / 3 == 0 ? snFinest : sn;
    vk::Buffer noiseGpu = Floats(noise, "noise");
    RecordBayesSolve(Ctx(), recorder, momentsGpu, bands, levels, noiseGpu, pn, params);
    recorder.Submit();
    std::vector<float> got = params.DownloadFloats(bands * BAYES_PARAM_STRIDE);
    for (int b = 0; b < bands; ++b) {
        const float *p = &got[b * BAYES_PARAM_STRIDE];
        int level = (b % (3 * levels)) / 3;
        double sN = level == 0 ? snFinest : sn;
        double m2 = moments[b * 4], m4 = moments[b * 4 + 1];
        ref::BandFit e = ref::SolveBand(m2, m4, int64_t(moments[b * 4 + 3]), sN, pn);
        SCOPED_TRACE(
            fmt::format("band {} (case {}): m2 {} m4 {} ref fit {} s_c {} p_c {}; gpu "
                        "fit {} s_c {} p_c {}",
                        b, caseOfBand[b], m2, m4, e.fit, e.sc, e.pc, p[4], p[2], p[3]));
        for (int i = 0; i < BAYES_PARAM_STRIDE; ++i) EXPECT_TRUE(std::isfinite(p[i])) << i;
        EXPECT_EQ(p[0], float(sN));
        ASSERT_EQ(int(p[4]), e.fit);
        if (e.fit == BAYES_FIT_NO_SIGNAL || e.fit == BAYES_FIT_EMPTY) continue;
        double vN = ref::GlSecondMoment(sN, pn), m4N = ref::GlFourthMoment(sN, pn);
        double varC = m2 - vN, m4C = m4 - m4N - 6 * varC * vN;
        // sigma_n^2 and m4_n come from float lgamma and exp: relative error E each.
        const double eps = 4 * kUnitRoundoff, E = 1e-5;
        double dVar = (eps * m2 + E * vN) / varC;
        double dM4 = (eps * m4 + E * (m4N + 6 * varC * vN) + 6 * vN * varC * dVar) / m4C;
        double errLogK = dM4 + 2 * dVar + 6 * 0x1p-20;
        double slope = std::fabs(std::log(ref::GlKurtosis(e.pc * 1.001)) -
                                 std::log(ref::GlKurtosis(e.pc * 0.999))) /
                       (0.002 * e.pc);
        double dp = e.fit == BAYES_FIT_SOLVED ? 2 * errLogK / slope + 1e-6 : 1e-7;
        EXPECT_NEAR(p[3], e.pc, dp);
        double scShift = std::fabs(std::sqrt(varC * std::exp(std::lgamma(1 / (e.pc + dp)) -
                                                             std::lgamma(3 / (e.pc + dp)))) -
                                   e.sc);
        EXPECT_NEAR(p[2], e.sc, 2 * scShift + (dVar + 1e-5) * e.sc);
    }
}

// One band per fit: the GPU table at its nodes against the direct integral at the same y
// (from the GPU's params), then the interpolated lookup of many coefficients against the
// direct integral per coefficient: the table's error, measured and bounded.
TEST_F(BayesKernel, TableAndShrinkMatchTheDirectIntegral) {
    const int w = 64, h = 64, levels = 2, channels = 2;
    // Coefficients: band-specific scales, Laplacian-ish, plus a few large ones.
    Image coef(w, h, channels);
    std::mt19937_64 rng(SeedFromName("bayes table"));
    std::normal_distribution<float> normal(0.f, 1.f);
    for (float &v : coef.data) v = normal(rng) * (normal(rng) > 1.2f ? 4.f : 0.4f);
    coef.At(0, 40, 40) = 25.f;
    coef.At(1, 5, 50) = -12.f;
    int bands = BayesBandCount(channels, levels);
    vk::GpuImage c(Ctx(), w, h, channels, "coef");
    c.Upload(coef);
    vk::Buffer moments(Ctx(), bands * 4 * sizeof(float), "moments"),
        params(Ctx(), bands * BAYES_PARAM_STRIDE * sizeof(float), "params"),
        table(Ctx(), bands * BAYES_TABLE_SIZE * sizeof(float), "table");
    const float sn = 0.19f, pn = 1.5f;
    vk::Recorder recorder(Ctx());
    RecordBayesMoments(Ctx(), recorder, c, levels, moments);
    std::vector<float> noise(bands);
    for (int b = 0; b < bands; ++b) noise[b] = (b % (3 * levels)) / 3 == 0 ? 2 * sn : sn;
    vk::Buffer noiseGpu = Floats(noise, "noise");
    RecordBayesSolve(Ctx(), recorder, moments, bands, levels, noiseGpu, pn, params);
    RecordBayesTable(Ctx(), recorder, params, bands, table);
    RecordBayesShrink(Ctx(), recorder, c, levels, params, table);
    recorder.Submit();
    std::vector<float> p = params.DownloadFloats(bands * BAYES_PARAM_STRIDE);
    std::vector<float> t = table.DownloadFloats(bands * BAYES_TABLE_SIZE);
    Image shrunk = c.Download();
    std::vector<ref::BayesBand> refBands = ref::BayesBands(w, h, channels, levels);
    int solved = 0;
    double worstNode = 0, worstLookup = 0, worstNodeAbs = 0, worstLookupAbs = 0;
    for (int b = 0; b < bands; ++b) {
        const float *q = &p[b * BAYES_PARAM_STRIDE];
        ref::BandFit fit{int(q[4]), q[2], q[3]};
        solved += fit.fit == BAYES_FIT_SOLVED;
        // Nodes: float quadrature of the same rule. Each log term carries a few ulp of its
        // own size, (|y|/s_n)^p_n at most, so the weights are off by that relatively and
        // the mean by that times the posterior's spread (about s_n), plus 8 u of y.
        for (int i = 0; i < BAYES_TABLE_SIZE; ++i) {
            double y = double(q[6]) * std::sinh(double(i) * q[7]);
            double e = ref::PosteriorMean(y, fit, q[0], q[1]);
            double bound = 64 * kUnitRoundoff * (1 + std::pow(y / q[0], q[1])) * q[0] +
                           8 * kUnitRoundoff * y + 1e-7;
            worstNode = std::max(worstNode, std::fabs(t[b * BAYES_TABLE_SIZE + i] - e) / bound);
            worstNodeAbs =
                std::max(worstNodeAbs, std::fabs(t[b * BAYES_TABLE_SIZE + i] - e) / q[0]);
            EXPECT_NEAR(t[b * BAYES_TABLE_SIZE + i], e, bound) << "band " << b << " node " << i;
        }
        // Lookups: linear interpolation in u = asinh(y / s_n) with step du: the error is at
        // most du^2 / 8 max |d^2 c^ / du^2|; c^ ~ y far out gives d^2/du^2 ~ y, and the knee
        // near y ~ s_n bends it by about s_n. Bound: du^2 (|y| + 4 s_n) (measured below).
        const ref::BayesBand &band = refBands[b];
        double du = q[7];
        for (int y = band.y0; y < band.y1; ++y)
            for (int x = band.x0; x < band.x1; ++x) {
                double v = coef.At(band.channel, y, x);
                double e = ref::PosteriorMean(v, fit, q[0], q[1]);
                double bound =
                    du * du * (std::fabs(v) + 4 * q[0]) + 1e-5 * (std::fabs(v) + q[0]);
                double err = std::fabs(shrunk.At(band.channel, y, x) - e);
                worstLookup = std::max(worstLookup, err / bound);
                worstLookupAbs = std::max(worstLookupAbs, err / q[0]);
                EXPECT_NEAR(shrunk.At(band.channel, y, x), e, bound)
                    << "band " << b << " at (" << x << ", " << y << ") y = " << v;
            }
    }
    EXPECT_GT(solved, 0);
    std::printf(
        "[ table ] worst node error %.3g of its bound (%.2g s_n), worst lookup %.3g of its "
        "bound "
        "(%.2g s_n)\n",
        worstNode, worstNodeAbs, worstLookup, worstLookupAbs);
    // The low-low band is untouched.
    for (int y = 0; y < LevelExtent(h, levels); ++y)
        for (int x = 0; x < LevelExtent(w, levels); ++x)
            EXPECT_EQ(shrunk.At(0, y, x), coef.At(0, y, x));
}

// ---------------------------------------------------------------- the whole method

bool AllFinite(const Image &image) {
    for (float v : image.data)
        if (!std::isfinite(v)) return false;
    return true;
}

// GPU against the reference end to end. The GPU's per-coefficient error is the table's
// (bounded above) plus float analysis error; the fits may move within their bound. In the
// log domain the output's error is then a few times the shrink error, summed over levels:
// 2e-3 absolute in log (0.2% in value) covers it with room, and the mean stays at 1e-4.
struct SizeBasisCase {
    int w, h;
    WaveletBasis basis;
};

std::string SizeBasisName(const testing::TestParamInfo<SizeBasisCase> &info) {
    return fmt::format("{}x{}_{}", info.param.w, info.param.h, WaveletName(info.param.basis));
}

std::vector<SizeBasisCase> WholeMethodCases() {
    std::vector<SizeBasisCase> cases;
    for (auto [w, h] : kSizes)
        for (WaveletBasis basis : {WaveletBasis::Haar, WaveletBasis::Cdf97})
            cases.push_back({w, h, basis});
    return cases;
}

class BayesKernelWholeMethod : public BayesKernelWithParam<SizeBasisCase> {};

TEST_P(BayesKernelWholeMethod, MatchesReference) {
    const auto [w, h, basis] = GetParam();
    SCOPED_TRACE(fmt::format("{}x{} {}", w, h, WaveletName(basis)));
    Image color = NoisyPicture(w, h, SeedFromName(fmt::format("whole{}x{}", w, h)), 0.3);
    BayesParams options = PaperBayesParams();
    options.basis = basis;
    BayesResult gpu = BayesDenoise(Ctx(), color, options);
    BayesParams refParams = options;
    refParams.levels = gpu.levels;
    ref::BayesRefResult cpu = ref::BayesDenoise(color, refParams);
    ASSERT_EQ(gpu.fits.size(), cpu.fits.size());
    for (size_t b = 0; b < cpu.fits.size(); ++b)
        EXPECT_EQ(int(gpu.fits[b].params[4]), cpu.fits[b].fit) << "band " << b;
    Image logGpu = gpu.image, logCpu = cpu.image;
    for (float &v : logGpu.data) v = std::log(v);
    for (float &v : logCpu.data) v = std::log(v);
    EXPECT_TRUE(ImagesMatch(logCpu, logGpu, {}, {0, 2e-3, 1e-4}));
}

INSTANTIATE_TEST_SUITE_P(Cases, BayesKernelWholeMethod, testing::ValuesIn(WholeMethodCases()),
                         SizeBasisName);

// Cycle spinning on both sides: the same tolerance as one run (an average of results
// each within it).
struct SpinCase {
    int w, h, spins;
};

std::string SpinCaseName(const testing::TestParamInfo<SpinCase> &info) {
    return fmt::format("{}x{}_spins{}", info.param.w, info.param.h, info.param.spins);
}

class BayesKernelCycleSpinning : public BayesKernelWithParam<SpinCase> {};

TEST_P(BayesKernelCycleSpinning, MatchesReference) {
    const auto [w, h, spins] = GetParam();
    SCOPED_TRACE(fmt::format("{}x{} spins {}", w, h, spins));
    Image color = NoisyPicture(w, h, SeedFromName(fmt::format("spin{}x{}", w, h)), 0.3);
    BayesParams options = PaperBayesParams();
    options.spins = spins;
    BayesResult gpu = BayesDenoise(Ctx(), color, options);
    // Levels clamped per shifted image on both sides.
    Image cpu = ref::BayesDenoise(color, options).image;
    for (float &v : gpu.image.data) v = std::log(v);
    for (float &v : cpu.data) v = std::log(v);
    EXPECT_TRUE(ImagesMatch(cpu, gpu.image, {}, {0, 2e-3, 1e-4}));
    EXPECT_TRUE(Contains(gpu.plan[0], "cycle spinning"));
}

INSTANTIATE_TEST_SUITE_P(Cases, BayesKernelCycleSpinning,
                         testing::Values(SpinCase{19, 11, 2}, SpinCase{1, 6, 2},
                                         SpinCase{2, 3, 4}),
                         SpinCaseName);

// Noise models at the ends of the options' ranges, against the reference with the whole
// method's tolerance. p_n 10 with s_n 0.01: (|y - c| / s_n)^10 overflowed float before
// model.glsl capped the exponent (NaN tables, a black image; 1e-3 too, measured with `diff`,
// left out here for time: its tables need the full 65536 points). s_n 1e-30: below
// BAYES_MIN_NOISE_S every band is NO_NOISE and the input comes back through the transforms
// (before: NaN bands, a black image). p_n 0.1: every band NO_SIGNAL.
class BayesKernelExtremeNoiseModel : public BayesKernelWithParam<std::pair<float, float>> {};

TEST_P(BayesKernelExtremeNoiseModel, MatchesReference) {
    const auto [sn, pn] = GetParam();
    // The same frame for every case.
    Image color = NoisyPicture(23, 14, SeedFromName("extreme noise models"), 0.3);
    SCOPED_TRACE(fmt::format("s_n {} p_n {}", sn, pn));
    BayesParams options = PaperBayesParams();
    options.sn = sn;
    options.pn = pn;
    BayesResult gpu = BayesDenoise(Ctx(), color, options);
    EXPECT_TRUE(AllFinite(gpu.image));
    ref::BayesRefResult cpu = ref::BayesDenoise(color, options);
    for (size_t b = 0; b < cpu.fits.size(); ++b)
        EXPECT_EQ(int(gpu.fits[b].params[4]), cpu.fits[b].fit) << "band " << b;
    for (float &v : gpu.image.data) v = std::log(v);
    for (float &v : cpu.image.data) v = std::log(v);
    EXPECT_TRUE(ImagesMatch(cpu.image, gpu.image, {}, {0, 2e-3, 1e-4}));
    if (pn < 0.2f) {
        for (const BayesBandFit &f : gpu.fits) {
            EXPECT_EQ(int(f.params[4]), BAYES_FIT_NO_SIGNAL);
        }
    }
    if (sn < BAYES_MIN_NOISE_S) {
        for (const BayesBandFit &f : gpu.fits) EXPECT_EQ(int(f.params[4]), BAYES_FIT_NO_NOISE);
        Image logIn = color;
        for (float &v : logIn.data) v = std::log(v);
        EXPECT_TRUE(ImagesMatch(logIn, gpu.image, {}, {0, 1e-5, 1e-6}));
    }
}

INSTANTIATE_TEST_SUITE_P(Cases, BayesKernelExtremeNoiseModel,
                         testing::Values(std::pair{0.01f, 10.f}, std::pair{1e-30f, 1.5f},
                                         std::pair{0.19f, 0.1f}),
                         [](const testing::TestParamInfo<std::pair<float, float>> &info) {
                             return fmt::format("sn{}_pn{}", NameOf(info.param.first),
                                                NameOf(info.param.second));
                         });

// --noise auto with cycle spinning: one estimate (the unshifted image's) for every shift,
// so the reference given that s_n agrees within the usual tolerance.
TEST_F(BayesKernel, NoiseAutoSpinsShareOneEstimate) {
    Image color = NoisyPicture(21, 13, SeedFromName("auto spins"), 0.3);
    BayesParams options = PaperBayesParams();
    options.noise = BayesNoise::Mad;
    options.spins = 2;
    BayesResult gpu = BayesDenoise(Ctx(), color, options);
    BayesParams once = options;
    once.spins = 1;
    EXPECT_EQ(BayesDenoise(Ctx(), color, once).sn, gpu.sn);
    ref::BayesRefRun run;
    run.madSn = gpu.sn;
    Image cpu = ref::BayesDenoise(color, options, run).image;
    for (float &v : gpu.image.data) v = std::log(v);
    for (float &v : cpu.data) v = std::log(v);
    EXPECT_TRUE(ImagesMatch(cpu, gpu.image, {}, {0, 2e-3, 1e-4}));
}

// --noise mad on a frame mostly black (exact zeros, as a few samples per pixel leave a dark
// scene): in the log domain its zeros sit at the floor and their finest coefficients are
// exactly 0, which the median leaves out, so the estimate is the noisy part's. Counted, they
// are over half the sample and the noise reads 0: the frame comes back as it went in. Both
// transforms; the noisy part alone (the same pixels, 16 wide) gives the reference estimate.
TEST_F(BayesKernel, NoiseMadLeavesOutTheBlackPixelsExactZeros) {
    const int w = 64, h = 24, part = 16;
    Image noisy = NoisyPicture(part, h, SeedFromName("mad zeros"), 0.3);
    Image frame(w, h, 3);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < part; ++x) frame.At(c, y, w - part + x) = noisy.At(c, y, x);
    for (const char *transform : {"dwt", "swt"}) {
        SCOPED_TRACE(transform);
        BayesParams options = PaperBayesParams();
        options.noise = BayesNoise::Mad;
        options.transform =
            std::string(transform) == "swt" ? BayesTransform::Swt : BayesTransform::Dwt;
        const float alone = BayesDenoise(Ctx(), noisy, options).sn;
        BayesResult mixed = BayesDenoise(Ctx(), frame, options);
        fmt::print("{}: s_n {:.4g} on the frame, {:.4g} on its noisy part\n", transform,
                   mixed.sn, alone);
        ASSERT_GT(alone, 0.05f);
        EXPECT_GT(mixed.sn, 0.6f * alone);
        EXPECT_LT(mixed.sn, 1.6f * alone);
        // The noisy part is denoised: its pixels move.
        double moved = 0;
        for (int c = 0; c < 3; ++c)
            for (int y = 0; y < h; ++y)
                for (int x = w - part; x < w; ++x)
                    moved += std::fabs(mixed.image.At(c, y, x) - frame.At(c, y, x));
        EXPECT_GT(moved / (3 * h * part), 0.02);
    }
}

// The mix kernel: three products and two sums in float per output, so within 4 u of
// sum |m_ij| |v_j|; forward then inverse gives the input back within twice that.
class BayesMixKernel : public BayesKernel {};

TEST_F(BayesMixKernel, MatchesReference) {
    Image v = MakeInput(InputKind::Uniform, 37, 5, 3, SeedFromName("bayes mix"));
    vk::GpuImage image(Ctx(), 37, 5, 3, "mix");
    image.Upload(v);
    vk::Recorder recorder(Ctx());
    RecordBayesMix(Ctx(), recorder, image, BayesOpponent());
    recorder.Submit();
    Image mixed = image.Download();
    const double k3 = 1 / std::sqrt(3.0), k2 = 1 / std::sqrt(2.0), k6 = 1 / std::sqrt(6.0);
    const double m[3][3] = {{k3, k3, k3}, {k2, -k2, 0}, {k6, k6, -2 * k6}};
    for (int y = 0; y < 5; ++y)
        for (int x = 0; x < 37; ++x)
            for (int i = 0; i < 3; ++i) {
                double e = 0, scale = 0;
                for (int j = 0; j < 3; ++j)
                    e += m[i][j] * v.At(j, y, x), scale += std::fabs(m[i][j] * v.At(j, y, x));
                EXPECT_NEAR(mixed.At(i, y, x), e, 4 * kUnitRoundoff * scale + 1e-30);
            }
    RecordBayesMix(Ctx(), recorder, image, BayesOpponentInverse());
    recorder.Submit();
    Image back = image.Download();
    for (size_t i = 0; i < v.Size(); ++i) EXPECT_NEAR(back.data[i], v.data[i], 2e-6);
}

// Luminance + chroma: the same pipeline with the opponent mix around the transform.
class BayesKernelOpponentColour : public BayesKernelWithParam<std::pair<int, int>> {};

TEST_P(BayesKernelOpponentColour, MatchesReference) {
    const auto [w, h] = GetParam();
    SCOPED_TRACE(fmt::format("{}x{}", w, h));
    Image color = NoisyPicture(w, h, SeedFromName(fmt::format("opp{}x{}", w, h)), 0.3);
    BayesParams options = PaperBayesParams();
    options.opponent = true;
    BayesResult gpu = BayesDenoise(Ctx(), color, options);
    ref::BayesRefResult cpu = ref::BayesDenoise(color, options);
    for (size_t b = 0; b < cpu.fits.size(); ++b)
        EXPECT_EQ(int(gpu.fits[b].params[4]), cpu.fits[b].fit) << "band " << b;
    Image logGpu = gpu.image, logCpu = cpu.image;
    for (float &v : logGpu.data) v = std::log(v);
    for (float &v : logCpu.data) v = std::log(v);
    EXPECT_TRUE(ImagesMatch(logCpu, logGpu, {}, {0, 2e-3, 1e-4}));
}

INSTANTIATE_TEST_SUITE_P(Cases, BayesKernelOpponentColour,
                         testing::Values(std::pair{23, 17}, std::pair{1, 1}, std::pair{4, 9}),
                         SizeName);

TEST_F(BayesKernel, OpponentColourRefusesOtherThanThreeChannels) {
    BayesParams options = PaperBayesParams();
    options.opponent = true;
    EXPECT_TRUE(ThrowsError(ErrorKind::InvalidArgument,
                            [&] { BayesDenoise(Ctx(), Image(4, 4, 2, 1.f), options); }));
}

TEST_F(BayesKernel, RerunsAreBitIdentical) {
    Image color = AwkwardInput(45, 31, 3, SeedFromName("bayes rerun"));
    BayesParams options = PaperBayesParams();
    options.basis = WaveletBasis::Cdf97;
    options.noise = BayesNoise::Mad;
    options.spins = 2;
    Image first = BayesDenoise(Ctx(), color, options).image;
    Image second = BayesDenoise(Ctx(), color, options).image;
    EXPECT_TRUE(BitIdentical(first, second));
}

// ---------------------------------------------------------------- properties

class BayesProperties : public GpuTest {};

bool AnyWarning(const BayesResult &r, const std::string &part) {
    for (const std::string &w : r.warnings)
        if (Contains(w, part)) return true;
    return false;
}

// Blender's and accumulate's indirect = color - direct rounds a few ulps below 0 where all
// the light is direct: those are zeros (no warning of negative values), real ones are warned.
TEST_F(BayesProperties, SplitRoundingIsNotWarnedAsNegative) {
    const int w = 24, h = 16;
    Image direct = NoisyPicture(w, h, SeedFromName("split direct"), 0.3);
    Image indirect = NoisyPicture(w, h, SeedFromName("split indirect"), 0.3);
    for (int x = 0; x < w; x += 3) indirect.At(1, 5, x) = -2e-7f * direct.At(1, 5, x);
    BayesResult r = BayesDenoiseSplit(Ctx(), direct, indirect, BayesParams());
    EXPECT_FALSE(AnyWarning(r, "negative")) << ::testing::PrintToString(r.warnings);
    bool said = false;
    for (const std::string &line : r.plan) said |= Contains(line, "8 values of the indirect");
    EXPECT_TRUE(said) << ::testing::PrintToString(r.plan);
    indirect.At(2, 9, 4) = -0.25f;
    r = BayesDenoiseSplit(Ctx(), direct, indirect, BayesParams());
    EXPECT_TRUE(AnyWarning(r, "(indirect layer): 1 negative value"))
        << ::testing::PrintToString(r.warnings);
    // The bound is 8 float epsilons (2^-20) times |direct|: at it a zero, one float past it
    // negative light.
    indirect.At(2, 9, 4) = 0.25f;
    float bound = 0x1p-20f * std::fabs(direct.At(0, 2, 7));
    indirect.At(0, 2, 7) = -bound;
    indirect.At(0, 3, 7) = -std::nextafter(0x1p-20f * std::fabs(direct.At(0, 3, 7)), 1.f);
    r = BayesDenoiseSplit(Ctx(), direct, indirect, BayesParams());
    EXPECT_TRUE(AnyWarning(r, "(indirect layer): 1 negative value (first at pixel (7, 3)"))
        << ::testing::PrintToString(r.warnings);
    said = false;
    for (const std::string &line : r.plan) said |= Contains(line, "9 values of the indirect");
    EXPECT_TRUE(said) << ::testing::PrintToString(r.plan);
}

// --zeros restore: the zeros kept black, the missed samples filled (a dark pixel lone among
// lit pixels) and the zeros denoised from the floor (one channel of a lit pixel) are counted
// apart.
TEST_F(BayesProperties, RestoreSaysWhichZerosStayBlack) {
    Image color = NoisyPicture(20, 12, SeedFromName("lone zeros"), 0.3);
    for (float &v : color.data) v = std::max(v, 0.05f);
    color.At(0, 4, 6) = 0;
    for (int c = 0; c < 3; ++c) color.At(c, 2, 13) = 0;  // a missed sample
    for (int c = 0; c < 3; ++c)
        for (int x = 0; x < 20; ++x) color.At(c, 9, x) = 0;  // a black line
    BayesResult r = BayesDenoise(Ctx(), color, PaperBayesParams());
    for (const char *part :
         {"64 black or nearly black values", "the 60 black ones stay black",
          "; 3 in dark pixels lone among lit pixels", "; 1 denoised from the floor"})
        EXPECT_TRUE(AnyWarning(r, part)) << part << ::testing::PrintToString(r.warnings);
    EXPECT_GT(r.image.At(0, 4, 6), 0.f);
    for (int c = 0; c < 3; ++c) EXPECT_GT(r.image.At(c, 2, 13), 0.f);
    bool said = false;  // --explain tells of the fill
    for (const std::string &line : r.plan)
        said |= Contains(line, "samples that missed the light");
    EXPECT_TRUE(said) << ::testing::PrintToString(r.plan);
    for (int x = 0; x < 20; ++x) EXPECT_EQ(r.image.At(0, 9, x), 0.f);
}

// --zeros restore keeps zeros with a black pair of neighbours black; in low-spp indirect
// light half the pixels' samples miss it and most zeros have such a pair (issue 29's black
// holes): restore refuses the frame, saying why and what to use. A black region as large,
// whose zeros are mostly inside it, runs.
TEST_F(BayesProperties, RestoreRefusesZerosTooDense) {
    Image speckled = NoisyPicture(32, 32, SeedFromName("dense zeros"), 0.3);
    std::mt19937_64 rng(SeedFromName("dense zeros missed"));
    std::bernoulli_distribution missed(0.5);
    for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 32; ++x) {
            bool miss = missed(rng);
            for (int c = 0; c < 3; ++c)
                speckled.At(c, y, x) = miss ? 0.f : std::max(speckled.At(c, y, x), 0.05f);
        }
    auto restore = [&] { BayesDenoise(Ctx(), speckled, PaperBayesParams()); };
    EXPECT_TRUE(ThrowsError(ErrorKind::InvalidArgument, restore,
                            "--zeros restore refused: zeros too dense"));
    EXPECT_TRUE(Contains(ErrorOf(restore), "use --zeros denoise")) << ErrorOf(restore);
    BayesParams denoise = PaperBayesParams();
    denoise.restoreZeros = false;
    EXPECT_TRUE(AllFinite(BayesDenoise(Ctx(), speckled, denoise).image));
    // The split names the indirect layer in its refusal, and only there; bad parameters and
    // an empty image are refused as such first.
    Image direct(32, 32, 3);
    EXPECT_TRUE(ThrowsError(
        ErrorKind::InvalidArgument,
        [&] { BayesDenoiseSplit(Ctx(), direct, speckled, PaperBayesParams()); },
        "bayes (indirect layer): --zeros restore refused"));
    BayesParams bad = PaperBayesParams();
    bad.pn = 20;
    EXPECT_TRUE(ThrowsError(
        ErrorKind::InvalidArgument, [&] { BayesDenoiseSplit(Ctx(), direct, speckled, bad); },
        "bayes: p_n must be in"));
    EXPECT_TRUE(ThrowsError(
        ErrorKind::InvalidArgument, [&] { BayesDenoise(Ctx(), Image(), PaperBayesParams()); },
        "bayes: the image is empty"));

    Image region = NoisyPicture(32, 32, SeedFromName("dense zeros region"), 0.3);
    for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 32; ++x)
            for (int c = 0; c < 3; ++c)
                region.At(c, y, x) = x < 16 ? 0.f : std::max(region.At(c, y, x), 0.05f);
    BayesResult r = BayesDenoise(Ctx(), region, PaperBayesParams());
    EXPECT_TRUE(AnyWarning(r, "black ones stay black")) << ::testing::PrintToString(r.warnings);
}

// The refusal asks both that the zeros kept black be a tenth of the values and that half lie
// beside a lit value. A zero is kept black between two black neighbours: the middles of runs
// of three black pixels across a lit frame, each beside lit pixels above and below, pass the
// second test; 307 of the 3072 values run, 308 (a tenth or more) are refused.
TEST_F(BayesProperties, RestoreRefusesZerosFromATenthOfTheValues) {
    for (auto [kept, refused, spins] : {std::tuple{307, false, 1}, std::tuple{308, true, 1},
                                        std::tuple{307, false, 2}, std::tuple{308, true, 2}}) {
        BayesParams params = PaperBayesParams();
        params.spins = spins;
        Image color = NoisyPicture(32, 32, SeedFromName("few dense zeros"), 0.3);
        for (float &v : color.data) v = std::max(v, 0.05f);
        // Runs of three on the odd rows, away from the frame's edges (clamped neighbours
        // there are black too), in as many channels as the count has left.
        int left = kept;
        for (int y = 1; y < 32; y += 2)
            for (int x0 = 2; x0 + 2 < 30; x0 += 4)
                for (int c = 0, n = std::min(3, left); c < n; ++c, --left)
                    for (int x = x0; x < x0 + 3; ++x) color.At(c, y, x) = 0;
        ASSERT_EQ(left, 0);
        SCOPED_TRACE(fmt::format("{} kept black, spins {}", kept, spins));
        if (refused) {
            auto restore = [&] { BayesDenoise(Ctx(), color, params); };
            EXPECT_TRUE(
                ThrowsError(ErrorKind::InvalidArgument, restore,
                            fmt::format("({} of the 3072 values would stay black", kept)));
        } else {
            BayesResult r = BayesDenoise(Ctx(), color, params);
            const std::string stay = fmt::format("the {} black ones stay black", kept);
            EXPECT_TRUE(AnyWarning(r, stay.c_str())) << ::testing::PrintToString(r.warnings);
        }
    }
}

// The refusal's second test, half the zeros kept black beside a lit value, at its edge. The
// top 6 rows black in channel 0 keep 160 zeros inside black (rows 0 to 4) and 32 beside light
// (row 5); the middles of runs of three black pixels below add one beside light each. With
// 128 runs, 160 of the 320 kept are beside light (half: refused); with 127, 159 of 318 run.
TEST_F(BayesProperties, RestoreRefusesFromHalfTheZerosBesideLight) {
    for (auto [runs, refused] : {std::pair{127, false}, std::pair{128, true}}) {
        Image color = NoisyPicture(32, 32, SeedFromName("zeros beside light"), 0.3);
        for (float &v : color.data) v = std::max(v, 0.05f);
        for (int y = 0; y < 6; ++y)
            for (int x = 0; x < 32; ++x) color.At(0, y, x) = 0;
        int left = runs;
        for (int y = 7; y < 32; y += 2)
            for (int x0 = 2; x0 + 2 < 30; x0 += 4)
                for (int c = 0, n = std::min(3, left); c < n; ++c, --left)
                    for (int x = x0; x < x0 + 3; ++x) color.At(c, y, x) = 0;
        ASSERT_EQ(left, 0);
        const int kept = 192 + runs, beside = 32 + runs;
        SCOPED_TRACE(fmt::format("{} kept black, {} beside light", kept, beside));
        if (refused) {
            auto restore = [&] { BayesDenoise(Ctx(), color, PaperBayesParams()); };
            EXPECT_TRUE(ThrowsError(
                ErrorKind::InvalidArgument, restore,
                fmt::format("({} of the 3072 values would stay black, at least 10%, and {} of "
                            "them are beside a lit value",
                            kept, beside)));
        } else {
            BayesResult r = BayesDenoise(Ctx(), color, PaperBayesParams());
            const std::string stay = fmt::format("the {} black ones stay black", kept);
            EXPECT_TRUE(AnyWarning(r, stay.c_str())) << ::testing::PrintToString(r.warnings);
        }
    }
}

// A lit frame whose `side` x `side` top left corner is speckled with zeros: half its pixels'
// samples missed the light (black in every channel), as in low-spp indirect light.
Image SpeckledCorner(int width, int height, int side) {
    Image color = NoisyPicture(width, height, SeedFromName("speckled corner"), 0.3);
    std::mt19937_64 rng(SeedFromName("speckled corner missed"));
    std::bernoulli_distribution missed(0.5);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            bool miss = x < side && y < side && missed(rng);
            for (int c = 0; c < 3; ++c)
                color.At(c, y, x) = miss ? 0.f : std::max(color.At(c, y, x), 0.05f);
        }
    return color;
}

// --zeros restore is decided on the whole frame, in tiles as whole: a frame speckled all over
// is refused either way with the frame's counts, before any tile runs; one speckled only in a
// 16x16 corner passes either way, though its first tile's window (the tile and its halo; a
// small halo: one level, no local mean) alone is refused.
TEST_F(BayesProperties, RestoreDecidesOnTheWholeFrameInTiles) {
    Device device = api::BorrowDevice(Ctx());
    Method method("bayes");
    method.Set("zeros", std::string("restore"));
    method.Set("bayes-levels", 1);
    method.Set("bayes-mean-radius", 0);
    for (int tile : {0, 16}) {
        SCOPED_TRACE(fmt::format("tile size {}", tile));
        RunOptions run;
        run.tileSize = tile;
        Frame dense(64, 64);
        dense.layers["color"] = SpeckledCorner(64, 64, 64);
        auto restore = [&] { method.Run(device, dense, run); };
        EXPECT_TRUE(
            ThrowsError(ErrorKind::InvalidArgument, restore, "bayes: --zeros restore refused"));
        EXPECT_TRUE(Contains(ErrorOf(restore), "of the 12288 values would stay black"))
            << ErrorOf(restore);

        Frame corner(64, 64);
        corner.layers["color"] = SpeckledCorner(64, 64, 16);
        Result r = method.Run(device, corner, run);
        EXPECT_TRUE(r.image.SameShape(corner.layers["color"]));
        int halo = -1;
        for (const std::string &line : r.plan)
            if (size_t at = line.find("a halo of "); at != std::string::npos)
                halo = std::stoi(line.substr(at + 10));
        if (tile == 0) {
            EXPECT_EQ(halo, -1) << ::testing::PrintToString(r.plan);
            continue;
        }
        ASSERT_GT(halo, 0) << ::testing::PrintToString(r.plan);
        const int side = tile + halo;
        Frame window(side, side);
        window.layers["color"] = Image(side, side, 3);
        for (int c = 0; c < 3; ++c)
            for (int y = 0; y < side; ++y)
                for (int x = 0; x < side; ++x)
                    window.layers["color"].At(c, y, x) = corner.layers["color"].At(c, y, x);
        EXPECT_TRUE(ThrowsError(
            ErrorKind::InvalidArgument, [&] { method.Run(device, window, RunOptions()); },
            "--zeros restore refused"))
            << side;
    }
}

// Auto's bayes probe (SURE: the colour perturbed by its noise) may hold zeros denser than the
// frame's: it keeps the frame's --zeros restore decision. Here the frame's zeros are lone
// (none kept black: it runs), while the probe's wide noise turns about half their neighbours
// negative, black, which alone would be refused.
TEST_F(BayesProperties, RestoreInAutoProbesAsTheFrameDecided) {
    Device device = api::BorrowDevice(Ctx());
    Frame frame(32, 32);
    Image color = NoisyPicture(32, 32, SeedFromName("lone zeros"), 0.3);
    Image variance(32, 32, 3);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < 32; ++y)
            for (int x = 0; x < 32; ++x) {
                bool zero = x % 2 == 0 && y % 2 == 0;
                color.At(c, y, x) = zero ? 0.f : std::max(color.At(c, y, x), 0.05f);
                variance.At(c, y, x) = zero ? 0.f : 1e6f;
            }
    frame.layers["color"] = color;
    frame.layers["variance"] = variance;
    Method method("auto");
    method.Set("zeros", std::string("restore"));
    method.Set("auto-candidates", std::string("bayes"));
    Result r = method.Run(device, frame);
    EXPECT_TRUE(r.image.SameShape(color));
    // The same run of bayes on a colour perturbed as widely is refused.
    std::mt19937_64 rng(SeedFromName("lone zeros probe"));
    std::bernoulli_distribution negative(0.5);
    Frame probe(32, 32);
    probe.layers["color"] = color;
    for (float &v : probe.layers["color"].data)
        if (v > 0 && negative(rng)) v = -v;
    Method bayes("bayes");
    bayes.Set("zeros", std::string("restore"));
    EXPECT_TRUE(ThrowsError(
        ErrorKind::InvalidArgument, [&] { bayes.Run(device, probe); },
        "--zeros restore refused"));
}

TEST_F(BayesProperties, ExtremeInputsGiveFiniteOutputAndCountedWarnings) {
    const int w = 33, h = 21;
    // Zeros, 1e-8 and 1e8 in one image.
    Image mixed = NoisyPicture(w, h, SeedFromName("mixed"), 0.3);
    for (int x = 0; x < w; ++x) mixed.At(0, 3, x) = 0;
    mixed.At(1, 10, 10) = 1e-8f;
    mixed.At(2, 11, 11) = 1e8f;
    BayesResult r = BayesDenoise(Ctx(), mixed, PaperBayesParams());
    EXPECT_TRUE(AllFinite(r.image));
    // One warning for the 33 zeros and the tiny value, saying what became of them.
    EXPECT_TRUE(AnyWarning(r, "34 black or nearly black values"))
        << ::testing::PrintToString(r.warnings);
    EXPECT_TRUE(AnyWarning(r, "the 33 black ones stay black"))
        << ::testing::PrintToString(r.warnings);
    for (int x = 0; x < w; ++x) EXPECT_EQ(r.image.At(0, 3, x), 0.f) << "black stays black";
    // NaN/Inf/negatives: 0 out, counted.
    Image bad = NoisyPicture(w, h, SeedFromName("bad"), 0.3);
    bad.At(0, 1, 2) = std::numeric_limits<float>::quiet_NaN();
    bad.At(1, 4, 5) = std::numeric_limits<float>::infinity();
    bad.At(2, 6, 7) = -std::numeric_limits<float>::infinity();
    bad.At(2, 8, 9) = -3.f;
    r = BayesDenoise(Ctx(), bad, PaperBayesParams());
    EXPECT_TRUE(AllFinite(r.image));
    EXPECT_TRUE(AnyWarning(r, "3 NaN/Inf values (first at pixel (2, 1), channel 0)"))
        << ::testing::PrintToString(r.warnings);
    EXPECT_TRUE(AnyWarning(r, "1 negative value")) << ::testing::PrintToString(r.warnings);
    EXPECT_EQ(r.image.At(0, 1, 2), 0.f);
    // All zeros, all NaN, pure noise (no signal at all), constant.
    for (float fill : {0.f, std::numeric_limits<float>::quiet_NaN()}) {
        BayesResult z = BayesDenoise(Ctx(), Image(w, h, 3, fill), PaperBayesParams());
        EXPECT_TRUE(AllFinite(z.image));
        for (float v : z.image.data) EXPECT_EQ(v, 0.f);
        EXPECT_FALSE(z.warnings.empty());
    }
    Image noise(w, h, 3);
    std::mt19937_64 rng(SeedFromName("pure noise"));
    std::normal_distribution<float> normal(0.f, 0.19f);
    for (float &v : noise.data) v = std::exp(normal(rng));
    BayesParams options = PaperBayesParams();
    options.noise = BayesNoise::Mad;
    BayesResult pure = BayesDenoise(Ctx(), noise, options);
    EXPECT_TRUE(AllFinite(pure.image));
    // Pure noise: the output varies far less than the input.
    double varIn = 0, varOut = 0, meanIn = 0, meanOut = 0;
    for (size_t i = 0; i < noise.Size(); ++i)
        meanIn += noise.data[i], meanOut += pure.image.data[i];
    meanIn /= noise.Size(), meanOut /= noise.Size();
    for (size_t i = 0; i < noise.Size(); ++i)
        varIn += std::pow(noise.data[i] - meanIn, 2),
            varOut += std::pow(pure.image.data[i] - meanOut, 2);
    EXPECT_LT(varOut, 0.25 * varIn) << varIn << " -> " << varOut;
    Image constant(w, h, 3, 0.37f);
    BayesResult k = BayesDenoise(Ctx(), constant, PaperBayesParams());
    for (float v : k.image.data) EXPECT_NEAR(v, 0.37f, 1e-5f);
    for (const BayesBandFit &f : k.fits) EXPECT_EQ(int(f.params[4]), BAYES_FIT_NO_SIGNAL);
}

TEST_F(BayesProperties, BadOptionsAreRefused) {
    Image color(8, 6, 3, 0.5f);
    BayesParams o = PaperBayesParams();
    o.sn = -1;
    EXPECT_TRUE(
        ThrowsError(ErrorKind::InvalidArgument, [&] { BayesDenoise(Ctx(), color, o); }));
    o = PaperBayesParams();
    o.pn = std::numeric_limits<float>::quiet_NaN();
    EXPECT_TRUE(
        ThrowsError(ErrorKind::InvalidArgument, [&] { BayesDenoise(Ctx(), color, o); }));
    o = PaperBayesParams();
    o.floorRel = 0;
    EXPECT_TRUE(
        ThrowsError(ErrorKind::InvalidArgument, [&] { BayesDenoise(Ctx(), color, o); }));
    EXPECT_TRUE(ThrowsError(ErrorKind::InvalidArgument,
                            [&] { BayesDenoise(Ctx(), Image(), PaperBayesParams()); }));
    EXPECT_TRUE(ThrowsError(ErrorKind::InvalidArgument, [&] {
        BayesDenoiseSplit(Ctx(), color, Image(8, 5, 3, 0.1f), PaperBayesParams());
    }));
}

// --noise auto on log-normal noise of known sigma recovers the finest level's s: for
// Haar, white noise of standard deviation sigma keeps sigma in every band, and s of a
// p = 2 generalised Laplacian is sigma sqrt(2).
TEST_F(BayesProperties, NoiseAutoEstimatesTheNoise) {
    const double sigma = 0.3;
    Image noise = LogNormalNoise(96, 96, SeedFromName("noise auto"), sigma);
    BayesParams options = PaperBayesParams();
    options.noise = BayesNoise::Mad;
    options.pn = 2;
    options.hpFactor = 1;
    BayesResult r = BayesDenoise(Ctx(), noise, options);
    EXPECT_NEAR(r.sn, sigma * std::sqrt(2.0), 0.05 * sigma * std::sqrt(2.0));
    EXPECT_NEAR(BayesScaleFromMad(0.6744897501960817, 2), std::sqrt(2.0), 1e-4);
}

// Whether color's value of channel c at (x, y) is above each of its neighbours in the frame.
bool LonePeak(const Image &color, int c, int y, int x) {
    for (int v = std::max(y - 1, 0); v <= std::min(y + 1, color.height - 1); ++v)
        for (int u = std::max(x - 1, 0); u <= std::min(x + 1, color.width - 1); ++u)
            if ((u != x || v != y) && !(color.At(c, y, x) > color.At(c, v, u))) return false;
    return true;
}

// Fireflies on a quiet picture, the noise fixed small (as a smooth frame's estimate reads):
// they stay detail, and no output of bayes is above its input where the input is a lone peak,
// on the GPU and in the twin, with and without cycle spinning, whole or split among threads.
TEST_F(BayesProperties, LonePeaksAreNeverRaised) {
    const int w = 37, h = 29;
    Image color = NoisyPicture(w, h, SeedFromName("lone peaks"), 0.02);
    std::mt19937_64 rng(SeedFromName("lone peak places"));
    std::uniform_real_distribution<double> uniform(0, 1);
    std::vector<std::pair<int, int>> planted;
    for (int k = 0; k < 12; ++k) {
        const int x = int(uniform(rng) * w), y = int(uniform(rng) * h);
        for (int c = 0; c < 3; ++c) color.At(c, y, x) *= float(20 + 100 * uniform(rng));
        planted.push_back({x, y});
    }
    int plantedPeaks = 0;
    for (auto [x, y] : planted) plantedPeaks += LonePeak(color, 0, y, x);
    EXPECT_GE(plantedPeaks, 10);
    BayesParams options = PaperBayesParams();
    options.sn = 0.002;
    options.meanRadius = BayesParams().meanRadius;
    // Cycle spinning on the GPU alone (its twin is BayesKernelCycleSpinning's).
    for (int spins : {1, 2}) {
        SCOPED_TRACE(fmt::format("spins {}", spins));
        options.spins = spins;
        BayesResult gpu = BayesDenoise(Ctx(), color, options);
        Image cpu = spins == 1 ? ref::BayesDenoise(color, options).image : gpu.image;
        for (int c = 0; c < 3; ++c)
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x)
                    if (LonePeak(color, c, y, x)) {
                        const std::string at = fmt::format("channel {} at ({}, {})", c, x, y);
                        EXPECT_LE(gpu.image.At(c, y, x), color.At(c, y, x)) << at;
                        EXPECT_LE(cpu.At(c, y, x), color.At(c, y, x)) << at;
                    }
        bool counted = false;
        for (const std::string &line : gpu.plan)
            counted = counted || Contains(line, "lone peaks: ");
        EXPECT_TRUE(counted);
        if (spins > 1) continue;
        ForceParallelParts split(5);
        EXPECT_EQ(BayesDenoise(Ctx(), color, options).image.data, gpu.image.data);
    }
    options.spins = 1;
    // A 1x1 frame is its own lone peak.
    Image one(1, 1, 3, 2.5f);
    EXPECT_LE(BayesDenoise(Ctx(), one, options).image.data[0], 2.5f);
    EXPECT_LE(ref::BayesDenoise(one, options).image.data[0], 2.5f);
}

TEST_F(BayesProperties, SplitAddsTheDirectPartBack) {
    Image indirect = NoisyPicture(20, 12, SeedFromName("split"), 0.2);
    Image direct(20, 12, 3, 0.25f);
    direct.At(0, 0, 0) = std::numeric_limits<float>::quiet_NaN();
    BayesResult whole = BayesDenoise(Ctx(), indirect, PaperBayesParams());
    BayesResult split = BayesDenoiseSplit(Ctx(), direct, indirect, PaperBayesParams());
    for (size_t i = 1; i < whole.image.Size(); ++i)
        EXPECT_EQ(split.image.data[i], whole.image.data[i] + 0.25f);
    EXPECT_TRUE(AnyWarning(split, "1 NaN/Inf values in the direct layer"));
    EXPECT_TRUE(Contains(split.plan[0], "split"));
}

// The stage of one of bayes's results by name (empty when missing).
template <typename Stages>
Image StageOf(const Stages &stages, const std::string &name) {
    for (const auto &[stageName, image] : stages)
        if (stageName == name) return image;
    return Image();
}

// A value whose exp lands bitwise on its input was filtered all the same: the local means'
// restore scales it as its neighbours, on the GPU and in the twin alike. Told by equality it
// was kept on the side that landed (the twin, in double) and scaled on the other (still_life's
// accumulated frame). A 16x16 block of 1 in multiplicative noise: one Haar level keeps its
// details 0, so its exp gives 1 back exactly on both sides, and the noise around it pulls
// the restore's gain over it. Lone zeros (one channel of a lit pixel) are denoised, so
// filtered too; a black line is kept black.
TEST_F(BayesProperties, RestoreScalesValuesThatLandOnTheirInput) {
    const int w = 48, h = 48, x0 = 16, y0 = 16, side = 16;
    Image color = LogNormalNoise(w, h, SeedFromName("landed on the input"), 1.0);
    for (int c = 0; c < 3; ++c)
        for (int y = y0; y < y0 + side; ++y)
            for (int x = x0; x < x0 + side; ++x) color.At(c, y, x) = 1.f;
    const std::pair<int, int> zeros[] = {{5, 6}, {40, 9}, {8, 41}};
    for (auto [x, y] : zeros) color.At(1, y, x) = 0;
    for (int x = 0; x < w; ++x) color.At(2, 44, x) = 0;
    BayesParams options = PaperBayesParams();
    options.levels = 1;
    options.meanRadius = 2;
    RunSetup setup;
    setup.keepStages = true;
    BayesResult gpu = BayesDenoise(Ctx(), color, options, setup);
    ref::BayesRefRun run;
    run.keepStages = true;
    ref::BayesRefResult cpu = ref::BayesDenoise(color, options, run);
    const std::pair<const char *, std::pair<Image, Image>> sides[] = {
        {"gpu", {StageOf(gpu.stages, "exp"), gpu.image}},
        {"twin", {StageOf(cpu.stages, "exp"), cpu.image}}};
    for (const auto &[name, images] : sides) {
        SCOPED_TRACE(name);
        const Image &exp = images.first, &out = images.second;
        ASSERT_TRUE(exp.SameShape(color));
        int landed = 0, moved = 0;
        for (int c = 0; c < 3; ++c)
            for (int y = y0; y < y0 + side; ++y)
                for (int x = x0; x < x0 + side; ++x) {
                    landed += exp.At(c, y, x) == 1.f;
                    moved += out.At(c, y, x) != exp.At(c, y, x);
                }
        EXPECT_EQ(landed, 3 * side * side);  // the case holds: every exp on its input
        EXPECT_EQ(moved, 3 * side * side);
        for (auto [x, y] : zeros) EXPECT_NE(out.At(1, y, x), exp.At(1, y, x)) << x << ", " << y;
        for (int x = 0; x < w; ++x) EXPECT_EQ(out.At(2, 44, x), 0.f);
    }
    Image logGpu = gpu.image, logCpu = cpu.image;
    for (float &v : logGpu.data) v = std::log(v);
    for (float &v : logCpu.data) v = std::log(v);
    EXPECT_TRUE(ImagesMatch(logCpu, logGpu, {}, {0, 2e-3, 1e-4}));
}

// ---------------------------------------------------------------- --noise variance

class BayesVariance : public GpuTest {};

// A variance layer with zeros, negatives, NaN, +Inf, 1e30 and ordinary values.
Image AwkwardVariance(const Image &color, uint64_t seed) {
    Image variance(color.width, color.height, color.channels);
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> rel(0.f, 0.5f);
    for (size_t i = 0; i < variance.Size(); ++i) {
        float y = std::isfinite(color.data[i]) ? color.data[i] : 1.f;
        variance.data[i] = rel(rng) * y * y;
        switch (rng() % 20) {
            case 0:
                variance.data[i] = 0;
                break;
            case 1:
                variance.data[i] = -1;
                break;
            case 2:
                variance.data[i] = std::numeric_limits<float>::quiet_NaN();
                break;
            case 3:
                variance.data[i] = std::numeric_limits<float>::infinity();
                break;
            case 4:
                variance.data[i] = 1e30f;
                break;
            default:
                break;
        }
    }
    return variance;
}

// Host (GPU squared analysis) against the reference estimate. Both take the same floors
// and the same per-pixel log(1 + V / Y^2) (double, rounded to float); the rest is sums of
// non-negative terms, so no cancellation: the GPU's squared analysis has at most ~10
// float operations per output per axis pass, 2 passes per level, 3 levels, each within u
// relatively, and the reference rounds to float after every level too: 2 x 60 u = 7e-6 on
// a band's variance, half that on s. 1e-5 relative leaves room.
struct VarianceCase {
    int w, h;
    WaveletBasis basis;
    bool opponent;
};

std::vector<VarianceCase> VarianceCases() {
    std::vector<std::pair<int, int>> sizes = kSizes;
    sizes.push_back({64, 48});
    std::vector<VarianceCase> cases;
    for (auto [w, h] : sizes)
        for (WaveletBasis basis :
             {WaveletBasis::Haar, WaveletBasis::LeGall53, WaveletBasis::Cdf97})
            for (bool opponent : {false, true}) cases.push_back({w, h, basis, opponent});
    return cases;
}

class BayesVarianceEstimate : public GpuTestWithParam<VarianceCase> {};

TEST_P(BayesVarianceEstimate, MatchesReference) {
    const auto [w, h, basis, opponent] = GetParam();
    SCOPED_TRACE(fmt::format("{}x{} {} opponent {}", w, h, WaveletName(basis), opponent));
    uint64_t seed = SeedFromName(fmt::format("variance{}x{}", w, h));
    Image color = AwkwardInput(w, h, 3, seed);
    Image variance = AwkwardVariance(color, seed + 7);
    int levels = std::min(3, MaxWaveletLevels(w, h));
    std::vector<float> floors = BayesFloors(color, 1e-3f);
    std::vector<double> refFloors(floors.begin(), floors.end());
    std::vector<float> gpu =
        BayesVarianceNoise(Ctx(), color, variance, floors, basis, levels, 1.5f, opponent);
    std::vector<double> cpu =
        ref::BayesVarianceNoise(color, variance, refFloors, basis, levels, 1.5, opponent);
    ASSERT_EQ(gpu.size(), cpu.size());
    ASSERT_EQ(gpu.size(), size_t(3 * 3 * levels));
    for (size_t b = 0; b < cpu.size(); ++b) {
        EXPECT_TRUE(std::isfinite(gpu[b]) && gpu[b] >= 0) << "band " << b;
        EXPECT_NEAR(gpu[b], cpu[b], 1e-5 * cpu[b]) << "band " << b;
    }
}

INSTANTIATE_TEST_SUITE_P(Cases, BayesVarianceEstimate, testing::ValuesIn(VarianceCases()),
                         [](const testing::TestParamInfo<VarianceCase> &info) {
                             const VarianceCase &c = info.param;
                             return fmt::format("{}x{}_{}_{}", c.w, c.h, WaveletName(c.basis),
                                                c.opponent ? "opponent" : "rgb");
                         });

// Synthetic log-normal noise of known, per-pixel sigma in [0.2, 0.4] on a smooth picture,
// with the variance layer a renderer would write for it (V = Y^2 (e^sigma^2 - 1), the
// sample variance scaling with its own mean): every level's estimated noise variance
// (s^2 Gamma(3/p) / Gamma(1/p), p_n 1.5, the mean over the level's bands) must match the
// measured variance of the pure-noise coefficients, the DWT of log Y - log C. The
// measurement is a mean of n squared Gaussians with different variances: its relative
// standard deviation is sqrt(2 k / n), k = E[sigma^4] / E[sigma^2]^2 = 1.14 for sigma
// uniform on [0.2, 0.4]; the biorthogonal bases correlate neighbouring coefficients, which
// we allow for with a factor 2 in variance, and take 6 standard deviations: on 256x256,
// 6% at the finest level (n = 49152) to 23% at the third (n = 3072). A wrong filter gain,
// the variance-to-s conversion or the log-normal formula each miss by more.
// Exact (up to that sampling) for Haar at every level and every basis at the finest level.
// For the biorthogonal 5/3 and 9/7 at coarser levels the squared cascade ignores the
// correlation their overlapping low-pass puts between the next level's inputs: measured
// here 0.88 (5/3) and 0.95 (9/7) at level 1, 1.18 and 1.12 at level 2 (with the level's
// sampling tolerance on top); those levels get 0.25 plus the sampling tolerance.
struct LogNormalFrame {
    Image clean, noisy, variance, noise;
};

// The frame, made once for every basis.
const LogNormalFrame &KnownSigmaFrame() {
    static const LogNormalFrame frame = [] {
        const int w = 256, h = 256;
        LogNormalFrame f{Image(w, h, 1), Image(w, h, 1), Image(w, h, 1), Image(w, h, 1)};
        std::mt19937_64 rng(SeedFromName("variance lognormal"));
        std::normal_distribution<double> normal(0, 1);
        std::uniform_real_distribution<double> sigmaDist(0.2, 0.4);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                double c = 0.5 + 0.4 * std::sin(0.05 * x) * std::cos(0.03 * y);
                double sigma = sigmaDist(rng), z = sigma * normal(rng);
                float yv = float(c * std::exp(z));
                f.clean.At(0, y, x) = float(c);
                f.noisy.At(0, y, x) = yv;
                f.noise.At(0, y, x) = float(std::log(double(yv)) - std::log(c));
                f.variance.At(0, y, x) = float(double(yv) * yv * std::expm1(sigma * sigma));
            }
        return f;
    }();
    return frame;
}

std::string BasisName(const testing::TestParamInfo<WaveletBasis> &info) {
    return WaveletName(info.param);
}

class BayesVarianceKnownSigma : public GpuTestWithParam<WaveletBasis> {};

TEST_P(BayesVarianceKnownSigma, IsRecovered) {
    const WaveletBasis basis = GetParam();
    const int w = 256, h = 256, levels = 3;
    const double pn = 1.5;
    const auto &[clean, noisy, variance, noise] = KnownSigmaFrame();
    std::vector<float> floors = BayesFloors(noisy, 1e-3f);
    double toVariance = std::exp(std::lgamma(3 / pn) - std::lgamma(1 / pn));
    std::vector<float> s =
        BayesVarianceNoise(Ctx(), noisy, variance, floors, basis, levels, float(pn), false);
    Image coef = ref::WaveletAnalyze(noise, basis, levels);
    std::vector<ref::BayesBand> bands = ref::BayesBands(w, h, 1, levels);
    for (int level = 0; level < levels; ++level) {
        double estimated = 0, measured = 0;
        int64_t n = 0;
        for (size_t b = 0; b < bands.size(); ++b) {
            if (bands[b].level != level) continue;
            estimated += double(s[b]) * s[b] * toVariance / 3;
            for (int y = bands[b].y0; y < bands[b].y1; ++y)
                for (int x = bands[b].x0; x < bands[b].x1; ++x, ++n)
                    measured += double(coef.At(0, y, x)) * coef.At(0, y, x);
        }
        measured /= double(n);
        double tolerance = 6 * std::sqrt(2 * 1.14 * 2 / double(n));
        std::printf("[ variance ] %s level %d: estimated / measured %.4f (sampling tol %.3f)\n",
                    WaveletName(basis), level, estimated / measured, tolerance);
        if (basis != WaveletBasis::Haar && level > 0) tolerance += 0.25;
        EXPECT_NEAR(estimated / measured, 1.0, tolerance)
            << WaveletName(basis) << " level " << level << ": estimated " << estimated
            << ", measured " << measured;
    }
}

INSTANTIATE_TEST_SUITE_P(Cases, BayesVarianceKnownSigma,
                         testing::Values(WaveletBasis::Haar, WaveletBasis::LeGall53,
                                         WaveletBasis::Cdf97),
                         BasisName);

// Zero and huge variances: finite, non-negative noise s, finite output; zero variance is
// no noise (every band NO_NOISE, the input back), a huge one zeroes the detail
// (NO_SIGNAL). The whole method with the layer against the reference (the whole method's
// tolerance), with cycle spinning too, and bit-identical reruns.
class BayesVarianceFilled : public GpuTestWithParam<float> {};

TEST_P(BayesVarianceFilled, IsStable) {
    const float fill = GetParam();
    // The same frame for every case.
    Image color = NoisyPicture(33, 21, SeedFromName("variance extremes"), 0.3);
    SCOPED_TRACE(fmt::format("variance {}", fill));
    Image variance(color.width, color.height, 3, fill);
    BayesParams options = PaperBayesParams();
    options.noise = BayesNoise::Variance;
    BayesResult r = BayesDenoise(Ctx(), color, options, {}, &variance);
    EXPECT_TRUE(AllFinite(r.image));
    for (const BayesBandFit &f : r.fits) {
        EXPECT_TRUE(std::isfinite(f.params[0]) && f.params[0] >= 0);
        int expect = fill > 1e29f ? BAYES_FIT_NO_SIGNAL : BAYES_FIT_NO_NOISE;
        EXPECT_EQ(int(f.params[4]), expect);
    }
}

INSTANTIATE_TEST_SUITE_P(Cases, BayesVarianceFilled,
                         testing::Values(0.f, 1e30f, std::numeric_limits<float>::max(),
                                         std::numeric_limits<float>::infinity(),
                                         std::numeric_limits<float>::quiet_NaN()),
                         [](const testing::TestParamInfo<float> &info) {
                             return NameOf(info.param);
                         });

TEST_F(BayesVariance, AwkwardVarianceGivesFiniteOutput) {
    Image awkward = AwkwardInput(37, 23, 3, SeedFromName("variance awkward"));
    Image awkwardVariance = AwkwardVariance(awkward, 5);
    BayesParams options = PaperBayesParams();
    options.noise = BayesNoise::Variance;
    EXPECT_TRUE(AllFinite(BayesDenoise(Ctx(), awkward, options, {}, &awkwardVariance).image));
}

class BayesVarianceWholeMethod : public GpuTestWithParam<SpinCase> {};

TEST_P(BayesVarianceWholeMethod, MatchesReference) {
    const auto [w, h, spins] = GetParam();
    SCOPED_TRACE(fmt::format("{}x{} spins {}", w, h, spins));
    Image c = NoisyPicture(w, h, SeedFromName(fmt::format("var whole{}x{}", w, h)), 0.3);
    Image v = c;
    for (float &x : v.data) x = 0.05f * x * x;
    BayesParams o = PaperBayesParams();
    o.noise = BayesNoise::Variance;
    o.spins = spins;
    o.basis = WaveletBasis::Cdf97;
    BayesResult gpu = BayesDenoise(Ctx(), c, o, {}, &v);
    EXPECT_TRUE(BitIdentical(gpu.image, BayesDenoise(Ctx(), c, o, {}, &v).image));
    ref::BayesRefRun run;
    run.variance = &v;
    ref::BayesRefResult cpu = ref::BayesDenoise(c, o, run);
    for (size_t b = 0; b < cpu.fits.size() && b < gpu.fits.size(); ++b)
        EXPECT_EQ(int(gpu.fits[b].params[4]), cpu.fits[b].fit) << "band " << b;
    for (float &x : gpu.image.data) x = std::log(x);
    for (float &x : cpu.image.data) x = std::log(x);
    EXPECT_TRUE(ImagesMatch(cpu.image, gpu.image, {}, {0, 2e-3, 1e-4}));
}

INSTANTIATE_TEST_SUITE_P(Cases, BayesVarianceWholeMethod,
                         testing::Values(SpinCase{37, 23, 1}, SpinCase{1, 1, 1},
                                         SpinCase{19, 11, 2}),
                         SpinCaseName);

}  // namespace
}  // namespace mcd::test
