// Runs on frames of borrowed layers (Frame::SetLayer with views) and into the caller's
// buffer (RunOptions::output): the same bits as on owned planar layers for every method,
// alpha through, half in and out, cancellation that leaves the output untouched.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "harness/errors.h"
#include "harness/gpu_fixture.h"
#include "harness/inputs.h"
#include "host/api/device.h"
#include "host/common/half.h"
#include "mcdenoise/mcdenoise.h"
#include "tools/render/renderer.h"

namespace mcd::test {
namespace {

// A rendered frame with every layer, and an alpha layer of seeded values.
Frame OwnedFrame(int width, int height) {
    render::RenderOptions o;
    o.width = width, o.height = height, o.spp = 4;
    o.layers = render::kLayersAll;
    render::RenderResult r = render::Render(render::BuildScene("cornell"), o);
    Frame frame;
    frame.width = width, frame.height = height;
    for (auto &[name, image] : r.layers) frame.layers[name] = std::move(image);
    frame.layers["alpha"] = MakeVarianceInput(InputKind::Uniform, width, height, 1, 5);
    return frame;
}

// A renderer's buffers: each layer interleaved, float32 or half.
struct Buffers {
    std::vector<std::vector<float>> floats;
    std::vector<std::vector<uint16_t>> halves;

    LayerView Add(const Image &image, DataType type) {
        size_t n = image.data.size();
        auto at = [&](size_t i) {
            size_t pixel = i / size_t(image.channels), c = i % size_t(image.channels);
            return image.data[c * image.PixelCount() + pixel];
        };
        if (type == DataType::Float16) {
            halves.emplace_back(n);
            for (size_t i = 0; i < n; ++i) halves.back()[i] = FloatToHalf(at(i));
            return LayerView::Interleaved(halves.back().data(), image.width, image.height,
                                          image.channels, type);
        }
        floats.emplace_back(n);
        for (size_t i = 0; i < n; ++i) floats.back()[i] = at(i);
        return LayerView::Interleaved(floats.back().data(), image.width, image.height,
                                      image.channels);
    }
};

// The frame as borrowed views (`halfLayers` in half), and the owned frame with those
// layers rounded to half as the views hold them.
std::pair<Frame, Frame> Borrowed(const Frame &owned, Buffers &buffers,
                                 const std::vector<std::string> &halfLayers = {}) {
    Frame views, rounded = owned;
    buffers.floats.reserve(owned.layers.size());
    buffers.halves.reserve(owned.layers.size());
    for (const auto &[name, image] : owned.layers) {
        bool half = std::find(halfLayers.begin(), halfLayers.end(), name) != halfLayers.end();
        views.SetLayer(name, buffers.Add(image, half ? DataType::Float16 : DataType::Float32));
        if (half)
            for (float &v : rounded.layers[name].data) v = HalfToFloat(FloatToHalf(v));
    }
    return {std::move(views), std::move(rounded)};
}

class LibraryRun : public GpuTestWithParam<std::string> {};
class LibraryRunning : public GpuTest {};

// Every method on borrowed interleaved layers gives the owned run's bits, into an RGBA
// buffer whose fourth channel is the frame's alpha.
TEST_P(LibraryRun, BorrowedLayersGiveTheOwnedBitsAndAlphaPassesThrough) {
    Device device = api::BorrowDevice(Ctx());
    Method method(GetParam());
    Frame owned = OwnedFrame(29, 23);
    Buffers buffers;
    auto [views, rounded] = Borrowed(owned, buffers);
    Result expected = method.Run(device, owned);
    std::vector<float> out(size_t(29) * 23 * 4, -1.f);
    RunOptions run;
    run.output = OutputView::Interleaved(out.data(), 29, 23, 4);
    Result result = method.Run(device, views, run);
    EXPECT_TRUE(result.image.Empty());
    EXPECT_EQ(result.method, expected.method);
    EXPECT_EQ(result.candidates, expected.candidates);
    EXPECT_EQ(result.candidates.empty(), GetParam() != "auto");
    ASSERT_EQ(result.alpha.data, owned.layers["alpha"].data);
    const Image &image = expected.image;
    for (size_t i = 0; i < image.PixelCount(); ++i) {
        for (int c = 0; c < 3; ++c)
            ASSERT_EQ(std::memcmp(&out[i * 4 + c], &image.data[c * image.PixelCount() + i], 4),
                      0)
                << "pixel " << i << " channel " << c;
        ASSERT_EQ(out[i * 4 + 3], result.alpha.data[i]);
    }
}

// Pixels of alpha 0 (a transparent film's background) keep the frame's colour bits, read
// from borrowed layers as from owned ones, with --alpha-rim 0; the rest is the owned run's.
TEST_P(LibraryRun, TransparentPixelsKeepTheBorrowedColour) {
    Device device = api::BorrowDevice(Ctx());
    Method method(GetParam());
    method.Set("alpha-rim", 0.f);
    const int width = 29, height = 23, edge = 10;
    Frame owned = OwnedFrame(width, height);
    Image &alpha = owned.layers["alpha"];
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) alpha.At(0, y, x) = x < edge ? 0.f : 1.f;
    alpha.At(0, 11, 20) = 0.f;
    Buffers buffers;
    auto [views, rounded] = Borrowed(owned, buffers);
    Result expected = method.Run(device, owned);
    Result result = method.Run(device, views);
    const Image &color = owned.layers["color"];
    ASSERT_TRUE(result.image.SameShape(color));
    EXPECT_EQ(result.image.data, expected.image.data);
    size_t transparent = 0, changed = 0;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
            for (int c = 0; c < 3; ++c) {
                bool clear = alpha.At(0, y, x) == 0.f;
                transparent += clear;
                if (clear)
                    ASSERT_EQ(result.image.At(c, y, x), color.At(c, y, x))
                        << "pixel (" << x << ", " << y << "), channel " << c;
                else
                    changed += result.image.At(c, y, x) != color.At(c, y, x);
            }
    EXPECT_EQ(transparent, size_t(3) * (edge * height + 1));
    EXPECT_GT(changed, 0u);
    EXPECT_EQ(result.alpha.data, alpha.data);
    std::string plan = fmt::format("{}", fmt::join(result.plan, "\n"));
    EXPECT_NE(plan.find(fmt::format("alpha: {} fully transparent", edge * height + 1)),
              std::string::npos)
        << plan;
}

// By default a pixel of alpha 0 takes --alpha-rim's share of the colour and of the alpha
// of each of its 4 neighbours of alpha above 0, which keep the rest (the pixel filter's
// coverage past a silhouette); pixels of alpha 0 farther out keep the frame's colour.
// Expected values from the run with the share off, each giver's shares pushed to its
// receivers here (the pass gathers per receiver): a receiver sums at most 4 terms, so the
// two orders differ by at most 4 roundings of the largest magnitude summed.
TEST_P(LibraryRun, TransparentRimTakesAShareOfItsCoveredNeighbours) {
    Device device = api::BorrowDevice(Ctx());
    const int width = 29, height = 23, edge = 10;
    Frame frame = OwnedFrame(width, height);
    Image &alpha = frame.layers["alpha"];
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < edge; ++x) alpha.At(0, y, x) = 0.f;
    alpha.At(0, 11, 20) = 0.f;     // a hole with 4 covered neighbours
    alpha.At(0, 3, edge) = 0.25f;  // a partly covered giver
    Method kept(GetParam()), shared(GetParam());
    kept.Set("alpha-rim", 0.f);
    const float share = std::get<float>(shared.Get("alpha-rim"));
    ASSERT_GT(share, 0.f);
    EXPECT_THROW(Method(shared).Set("alpha-rim", 0.21f), Error);
    EXPECT_NO_THROW(Method(shared).Set("alpha-rim", 0.2f));
    EXPECT_THROW(shared.Set("alpha-rim", -0.01f), Error);
    Result before = kept.Run(device, frame), after = shared.Run(device, frame);

    Image color = before.image, coverage = alpha, bound(width, height, 1, 0.f);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            float a = alpha.At(0, y, x);
            if (a <= 0.f) continue;
            const int offsets[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
            for (const auto &o : offsets) {
                int rx = x + o[0], ry = y + o[1];
                if (rx < 0 || ry < 0 || rx >= width || ry >= height) continue;
                if (alpha.At(0, ry, rx) > 0.f) continue;
                for (int c = 0; c < 3; ++c) {
                    float v = before.image.At(c, y, x);
                    color.At(c, ry, rx) += share * v;
                    color.At(c, y, x) -= share * v;
                    for (float *b : {&bound.At(0, ry, rx), &bound.At(0, y, x)})
                        *b = std::max(*b, std::fabs(v));
                }
                coverage.At(0, ry, rx) += share * a;
                coverage.At(0, y, x) -= share * a;
            }
        }
    ASSERT_TRUE(after.image.SameShape(color));
    ASSERT_TRUE(after.alpha.SameShape(alpha));
    const float eps = std::numeric_limits<float>::epsilon();
    size_t moved = 0;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            for (int c = 0; c < 3; ++c) {
                float want = color.At(c, y, x);
                float tol = 4 * eps *
                            (std::fabs(want) + std::fabs(before.image.At(c, y, x)) +
                             4 * share * bound.At(0, y, x));
                ASSERT_NEAR(after.image.At(c, y, x), want, tol)
                    << "pixel (" << x << ", " << y << "), channel " << c;
                moved += after.image.At(c, y, x) != before.image.At(c, y, x);
            }
            ASSERT_NEAR(after.alpha.At(0, y, x), coverage.At(0, y, x), 4 * eps)
                << "alpha at (" << x << ", " << y << ")";
            if (x < edge - 1)
                for (int c = 0; c < 3; ++c)
                    ASSERT_EQ(after.image.At(c, y, x), frame.layers["color"].At(c, y, x));
        }
    EXPECT_GT(moved, size_t(3) * height);
    EXPECT_GT(after.alpha.At(0, 11, 20), 0.f);
    std::string plan = fmt::format("{}", fmt::join(after.plan, "\n"));
    EXPECT_NE(
        plan.find(fmt::format("alpha: {} pixel(s) of alpha 0 beside covered", height + 1)),
        std::string::npos)
        << plan;
}

// The rim's light moves only where its alpha reaches the caller: into an output with the
// alpha channel (as Result::alpha), not into one with the colour's channels alone, which
// gets the colour of a run with the share off and a plan line that says why.
TEST_F(LibraryRunning, AlphaRimRunsOnlyWhereItsAlphaIsDelivered) {
    Device device = api::BorrowDevice(Ctx());
    const int width = 17, height = 13;
    Frame frame = OwnedFrame(width, height);
    Image &alpha = frame.layers["alpha"];
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < 6; ++x) alpha.At(0, y, x) = 0.f;
    Method shared("bayes"), kept("bayes");
    kept.Set("alpha-rim", 0.f);
    Result before = kept.Run(device, frame), after = shared.Run(device, frame);
    ASSERT_GT(after.rimPixels, 0);
    EXPECT_EQ(before.rimPixels, 0);
    ASSERT_NE(after.image.data, before.image.data);

    std::vector<float> rgb(size_t(width) * height * 3), rgba(size_t(width) * height * 4);
    RunOptions run;
    run.output = OutputView::Planar(rgb.data(), width, height, 3);
    Result plain = shared.Run(device, frame, run);
    EXPECT_EQ(rgb, before.image.data);
    EXPECT_EQ(plain.rimPixels, 0);
    std::string plan = fmt::format("{}", fmt::join(plain.plan, "\n"));
    EXPECT_NE(plan.find(fmt::format("alpha: --alpha-rim left out: the output has no alpha "
                                    "channel, so the {} pixel(s)",
                                    height)),
              std::string::npos)
        << plan;

    run.output = OutputView::Planar(rgba.data(), width, height, 4);
    shared.Run(device, frame, run);
    std::vector<float> want = after.image.data;
    want.insert(want.end(), after.alpha.data.begin(), after.alpha.data.end());
    EXPECT_EQ(rgba, want);
}

// A pixel of NaN alpha (kept under non-finite zero) is no rim: it takes no share, so its
// colour and alpha are those of the run with the share off.
TEST_F(LibraryRunning, AlphaRimLeavesANanAlphaPixelAlone) {
    Device device = api::BorrowDevice(Ctx());
    Frame frame = OwnedFrame(15, 11);
    Image &alpha = frame.layers["alpha"];
    alpha.At(0, 5, 7) = std::numeric_limits<float>::quiet_NaN();
    alpha.At(0, 2, 3) = 0.f;
    Method shared("bayes"), kept("bayes");
    shared.Set("non-finite", std::string("zero"));
    kept.Set("non-finite", std::string("zero"));
    kept.Set("alpha-rim", 0.f);
    Result before = kept.Run(device, frame), after = shared.Run(device, frame);
    EXPECT_EQ(after.rimPixels, 1);
    EXPECT_TRUE(std::isnan(after.alpha.At(0, 5, 7)));
    for (int c = 0; c < 3; ++c)
        EXPECT_EQ(after.image.At(c, 5, 7), before.image.At(c, 5, 7)) << c;
}

INSTANTIATE_TEST_SUITE_P(Methods, LibraryRun,
                         ::testing::Values("awr", "bayes", "pivot", "rhf", "auto"));

// Half layers read as their float values; a half output holds the float result rounded.
TEST_F(LibraryRunning, HalfInAndOut) {
    Device device = api::BorrowDevice(Ctx());
    Method method("bayes");
    Frame owned = OwnedFrame(21, 17);
    Buffers buffers;
    auto [views, rounded] = Borrowed(owned, buffers, {"color", "variance"});
    Result expected = method.Run(device, rounded);
    std::vector<uint16_t> out(size_t(21) * 17 * 3);
    RunOptions run;
    run.output = OutputView::Planar(out.data(), 21, 17, 3, DataType::Float16);
    method.Run(device, views, run);
    for (size_t i = 0; i < out.size(); ++i)
        ASSERT_EQ(out[i], FloatToHalf(expected.image.data[i])) << i;
}

TEST_F(LibraryRunning, RefusesAnOutputOfAnotherShape) {
    Device device = api::BorrowDevice(Ctx());
    Frame owned = OwnedFrame(12, 10);
    std::vector<float> out(size_t(12) * 10 * 5);
    RunOptions run;
    run.output = OutputView::Interleaved(out.data(), 12, 10, 5);
    try {
        Method("rhf").Run(device, owned, run);
        FAIL() << "ran";
    } catch (const Error &e) {
        EXPECT_EQ(e.Kind(), ErrorKind::InvalidArgument) << e.what();
    }
    run.output = OutputView::Interleaved(out.data(), 11, 10, 3);
    EXPECT_TRUE(ThrowsError(ErrorKind::InvalidArgument,
                            [&] { Method("rhf").Run(device, owned, run); }));
}

// NaN in a borrowed layer is refused by the non-finite policy, as in an owned one.
TEST_F(LibraryRunning, RefusesNonFiniteBorrowedInput) {
    Device device = api::BorrowDevice(Ctx());
    Frame whole = OwnedFrame(12, 10), owned;
    owned.SetLayer("color", whole.layers["color"]);
    owned.layers["color"].At(1, 3, 4) = NAN;
    Buffers buffers;
    auto [views, rounded] = Borrowed(owned, buffers);
    try {
        Method("bayes").Run(device, views);
        FAIL() << "ran";
    } catch (const Error &e) {
        EXPECT_EQ(e.Kind(), ErrorKind::NonFiniteInput) << e.what();
        EXPECT_NE(std::string(e.what()).find("pixel (4, 3), channel 1"), std::string::npos)
            << e.what();
    }
}

// A cancel at the k-th poll stops the run with kind Cancelled, polls no more and leaves
// the output as it was; the device runs normally afterwards.
void ExpectCancelled(Device &device, const std::string &name, int cancelAt) {
    Frame owned = OwnedFrame(24, 20);
    std::vector<float> out(size_t(24) * 20 * 3, 42.f);
    RunOptions run;
    run.output = OutputView::Interleaved(out.data(), 24, 20, 3);
    int polls = 0;
    run.cancel = [&] { return ++polls >= cancelAt; };
    try {
        Method(name).Run(device, owned, run);
        FAIL() << name << " ran";
    } catch (const Error &e) {
        EXPECT_EQ(e.Kind(), ErrorKind::Cancelled) << name << ": " << e.what();
    }
    EXPECT_EQ(polls, cancelAt) << name;
    for (float v : out) ASSERT_EQ(v, 42.f) << name;
    Method(name).Run(device, owned, {});
}

TEST_F(LibraryRunning, CancelsBetweenSubmissions) {
    Device device = api::BorrowDevice(Ctx());
    for (const char *name : {"awr", "bayes", "pivot", "rhf"}) ExpectCancelled(device, name, 1);
    ExpectCancelled(device, "bayes", 2);
    // auto leaves out a candidate that fails; a cancelled run is still cancelled.
    ExpectCancelled(device, "auto", 3);
}

}  // namespace
}  // namespace mcd::test
