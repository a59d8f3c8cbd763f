// Method auto's object floor (issue 29): the relative combination darkens an object whose
// candidates disagree pixel by pixel below every candidate; the floor brings the object's
// luminance sum to the darkest candidate's and leaves every other object bit for bit.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "cpu_reference/auto_combine.h"
#include "harness/gpu_fixture.h"
#include "harness/inputs.h"
#include "host/api/device.h"
#include "host/common/parallel.h"
#include "host/methods/auto_object_floor.h"
#include "mcdenoise/mcdenoise.h"
#include "methods/auto_object_frames.h"
#include "tools/render/renderer.h"

namespace mcd::test {
namespace {

constexpr double kUnitRoundoff = 0x1p-24;

// Two objects side by side. On object 1 the candidates disagree pixel by pixel (a
// checkerboard of 1 and 4, swapped between them, b a little brighter); on object 2 they
// differ by a constant (2 and 2.2).
struct TwoObjects {
    Image color, ids, errors, variance;
    std::vector<Image> candidates;
};

TwoObjects MakeTwoObjects(int w, int h) {
    TwoObjects f{Image(w, h, 3),
                 Image(w, h, 1),
                 Image(w, h, 2, 0.01f),
                 Image(w, h, 3, 1e-6f),
                 {Image(w, h, 3), Image(w, h, 3)}};
    const float tint[3] = {1.f, 0.8f, 0.6f};
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            bool left = x < w / 2, even = (x + y) % 2 == 0;
            f.ids.At(0, y, x) = left ? 1.f : 2.f;
            float a = left ? (even ? 1.f : 4.f) : 2.f;
            float b = left ? 1.02f * (even ? 4.f : 1.f) : 2.2f;
            for (int c = 0; c < 3; ++c) {
                f.candidates[0].At(c, y, x) = a * tint[c];
                f.candidates[1].At(c, y, x) = b * tint[c];
                f.color.At(c, y, x) = 0.5f * (a + b) * tint[c];
            }
        }
    return f;
}

TEST(AutoObjectFloor, BringsADarkenedObjectToItsDarkestCandidateAndLeavesTheOther) {
    const int w = 9, h = 7;
    TwoObjects f = MakeTwoObjects(w, h);
    ref::AutoCombined relative =
        ref::AutoCombineRelative(f.color, f.candidates, f.errors, f.variance, 2, 1e-5, 30, 4);
    std::vector<const Image *> outputs = {&f.candidates[0], &f.candidates[1]};
    const Image weighted = AutoWeightedMean(outputs, relative.weights, relative.color);
    // The relative value darkens object 1 below both candidates, not object 2.
    double darkest = ObjectSum(f.candidates[0], f.ids, 1).first;
    ASSERT_LT(darkest, ObjectSum(f.candidates[1], f.ids, 1).first);
    ASSERT_LT(ObjectSum(relative.color, f.ids, 1).first, 0.7 * darkest);
    ASSERT_GE(ObjectSum(relative.color, f.ids, 2).first,
              ObjectSum(f.candidates[0], f.ids, 2).first);

    Image floored = relative.color;
    std::vector<AutoObjectMove> moved =
        AutoObjectFloor(f.ids, outputs, weighted, 1, &floored, 1);
    ASSERT_EQ(moved.size(), 1u);
    EXPECT_EQ(moved[0].id, 1.f);
    EXPECT_EQ(moved[0].darkest, 0);
    EXPECT_GT(moved[0].alpha, 0);
    EXPECT_LE(moved[0].alpha, 1);
    // Each value's move rounds once to a float (half a unit of it), its luminance sum adds
    // a few double roundings: within 4 u of the sum of the magnitudes.
    auto [sum, magnitude] = ObjectSum(floored, f.ids, 1);
    EXPECT_NEAR(sum, darkest, 4 * kUnitRoundoff * magnitude);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = w / 2; x < w; ++x)
                ASSERT_EQ(floored.At(c, y, x), relative.color.At(c, y, x)) << c << y << x;
    // Without the floor's move the weighted mean's object 1 is brighter than the darkest.
    EXPECT_GT(ObjectSum(weighted, f.ids, 1).first, darkest);
    // Objects of fewer pixels than the minimum (28 and 35 here) are left, and counted.
    Image few = relative.color;
    size_t small = 0;
    EXPECT_TRUE(AutoObjectFloor(f.ids, outputs, weighted, 1, &few, 29, &small).empty());
    EXPECT_EQ(small, 1u);
    EXPECT_EQ(few.data, relative.color.data);
    EXPECT_TRUE(AutoObjectFloor(f.ids, outputs, weighted, 1, &few).empty());  // 64 px
    // A lower level holds the object to that share of the darkest candidate's sum.
    Image lower = relative.color;
    ASSERT_EQ(AutoObjectFloor(f.ids, outputs, weighted, 0.9, &lower, 1).size(), 1u);
    auto [lowerSum, lowerMagnitude] = ObjectSum(lower, f.ids, 1);
    EXPECT_NEAR(lowerSum, 0.9 * darkest, 4 * kUnitRoundoff * lowerMagnitude);
}

TEST(AutoObjectFloor, WeightedMeanKeepsTheImageWhereNoCandidateWeighs) {
    Image image(2, 1, 1), weights(2, 1, 2), a(2, 1, 1, 3.f), b(2, 1, 1, 5.f);
    image.data = {7.f, 7.f};
    weights.data = {0.25f, 0.f, 0.75f, 0.f};  // pixel 0: a 1/4, b 3/4; pixel 1: none
    Image mean = AutoWeightedMean({&a, &b}, weights, image);
    EXPECT_FLOAT_EQ(mean.data[0], 4.5f);
    EXPECT_EQ(mean.data[1], 7.f);
}

// The pixels split among threads give the serial loop's bits, at odd sizes, 1x1 and with
// NaN/Inf outputs and weights (a pair that does not count).
TEST(AutoObjectFloor, WeightedMeanSplitGivesTheSerialBits) {
    std::mt19937_64 rng(SeedFromName("auto weighted mean split"));
    std::uniform_real_distribution<float> unit(0, 1);
    auto special = [&](float v) {
        const float u = unit(rng);
        return u < 0.02f   ? std::numeric_limits<float>::quiet_NaN()
               : u < 0.04f ? std::numeric_limits<float>::infinity()
               : u < 0.10f ? 0.f
                           : v;
    };
    for (auto [w, h] : {std::pair{1, 1}, std::pair{3, 1}, std::pair{131, 67}}) {
        Image image(w, h, 3), weights(w, h, 3);
        std::vector<Image> outputs(3, Image(w, h, 3));
        for (float &v : image.data) v = unit(rng);
        for (float &v : weights.data) v = special(unit(rng));
        for (Image &o : outputs)
            for (float &v : o.data) v = special(4 * unit(rng));
        const std::vector<const Image *> pointers{&outputs[0], &outputs[1], &outputs[2]};
        Image serial;
        {
            ForceParallelParts force(1);
            serial = AutoWeightedMean(pointers, weights, image);
        }
        for (int parts : {2, 3, 7}) {
            ForceParallelParts force(parts);
            const Image split = AutoWeightedMean(pointers, weights, image);
            ASSERT_TRUE(split.SameShape(serial));
            EXPECT_EQ(0, std::memcmp(split.data.data(), serial.data.data(),
                                     serial.data.size() * sizeof(float)))
                << w << "x" << h << ", " << parts << " parts";
        }
    }
}

// Two objects combined, their candidates' weighted mean, and a stand-in restore of the
// combination (a gain and a lift): the floor's inputs after the local-mean restore.
struct AfterRestore {
    TwoObjects f;
    ref::AutoCombined relative;
    Image mean, restored;
    std::vector<const Image *> Outputs() const { return {&f.candidates[0], &f.candidates[1]}; }
};

AfterRestore MakeAfterRestore(int w, int h) {
    AfterRestore a;
    a.f = MakeTwoObjects(w, h);
    a.relative = ref::AutoCombineRelative(a.f.color, a.f.candidates, a.f.errors, a.f.variance,
                                          2, 1e-5, 30, 4);
    a.mean = AutoWeightedMean({&a.f.candidates[0], &a.f.candidates[1]}, a.relative.weights,
                              a.relative.color);
    a.restored = a.relative.color;
    for (float &v : a.restored.data) v = 0.9f * v + 0.25f;
    return a;
}

// The floor of a's restored image toward `target`, each object held to all of its darkest
// candidate's sum: object 1 alone moves, part of the way, and reaches that sum. Returns the
// fraction it moved (NaN where it did not move alone).
double FloorObjectOne(const AfterRestore &a, const Image &target, Image *floored) {
    *floored = a.restored;
    std::vector<AutoObjectMove> moved =
        AutoObjectFloor(a.f.ids, a.Outputs(), target, 1, floored, 1);
    EXPECT_EQ(moved.size(), 1u);
    if (moved.size() != 1) return NAN;
    EXPECT_EQ(moved[0].id, 1.f);
    EXPECT_GT(moved[0].alpha, 0);
    EXPECT_LT(moved[0].alpha, 1);
    const double darkest = ObjectSum(a.f.candidates[0], a.f.ids, 1).first;
    auto [sum, magnitude] = ObjectSum(*floored, a.f.ids, 1);
    EXPECT_NEAR(sum, darkest, 4 * kUnitRoundoff * magnitude);
    return moved[0].alpha;
}

// The default path, after the local-mean restore: a stand-in restore (a gain and a lift)
// changes the combination (object 2 stays above its darkest), the floor moves from the restored
// value by alpha times the weighted mean's excess over the unrestored combination, and reaches
// the darkest's sum.
TEST(AutoObjectFloor, AfterTheRestoreKeepsTheRestoresChangeAndReachesTheDarkest) {
    const AfterRestore a = MakeAfterRestore(9, 7);
    const TwoObjects &f = a.f;
    const Image &mean = a.mean, &restored = a.restored, &combined = a.relative.color;
    const int w = combined.width, h = combined.height;
    const Image target = AutoFloorTarget(mean, combined, restored);
    Image floored;
    const double alpha = FloorObjectOne(a, target, &floored);
    ASSERT_TRUE(std::isfinite(alpha));
    // Each moved value: the target's two float roundings (scaled by alpha) and the move's.
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                double r = restored.At(c, y, x), m = mean.At(c, y, x);
                double u = combined.At(c, y, x);
                double expected = x < w / 2 ? r + alpha * (m - u) : r;
                EXPECT_NEAR(floored.At(c, y, x), expected,
                            4 * kUnitRoundoff * (std::abs(r) + std::abs(m) + std::abs(u)))
                    << c << " " << y << " " << x;
            }
    EXPECT_THROW(AutoFloorTarget(mean, Image(w, h, 1), restored), Error);
}

// With the input: the target is the weighted mean's value (the restore's change kept) taken
// the share of the way to the input, the floor still reaches the darkest's sum, and a share of
// 0 is the target without the input, bit for bit.
TEST(AutoObjectFloor, AfterTheRestoreTakesItsShareOfTheWayToTheInput) {
    const AfterRestore a = MakeAfterRestore(9, 7);
    const TwoObjects &f = a.f;
    const Image &mean = a.mean, &restored = a.restored, &combined = a.relative.color;
    const int w = combined.width, h = combined.height;
    // The input holds object 1's light in its even pixels, where the samples found it.
    Image input = f.color;
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) input.At(c, y, x) *= (x + y) % 2 == 0 ? 1.6f : 0.4f;
    const float share = 0.5f;
    const Image target = AutoFloorTarget(mean, combined, restored, &input, share);
    const Image without = AutoFloorTarget(mean, combined, restored);
    const Image none = AutoFloorTarget(mean, combined, restored, &input, 0);
    EXPECT_EQ(none.data, without.data);
    // Without the input the target is the float sum as before the share existed.
    for (size_t i = 0; i < without.data.size(); ++i)
        ASSERT_EQ(without.data[i], restored.data[i] + (mean.data[i] - combined.data[i])) << i;
    bool differs = false;
    for (size_t i = 0; i < target.data.size(); ++i) {
        double m = double(restored.data[i]) + (mean.data[i] - combined.data[i]);
        double expected = m + share * (input.data[i] - m);
        EXPECT_NEAR(target.data[i], expected,
                    4 * kUnitRoundoff * (std::abs(m) + std::abs(input.data[i])))
            << i;
        differs = differs || std::abs(target.data[i] - without.data[i]) > 1e-3f;
    }
    EXPECT_TRUE(differs);
    Image floored;
    const double alpha = FloorObjectOne(a, target, &floored);
    ASSERT_TRUE(std::isfinite(alpha));
    for (size_t i = 0; i < floored.data.size(); ++i) {
        const bool left = int(i % (size_t(w) * h)) % w < w / 2;
        double r = restored.data[i], t = target.data[i];
        double expected = left ? r + alpha * (t - r) : r;
        EXPECT_NEAR(floored.data[i], expected, 4 * kUnitRoundoff * (std::abs(r) + std::abs(t)))
            << i;
    }
    EXPECT_THROW(AutoFloorTarget(mean, combined, restored, &f.ids, share), Error);
}

TEST(AutoObjectFloor, LeavesAnObjectWhoseDarkestSumIsNotPositive) {
    Image ids(3, 2, 1, 1.f), a(3, 2, 3, -1.f), b(3, 2, 3, -0.5f);
    Image image(3, 2, 3, -3.f), weighted(3, 2, 3, -0.75f);
    const Image before = image;
    EXPECT_TRUE(AutoObjectFloor(ids, {&a, &b}, weighted, 0.98, &image, 1).empty());
    EXPECT_EQ(image.data, before.data);
}

TEST(AutoObjectFloor, WeightedMeanNormalisesOverFinitePairsAndChecksShapes) {
    Image image(1, 1, 2), weights(1, 1, 2), a(1, 1, 2), b(1, 1, 2, 5.f);
    image.data = {7.f, 7.f};
    a.data = {NAN, 3.f};
    weights.data = {0.25f, 0.75f};  // a 1/4, b 3/4; a's channel 0 is not finite
    Image mean = AutoWeightedMean({&a, &b}, weights, image);
    EXPECT_FLOAT_EQ(mean.data[0], 5.f);
    EXPECT_FLOAT_EQ(mean.data[1], 4.5f);
    EXPECT_THROW(AutoWeightedMean({&a, &b}, Image(), image), Error);
    EXPECT_THROW(AutoWeightedMean({&a, &b}, Image(1, 1, 1), image), Error);
    EXPECT_THROW(AutoWeightedMean({&a, &b}, weights, Image(2, 1, 2)), Error);
}

// The front end: without an objectId layer the output is the floor-off one bit for bit,
// and --explain says why; with ids, every pixel outside the objects moved is the floor-off
// one's, and each object moved is no longer below its darkest candidate's share.
class AutoObjectFloorMethod : public GpuTest {};

TEST_F(AutoObjectFloorMethod, LeavesAFrameWithoutIdsAndOnlyMovesTheObjectsItNames) {
    Device device = api::BorrowDevice(Ctx());
    Method on("auto"), off("auto");
    off.Set("auto-object-floor", std::string("off"));
    const Frame plain = RenderCornell(false);
    Result withoutIds = on.Run(device, plain);
    EXPECT_EQ(withoutIds.image.data, off.Run(device, plain).image.data);
    EXPECT_TRUE(PlanHas(withoutIds, "auto: object floor: left out (the frame has no objectId"))
        << fmt::format("{}", fmt::join(withoutIds.plan, "\n"));

    const Frame frame = RenderCornell(true);
    Result floored = on.Run(device, frame), unfloored = off.Run(device, frame);
    EXPECT_TRUE(PlanHas(floored, "auto: object floor (after the local-mean restore)"))
        << fmt::format("{}", fmt::join(floored.plan, "\n"));
    std::vector<float> movedIds;
    for (const std::string &line : floored.plan)
        if (line.starts_with("auto: object floor (after the local-mean restore): object "))
            movedIds.push_back(std::stof(line.substr(line.find("): object ") + 10)));
    const Image &ids = frame.layers.at("objectId");
    const size_t pixels = ids.PixelCount();
    for (int c = 0; c < floored.image.channels; ++c)
        for (size_t i = 0; i < pixels; ++i)
            if (std::find(movedIds.begin(), movedIds.end(), ids.data[i]) == movedIds.end()) {
                ASSERT_EQ(floored.image.data[c * pixels + i],
                          unfloored.image.data[c * pixels + i]);
            }
    for (float id : movedIds)
        EXPECT_GT(ObjectSum(floored.image, ids, id).first,
                  ObjectSum(unfloored.image, ids, id).first);
}

}  // namespace
}  // namespace mcd::test
