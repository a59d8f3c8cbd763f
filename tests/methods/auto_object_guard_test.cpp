// Method auto's object guard (issue 29): before the combination, a candidate whose luminance
// sum over an object departs from the input's by more than z standard errors of the input's
// sum weighs less on the object; an object within its noise leaves the estimates, and so the
// weights, bit for bit.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "harness/frames.h"
#include "harness/gpu_fixture.h"
#include "harness/inputs.h"
#include "host/api/device.h"
#include "host/methods/auto.h"
#include "host/methods/auto_halves.h"
#include "host/methods/auto_object_floor.h"
#include "mcdenoise/mcdenoise.h"
#include "methods/auto_object_frames.h"

namespace mcd::test {
namespace {

// An odd-sized RGB frame of two objects (id 1 the left columns, id 2 the rest) whose input
// is `level` plus seeded normal noise of deviation `sigma` per value, and whose variance
// layer is sigma^2; one pixel of object 1 is NaN where `nan`.
struct GuardFrame {
    Image input, ids, variance;
};

GuardFrame MakeGuardFrame(int w, int h, int leftColumns, float level, float sigma, bool nan,
                          const char *seedName) {
    GuardFrame f{Image(w, h, 3), Image(w, h, 1), Image(w, h, 3, sigma * sigma)};
    std::mt19937_64 rng(SeedFromName(seedName));
    std::normal_distribution<float> normal(0, sigma);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) f.ids.At(0, y, x) = x < leftColumns ? 1.f : 2.f;
    for (float &v : f.input.data) v = level + normal(rng);
    if (nan) f.input.At(1, 0, 0) = NAN;
    return f;
}

// The input scaled by `scale` on the pixels of object `id`, as it is elsewhere.
Image ScaledOn(const GuardFrame &f, float id, float scale) {
    Image out = f.input;
    const size_t pixels = out.PixelCount();
    for (int c = 0; c < out.channels; ++c)
        for (size_t i = 0; i < pixels; ++i)
            if (f.ids.data[i] == id) out.data[c * pixels + i] *= scale;
    return out;
}

// Object `id`'s input luminance sum and its standard error, in double over the pixels whose
// values are finite: the channels of one deviation each, fully correlated, give a luminance
// deviation of sigma (Rec. 709's weights sum to 1).
std::pair<double, double> InputSum(const GuardFrame &f, float id, float sigma) {
    double sum = 0;
    size_t count = 0;
    for (size_t i = 0; i < f.input.PixelCount(); ++i)
        if (f.ids.data[i] == id && std::isfinite(PixelLuminance(f.input, i)))
            sum += PixelLuminance(f.input, i), ++count;
    const double deviation = (0.2126 + 0.7152 + 0.0722) * sigma;
    return {sum, deviation * std::sqrt(double(count))};
}

// The factor the guard puts on an estimate at t standard errors: exp((t^2 - z^2) / 2), at most
// exp(kAutoGuardMostLog).
double GuardFactor(double t, double z) {
    return std::exp(std::min(0.5 * (t * t - z * z), kAutoGuardMostLog));
}

TEST(AutoObjectGuard, WeighsDownOnlyTheCandidatesThatDepartFarFromTheInputsSum) {
    const int w = 15, h = 11, left = 6;
    const float sigma = 0.05f, z = 3;
    const GuardFrame f = MakeGuardFrame(w, h, left, 0.5f, sigma, true, "object guard factors");
    const auto [sum1, error1] = InputSum(f, 1, sigma);
    const auto [sum2, error2] = InputSum(f, 2, sigma);
    // c0 keeps the input; c1 darkens object 1 to 0.7 of it (far past its noise) and object 2
    // by half of z standard errors (within it); c2 brightens object 1 to 1.3 of it.
    const Image keep = f.input;
    Image dark = ScaledOn(f, 1, 0.7f);
    const float within = float(1 - 0.5 * z * error2 / sum2);
    const GuardFrame darkFrame{dark, f.ids, f.variance};
    dark = ScaledOn(darkFrame, 2, within);
    const Image bright = ScaledOn(f, 1, 1.3f);
    const Image lumVariance = AutoLuminanceVariance(f.input, &f.variance, nullptr, nullptr);
    const std::vector<const Image *> outputs = {&keep, &dark, &bright};
    const size_t pixels = f.input.PixelCount();
    for (bool both : {false, true}) {
        SCOPED_TRACE(both ? "both" : "dark");
        AutoObjectGuard guard;
        guard.z = z, guard.both = both, guard.minPixels = 1;
        const AutoObjectGuardResult result = AutoObjectGuardFactors(
            f.ids, f.input, lumVariance, nullptr, nullptr, outputs, guard);
        ASSERT_EQ(result.hits.size(), both ? 2u : 1u);
        EXPECT_EQ(result.hits[0].id, 1.f);
        EXPECT_EQ(result.hits[0].candidate, 1);
        EXPECT_EQ(result.hits[0].pixels, size_t(left * h - 1));  // the NaN pixel out
        // t and the factor from the sums in double; the float sums' rounding over the
        // object's pixels is far below the tolerance, and the factor's slope is t.
        const double t1 = (0.7 * sum1 - sum1) / error1;
        EXPECT_NEAR(result.hits[0].t, t1, 1e-4 * std::abs(t1));
        const double factor1 = GuardFactor(t1, z);
        EXPECT_NEAR(result.hits[0].factor, factor1, 1e-3 * factor1);
        if (both) {
            EXPECT_EQ(result.hits[1].candidate, 2);
            EXPECT_NEAR(result.hits[1].t, -t1, 1e-4 * std::abs(t1));
        }
        // Every other candidate, object and the guarded object's NaN pixel keep the factor 1
        // exactly.
        for (int k = 0; k < 3; ++k)
            for (size_t i = 0; i < pixels; ++i) {
                const bool guarded =
                    f.ids.data[i] == 1.f && i != 0 && (k == 1 || (both && k == 2));
                const float factor = result.factors.data[k * pixels + i];
                const float expected =
                    guarded ? float(result.hits[k == 1 ? 0 : 1].factor) : 1.f;
                ASSERT_EQ(factor, expected) << "candidate " << k << " pixel " << i;
            }
    }
    // Off, and objects of fewer pixels than the least: no factor but 1.
    AutoObjectGuard off;
    AutoObjectGuardResult none =
        AutoObjectGuardFactors(f.ids, f.input, lumVariance, nullptr, nullptr, outputs, off);
    EXPECT_TRUE(none.hits.empty());
    AutoObjectGuard large;
    large.z = z, large.minPixels = pixels;
    none =
        AutoObjectGuardFactors(f.ids, f.input, lumVariance, nullptr, nullptr, outputs, large);
    EXPECT_TRUE(none.hits.empty());
    EXPECT_EQ(none.small, 2u);
    for (float factor : none.factors.data) ASSERT_EQ(factor, 1.f);
}

// With a tiny variance the error is the floor, kAutoGuardRelative of the input's sum: a
// departure of 5 of them is guarded at t = -5, one of 2 (hundreds of the variance's standard
// errors) is not.
TEST(AutoObjectGuard, TheErrorIsAtLeastAHundredthOfTheInputsSum) {
    const int w = 13, h = 9, left = 5;
    const float sigma = 1e-4f, z = 3;
    const GuardFrame f = MakeGuardFrame(w, h, left, 0.5f, sigma, false, "object guard floor");
    const auto [sum1, error1] = InputSum(f, 1, sigma);
    ASSERT_LT(100 * error1, kAutoGuardRelative * sum1);
    const Image keep = f.input, fivePercent = ScaledOn(f, 1, 0.95f),
                twoPercent = ScaledOn(f, 1, 0.98f);
    const Image lumVariance = AutoLuminanceVariance(f.input, &f.variance, nullptr, nullptr);
    AutoObjectGuard guard;
    guard.z = z, guard.minPixels = 1;
    const AutoObjectGuardResult result =
        AutoObjectGuardFactors(f.ids, f.input, lumVariance, nullptr, nullptr,
                               {&keep, &fivePercent, &twoPercent}, guard);
    ASSERT_EQ(result.hits.size(), 1u);
    EXPECT_EQ(result.hits[0].id, 1.f);
    EXPECT_EQ(result.hits[0].candidate, 1);
    // t = -0.05 sum / (0.01 sum), up to the float scale's and sums' rounding.
    const double t = -0.05 / kAutoGuardRelative;
    EXPECT_NEAR(result.hits[0].t, t, 1e-4 * std::abs(t));
}

// Checks a guarded combination against the unguarded one on object 1, where candidate 1
// (`faded`) fades the input: unguarded it takes the object; guarded it weighs under 1e-3 of
// candidate 0 (the input) there, and the object keeps the input's sum within the tolerance
// from the weights. Off the object the output and the weights keep their bits.
void ExpectGuarded(const AutoResult &plain, const AutoResult &kept, const GuardFrame &f,
                   const Image &faded, float sigma, float z) {
    const auto [inputSum, error] = InputSum(f, 1, sigma);
    // Unguarded, the faded candidate takes the object: its sum is short by many errors.
    EXPECT_LT(ObjectSum(plain.image, f.ids, 1).first, inputSum - z * error);
    // Guarded, its estimate there is at least floorError times the factor (e^13.5 at t = -6),
    // so its share of the weight is at most (c0's estimate / that)^2. The object's output
    // departs from c0's (the input) by each pixel's share of c1's departure, summed: the
    // tolerance, from the weights returned, plus the float mean's rounding.
    const size_t pixels = f.input.PixelCount();
    double bound = 0;
    for (size_t i = 0; i < pixels; ++i)
        if (f.ids.data[i] == 1.f) {
            const double w0 = kept.weights.data[i], w1 = kept.weights.data[pixels + i];
            ASSERT_LT(w1, 1e-3 * w0) << "pixel " << i;
            bound += w1 / (w0 + w1) *
                     std::abs(PixelLuminance(faded, i) - PixelLuminance(f.input, i));
        }
    EXPECT_NEAR(ObjectSum(kept.image, f.ids, 1).first, inputSum,
                bound + 16 * 4 * 0x1p-24 * inputSum);
    for (int c = 0; c < 3; ++c)
        for (size_t i = 0; i < pixels; ++i)
            if (f.ids.data[i] != 1.f) {
                ASSERT_EQ(kept.image.data[c * pixels + i], plain.image.data[c * pixels + i]);
            }
    for (size_t i = 0; i < kept.weights.data.size(); ++i)
        if (f.ids.data[i % pixels] != 1.f) {
            ASSERT_EQ(kept.weights.data[i], plain.weights.data[i]);
        }
}

// A combination on SURE estimates, then beside the half-buffers (the default path): c0 is
// the input (the identity), c1 the true level, but at 0.7 of it on a small object. c1's
// window estimates barely see the object, so it takes the weight there and fades it; the
// guard's factors move the weight to c0, which keeps the object's light. Off the object the
// weights and the output are the unguarded ones bit for bit (their factors are 1).
class AutoObjectGuardCombine : public GpuTest {};

TEST_F(AutoObjectGuardCombine, ACandidateThatFadesAnObjectLosesItsWeightThere) {
    const int w = 23, h = 19, left = 4;
    const float level = 0.5f, sigma = 0.1f, z = 3;
    GuardFrame f = MakeGuardFrame(w, h, left, level, sigma, false, "object guard combine");
    // Object 1 is a block of 4x4 pixels in the frame's middle; the rest is object 2.
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            f.ids.At(0, y, x) = x >= 9 && x < 9 + left && y >= 7 && y < 7 + left ? 1.f : 2.f;
    std::mt19937_64 rng(SeedFromName("object guard probe"));
    Image probe(w, h, 3);
    for (float &b : probe.data) b = rng() % 2 ? 1.f : -1.f;
    AutoCandidate input, faded;
    input.label = "input", input.method = "input", input.output = f.input;
    input.probe = f.input;
    for (size_t i = 0; i < probe.data.size(); ++i) input.probe.data[i] += sigma * probe.data[i];
    faded.label = "faded", faded.method = "faded";
    faded.output = Image(w, h, 3, level);
    const GuardFrame truth{faded.output, f.ids, f.variance};
    faded.output = ScaledOn(truth, 1, 0.7f);
    faded.probe = faded.output;
    const std::vector<AutoCandidate> candidates = {input, faded};
    const Image lumVariance = AutoLuminanceVariance(f.input, &f.variance, nullptr, nullptr);
    AutoObjectGuard guard;
    guard.z = z, guard.minPixels = 1;
    AutoObjectGuardResult guarded = AutoObjectGuardFactors(
        f.ids, f.input, lumVariance, nullptr, nullptr, {&input.output, &faded.output}, guard);
    ASSERT_EQ(guarded.hits.size(), 1u);
    ASSERT_EQ(guarded.hits[0].candidate, 1);

    AutoEstimateInputs in;
    in.variance = f.variance, in.probe = probe;
    AutoOptions options;
    options.combination = AutoCombination::Weights;
    options.radius = 8;
    options.keepWeights = true;
    const AutoResult plain = AutoCombine(Ctx(), f.input, candidates, in, options);
    in.objectFactors = guarded.factors;
    const AutoResult kept = AutoCombine(Ctx(), f.input, candidates, in, options);

    ExpectGuarded(plain, kept, f, faded.output, sigma, z);
    // In strips the factors are cut with the rows: the whole frame's bits.
    options.stripRows = 5;
    EXPECT_EQ(AutoCombine(Ctx(), f.input, candidates, in, options).image.data, kept.image.data);

    // Beside the half-buffers the factors go on after the halves' adjustment (the default
    // path): c0's probe is F(half0) = half0, a second draw of the input's noise, scored
    // against half1, a third; the probe is zero.
    SCOPED_TRACE("half-buffers");
    const GuardFrame half0 = MakeGuardFrame(w, h, left, level, sigma, false, "object guard h0");
    const GuardFrame half1 = MakeGuardFrame(w, h, left, level, sigma, false, "object guard h1");
    std::vector<AutoCandidate> halvesCandidates = candidates;
    halvesCandidates[0].probe = half0.input;
    AutoEstimateInputs halves;
    halves.variance = f.variance, halves.probe = Image(w, h, 3), halves.half1 = half1.input;
    // A drop no candidate reaches: the halves' adjustment runs and leaves the estimates.
    options.stripRows = 0;
    options.halvesDrop = 100;
    const AutoResult halvesPlain =
        AutoCombine(Ctx(), f.input, halvesCandidates, halves, options);
    halves.objectFactors = guarded.factors;
    const AutoResult halvesKept =
        AutoCombine(Ctx(), f.input, halvesCandidates, halves, options);
    ExpectGuarded(halvesPlain, halvesKept, f, faded.output, sigma, z);
    options.stripRows = 5;
    EXPECT_EQ(AutoCombine(Ctx(), f.input, halvesCandidates, halves, options).image.data,
              halvesKept.image.data);
}

// The front end: a frame without ids is the guard-off output bit for bit and --explain says
// why; with ids, a guard no departure reaches leaves it bit for bit too.
class AutoObjectGuardMethod : public GpuTest {};

TEST_F(AutoObjectGuardMethod, LeavesAFrameWithoutIdsAndObjectsWithinTheirNoise) {
    Device device = api::BorrowDevice(Ctx());
    Method on("auto"), off("auto"), far("auto");
    on.Set("auto-object-guard", 3.0);
    on.Set("auto-object-guard-frames", std::string("all"));
    off.Set("auto-object-guard", 0.0);
    far.Set("auto-object-guard", 100.0);
    far.Set("auto-object-guard-frames", std::string("all"));
    far.Set("auto-object-guard-sign", std::string("both"));
    const Frame plain = RenderCornell(false);
    Result withoutIds = on.Run(device, plain);
    EXPECT_EQ(withoutIds.image.data, off.Run(device, plain).image.data);
    EXPECT_TRUE(PlanHas(withoutIds, "auto: object guard: left out (the frame has no objectId"))
        << fmt::format("{}", fmt::join(withoutIds.plan, "\n"));
    const Frame frame = RenderCornell(true);
    Result within = far.Run(device, frame);
    EXPECT_EQ(within.image.data, off.Run(device, frame).image.data);
    EXPECT_TRUE(PlanHas(within, "auto: object guard: no candidate's object sum departs"))
        << fmt::format("{}", fmt::join(within.plan, "\n"));
    // The sign and the frames need the guard on (off: refused).
    Method lone("auto");
    lone.Set("auto-object-guard", 0.0);
    lone.Set("auto-object-guard-sign", std::string("both"));
    EXPECT_THROW(lone.Run(device, frame), Error);
    Method loneFrames("auto");
    loneFrames.Set("auto-object-guard", 0.0);
    loneFrames.Set("auto-object-guard-frames", std::string("all"));
    EXPECT_THROW(loneFrames.Run(device, frame), Error);
    // The plan says why the guard (on by default) is left out: no estimates under the mean
    // combination; estimates not the halves' on a frame that has them.
    Method mean("auto");
    mean.Set("auto-combine", std::string("mean"));
    const Result meanRun = mean.Run(device, frame);
    EXPECT_TRUE(PlanHas(meanRun, "object guard: left out (no estimates: the mean combination)"))
        << fmt::format("{}", fmt::join(meanRun.plan, "\n"));
    render::RenderOptions options;
    options.width = 32, options.height = 24, options.spp = 8;
    options.layers = render::kLayersAll | render::kLayersHalves;
    const Frame halves = RenderedFrame("cornell", options);
    Method sure("auto");
    sure.Set("auto-noise", std::string("variance"));
    const Result sureRun = sure.Run(device, halves);
    EXPECT_TRUE(PlanHas(sureRun,
                        "object guard: left out (the estimates are not the "
                        "half-buffers'; --auto-object-guard-frames all)"))
        << fmt::format("{}", fmt::join(sureRun.plan, "\n"));
}

}  // namespace
}  // namespace mcd::test
