// Method auto's object lift (issue 29): the input is the unbiased estimate of each object's
// light; an object every candidate darkened below the input's sum by more than k standard
// errors of that sum is scaled up to the bound, and an object within its noise is left bit
// for bit.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "harness/gpu_fixture.h"
#include "host/api/device.h"
#include "host/methods/auto_object_floor.h"
#include "mcdenoise/mcdenoise.h"
#include "methods/auto_object_frames.h"
#include "tools/render/renderer.h"

namespace mcd::test {
namespace {

constexpr double kUnitRoundoff = 0x1p-24;

// Two objects of an odd-sized frame, RGBA: the input is noisy around a tinted level on
// both (seeded), its variance layer that of the pixel mean. The output holds object 1 at
// `dark` of the input (every candidate darkened it) and object 2 at the input less half a
// standard error of its sum (within its noise).
struct LiftFrame {
    Image input, ids, variance, output;
};

LiftFrame MakeLiftFrame(int w, int h, double dark, double k) {
    LiftFrame f{Image(w, h, 4), Image(w, h, 1), Image(w, h, 3), Image(w, h, 4)};
    const float tint[3] = {1.f, 0.8f, 0.6f};
    std::mt19937 rng(29);
    std::uniform_real_distribution<float> noise(0.5f, 1.5f);
    const size_t pixels = f.input.PixelCount();
    for (size_t i = 0; i < pixels; ++i) {
        f.ids.data[i] = (i % size_t(w)) < size_t(w / 2) ? 1.f : 2.f;
        float level = noise(rng);
        for (int c = 0; c < 3; ++c) {
            f.input.data[c * pixels + i] = level * tint[c];
            f.variance.data[c * pixels + i] = 1e-4f * tint[c] * tint[c];
        }
        f.input.data[3 * pixels + i] = 1.f;  // alpha
    }
    // The standard error of object 2's sum: the channels fully correlated, the deviation's
    // luminance is the tinted one of 0.01.
    const double deviation = 0.01 * (0.2126 * 1 + 0.7152 * 0.8 + 0.0722 * 0.6);
    const double count2 = double(pixels) - double(h) * (w / 2);
    const double error2 = deviation * std::sqrt(count2);
    const double input2 = ObjectSum(f.input, f.ids, 2).first;
    const double within = (input2 - 0.5 * k * error2) / input2;
    for (size_t i = 0; i < pixels; ++i) {
        double scale = f.ids.data[i] == 1.f ? dark : within;
        for (int c = 0; c < 3; ++c)
            f.output.data[c * pixels + i] = float(scale * f.input.data[c * pixels + i]);
        f.output.data[3 * pixels + i] = 0.5f;
    }
    return f;
}

TEST(AutoObjectLift, LiftsAnObjectDarkenedFarBelowItsInputToTheBoundAndLeavesTheOther) {
    const int w = 17, h = 13;
    const double k = 3;
    LiftFrame f = MakeLiftFrame(w, h, 0.7, k);
    Image lumVariance = AutoLuminanceVariance(f.input, &f.variance, nullptr, nullptr);
    Image lifted = f.output;
    std::vector<AutoObjectLift> moved =
        AutoObjectLiftToInput(f.ids, f.input, lumVariance, nullptr, nullptr, k, &lifted, 1);
    ASSERT_EQ(moved.size(), 1u);
    EXPECT_EQ(moved[0].id, 1.f);
    const size_t count1 = size_t(h) * (w / 2);
    EXPECT_EQ(moved[0].pixels, count1);
    EXPECT_EQ(moved[0].scale, moved[0].bound / moved[0].before);  // short of the largest

    // The bound from the sums in double: the input's less k times the root of the summed
    // variance of the luminance (each pixel's deviation the tinted 0.01).
    const auto [input1, magnitude1] = ObjectSum(f.input, f.ids, 1);
    const double deviation = 0.01 * (0.2126 * 1 + 0.7152 * 0.8 + 0.0722 * 0.6);
    const double bound = input1 - k * deviation * std::sqrt(double(count1));
    // Each pixel is scaled in double and rounded to float once (u relative), and the
    // variance layer's float deviations (a few u) reach the bound through k * error.
    const auto [after, magnitude] = ObjectSum(lifted, f.ids, 1);
    EXPECT_NEAR(after, bound,
                4 * kUnitRoundoff * magnitude + 16 * kUnitRoundoff * k * std::abs(bound));
    EXPECT_NEAR(moved[0].bound, bound, 16 * kUnitRoundoff * std::abs(bound));
    EXPECT_GT(after, ObjectSum(f.output, f.ids, 1).first);

    // One scale for the whole object: each pixel keeps its share; alpha and object 2 keep
    // their bits.
    const size_t pixels = lifted.PixelCount();
    const double scale = bound / ObjectSum(f.output, f.ids, 1).first;
    for (size_t i = 0; i < pixels; ++i) {
        for (int c = 0; c < 3; ++c) {
            const float before = f.output.data[c * pixels + i];
            if (f.ids.data[i] == 1.f)
                EXPECT_NEAR(lifted.data[c * pixels + i], scale * before,
                            4 * kUnitRoundoff * scale * before);
            else
                ASSERT_EQ(lifted.data[c * pixels + i], before);
        }
        ASSERT_EQ(lifted.data[3 * pixels + i], 0.5f);
    }

    // Two runs are bit-identical.
    Image again = f.output;
    AutoObjectLiftToInput(f.ids, f.input, lumVariance, nullptr, nullptr, k, &again, 1);
    EXPECT_EQ(again.data, lifted.data);
}

TEST(AutoObjectLift, LeavesObjectsWithinTheirNoiseSmallObjectsAndNonFinitePixels) {
    const int w = 17, h = 13;
    const double k = 3;
    // Object 1 darkened by 0.1% only: well within its noise; object 2 within half its bound.
    LiftFrame f = MakeLiftFrame(w, h, 0.999, k);
    Image lumVariance = AutoLuminanceVariance(f.input, &f.variance, nullptr, nullptr);
    Image image = f.output;
    EXPECT_TRUE(
        AutoObjectLiftToInput(f.ids, f.input, lumVariance, nullptr, nullptr, k, &image, 1)
            .empty());
    EXPECT_EQ(image.data, f.output.data);

    // Darkened far, but fewer pixels than the objects need: left, and counted.
    LiftFrame far = MakeLiftFrame(w, h, 0.5, k);
    Image few = far.output;
    size_t small = 0;
    EXPECT_TRUE(AutoObjectLiftToInput(far.ids, far.input, lumVariance, nullptr, nullptr, k,
                                      &few, 200, &small)
                    .empty());
    EXPECT_EQ(small, 2u);
    EXPECT_EQ(few.data, far.output.data);

    // A NaN and an Inf pixel inside object 1: left as they are and out of the sums.
    Image odd = far.output;
    const size_t pixels = odd.PixelCount();
    odd.data[0] = NAN;
    odd.data[pixels + 1] = INFINITY;
    std::vector<AutoObjectLift> moved =
        AutoObjectLiftToInput(far.ids, far.input, lumVariance, nullptr, nullptr, k, &odd, 1);
    ASSERT_EQ(moved.size(), 1u);
    EXPECT_EQ(moved[0].pixels, size_t(h) * (w / 2) - 2);
    EXPECT_TRUE(std::isnan(odd.data[0]));
    EXPECT_EQ(odd.data[pixels + 1], INFINITY);
    EXPECT_EQ(odd.data[1], far.output.data[1]);  // the Inf pixel's other channels too
    EXPECT_GT(odd.data[2], far.output.data[2]);  // a finite pixel of object 1 moved

    // A NaN in the variance layer: that pixel is left out of the sums and kept.
    Image variance = far.variance;
    variance.data[pixels + 3] = NAN;
    Image nanVariance = AutoLuminanceVariance(far.input, &variance, nullptr, nullptr);
    Image withNan = far.output;
    moved = AutoObjectLiftToInput(far.ids, far.input, nanVariance, nullptr, nullptr, k,
                                  &withNan, 1);
    ASSERT_EQ(moved.size(), 1u);
    EXPECT_EQ(moved[0].pixels, size_t(h) * (w / 2) - 1);
    EXPECT_EQ(withNan.data[3], far.output.data[3]);
    EXPECT_GT(withNan.data[2], far.output.data[2]);
}

TEST(AutoObjectLift, ANearlyBlackObjectRisesAtMostByTheLargestScale) {
    const int w = 17, h = 13;
    const double k = 3;
    LiftFrame f = MakeLiftFrame(w, h, 0.001, k);
    Image lumVariance = AutoLuminanceVariance(f.input, &f.variance, nullptr, nullptr);
    Image image = f.output;
    std::vector<AutoObjectLift> moved =
        AutoObjectLiftToInput(f.ids, f.input, lumVariance, nullptr, nullptr, k, &image, 1);
    ASSERT_EQ(moved.size(), 1u);
    // Each pixel scaled in double and rounded to float once.
    const auto [before, magnitude] = ObjectSum(f.output, f.ids, 1);
    EXPECT_NEAR(ObjectSum(image, f.ids, 1).first, kAutoObjectLiftMaxScale * before,
                4 * kUnitRoundoff * kAutoObjectLiftMaxScale * magnitude);
    EXPECT_LT(kAutoObjectLiftMaxScale * before, moved[0].bound);
    EXPECT_EQ(moved[0].scale, kAutoObjectLiftMaxScale);
}

TEST(AutoObjectLift, TheHalvesDisagreementOverTheObjectWidensTheBound) {
    const int w = 17, h = 13;
    const double k = 3;
    LiftFrame f = MakeLiftFrame(w, h, 0.7, k);
    Image lumVariance = AutoLuminanceVariance(f.input, &f.variance, nullptr, nullptr);
    // Halves that differ by the same share on every pixel: noise the pixels share, which
    // the variance layer does not hold. Object 1's halves differ by 0.8 of its input's sum,
    // a standard error of 0.4 of it: at 0.7 of the input it is within 3 of them.
    Image half0 = f.input, half1 = f.input;
    const size_t pixels = f.input.PixelCount();
    for (int c = 0; c < 3; ++c)
        for (size_t i = 0; i < pixels; ++i) {
            half0.data[c * pixels + i] *= 1.4f;
            half1.data[c * pixels + i] *= 0.6f;
        }
    Image image = f.output;
    EXPECT_TRUE(AutoObjectLiftToInput(f.ids, f.input, lumVariance, &half0, &half1, k, &image, 1)
                    .empty());
    EXPECT_EQ(image.data, f.output.data);
    // At a quarter of one such standard error (0.1 of the input) it is lifted to 0.9 of the
    // input, and says why.
    std::vector<AutoObjectLift> moved =
        AutoObjectLiftToInput(f.ids, f.input, lumVariance, &half0, &half1, 0.25, &image, 1);
    ASSERT_EQ(moved.size(), 1u);
    EXPECT_TRUE(moved[0].halves);
    const auto [after, magnitude] = ObjectSum(image, f.ids, 1);
    const double input1 = ObjectSum(f.input, f.ids, 1).first;
    EXPECT_NEAR(after, 0.9 * input1, 16 * kUnitRoundoff * magnitude);
}

TEST(AutoObjectLift, LuminanceVarianceFromTheVarianceLayerOrTheHalves) {
    Image color(3, 1, 3), variance(3, 1, 3), half0(3, 1, 3), half1(3, 1, 3);
    const float v[3] = {4.f, 1.f, 0.25f};
    for (int x = 0; x < 3; ++x)
        for (int c = 0; c < 3; ++c) {
            variance.At(c, 0, x) = v[c] * float(x + 1);
            half0.At(c, 0, x) = 1.f + float(x);
            half1.At(c, 0, x) = 1.f - float(x);
        }
    // The channels fully correlated: (sum of weight times deviation)^2.
    Image fromVariance = AutoLuminanceVariance(color, &variance, &half0, &half1);
    ASSERT_EQ(fromVariance.channels, 1);
    for (int x = 0; x < 3; ++x) {
        double d = std::sqrt(double(x + 1)) * (0.2126 * 2 + 0.7152 * 1 + 0.0722 * 0.5);
        EXPECT_NEAR(fromVariance.At(0, 0, x), d * d, 4 * kUnitRoundoff * d * d);
    }
    // Without one: a quarter of the halves' luminance difference squared.
    Image fromHalves = AutoLuminanceVariance(color, nullptr, &half0, &half1);
    for (int x = 0; x < 3; ++x) EXPECT_FLOAT_EQ(fromHalves.At(0, 0, x), float(x * x));
    EXPECT_TRUE(AutoLuminanceVariance(color, nullptr, &half0, nullptr).Empty());
    Image wrong(2, 1, 3);
    EXPECT_THROW(AutoLuminanceVariance(color, &wrong, nullptr, nullptr), Error);
}

// The front end: a frame without ids is the lift-off output bit for bit and --explain says
// why; with ids whose object 1 the output darkens, it is lifted and every pixel outside the
// objects lifted is the lift-off output's.
class AutoObjectLiftMethod : public GpuTest {};

TEST_F(AutoObjectLiftMethod, LeavesAFrameWithoutIdsAndOnlyScalesTheObjectsItNames) {
    Device device = api::BorrowDevice(Ctx());
    Method on("auto"), off("auto");
    off.Set("auto-object-lift", 0.0);
    const Frame plain = RenderCornell(false);
    Result withoutIds = on.Run(device, plain);
    EXPECT_EQ(withoutIds.image.data, off.Run(device, plain).image.data);
    EXPECT_TRUE(PlanHas(withoutIds, "auto: object lift: left out (the frame has no objectId"))
        << fmt::format("{}", fmt::join(withoutIds.plan, "\n"));

    // Ids that make object 1 the pixels where the lift-off output is below the input: its
    // sum falls short of the input's by about its pixels' mean deviation each, within a few
    // standard errors of this small frame's heavy-tailed variance layer, so a low bound of
    // 0.5 reaches it; the rest is object 2.
    Frame frame = RenderCornell(true);
    const Image reference = off.Run(device, frame).image;
    const Image &input = frame.layers.at("color");
    Image &ids = frame.layers.at("objectId");
    const size_t pixels = ids.PixelCount();
    for (size_t i = 0; i < pixels; ++i)
        ids.data[i] = PixelLuminance(reference, i) < PixelLuminance(input, i) ? 1.f : 2.f;
    Method lift("auto");
    lift.Set("auto-object-lift", 0.5);
    Result lifted = lift.Run(device, frame), unlifted = off.Run(device, frame);
    EXPECT_TRUE(PlanHas(lifted, "auto: object lift: "))
        << fmt::format("{}", fmt::join(lifted.plan, "\n"));
    std::vector<float> liftedIds;
    for (const std::string &line : lifted.plan)
        if (line.starts_with("auto: object lift: object "))
            liftedIds.push_back(std::stof(line.substr(26)));
    EXPECT_NE(std::find(liftedIds.begin(), liftedIds.end(), 1.f), liftedIds.end())
        << fmt::format("{}", fmt::join(lifted.plan, "\n"));
    for (int c = 0; c < lifted.image.channels; ++c)
        for (size_t i = 0; i < pixels; ++i)
            if (std::find(liftedIds.begin(), liftedIds.end(), ids.data[i]) == liftedIds.end()) {
                ASSERT_EQ(lifted.image.data[c * pixels + i],
                          unlifted.image.data[c * pixels + i]);
            }
    for (float id : liftedIds)
        EXPECT_GT(ObjectSum(lifted.image, ids, id).first,
                  ObjectSum(unlifted.image, ids, id).first);
}

}  // namespace
}  // namespace mcd::test
