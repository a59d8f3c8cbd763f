// The C API (include/mcdenoise/mcdenoise_c.h, io_c.h) against the C++ one: a run through
// handles gives the C++ run's bits, errors come back as codes with the C++ message, the
// progress function cancels, files round-trip.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "harness/gpu_fixture.h"
#include "harness/inputs.h"
#include "host/api/device.h"
#include "mcdenoise/io_c.h"
#include "mcdenoise/mcdenoise.h"
#include "mcdenoise/mcdenoise_c.h"

namespace mcd::test {
namespace {

std::pair<MCDError, std::string> TakeError() {
    const char *message = nullptr;
    MCDError code = mcdGetError(&message);
    return {code, message ? message : "(null)"};
}

// One C device for the suite (its kernels are built once).
MCDDevice SharedDevice() {
    static MCDDevice device = mcdNewDevice(nullptr);
    return device;
}

// Seeded color and variance, interleaved, as a renderer holds them.
struct Layers {
    int w = 19, h = 13;
    Image color = MakeVarianceInput(InputKind::LogNormalFireflies, 19, 13, 3, 3);
    Image variance = MakeVarianceInput(InputKind::Uniform, 19, 13, 3, 4);
    std::vector<float> colorBuffer = Interleave(color), varianceBuffer = Interleave(variance);

    static std::vector<float> Interleave(const Image &image) {
        std::vector<float> out(image.data.size());
        for (int c = 0; c < image.channels; ++c)
            for (size_t i = 0; i < image.PixelCount(); ++i)
                out[i * image.channels + c] = image.data[c * image.PixelCount() + i];
        return out;
    }
    MCDFrame NewFrame() {
        MCDFrame frame = mcdNewFrame();
        MCDView c = mcdInterleaved(colorBuffer.data(), MCD_FORMAT_FLOAT, w, h, 3);
        MCDView v = mcdInterleaved(varianceBuffer.data(), MCD_FORMAT_FLOAT, w, h, 3);
        EXPECT_TRUE(mcdSetFrameLayer(frame, "color", &c));
        EXPECT_TRUE(mcdSetFrameLayer(frame, "variance", &v));
        return frame;
    }
};

class CApi : public GpuTest {};

TEST_F(CApi, RunGivesTheCppRunsBits) {
    Layers layers;
    Frame owned;
    owned.SetLayer("color", layers.color);
    owned.SetLayer("variance", layers.variance);
    Device device = api::BorrowDevice(Ctx());
    Method cpp("bayes");
    cpp.Set("bayes-transform", std::string("dwt"));
    Result expected = cpp.Run(device, owned);

    MCDFrame frame = layers.NewFrame();
    MCDMethod method = mcdNewMethod("bayes");
    ASSERT_TRUE(mcdSetMethodString(method, "bayes-transform", "dwt"));
    std::vector<float> out(size_t(layers.w) * layers.h * 3);
    MCDView view = mcdPlanar(out.data(), MCD_FORMAT_FLOAT, layers.w, layers.h, 3);
    MCDResult result = mcdRunMethod(method, SharedDevice(), frame, &view);
    ASSERT_NE(result, nullptr) << TakeError().second;
    EXPECT_STREQ(mcdGetResultMethod(result), "bayes");
    EXPECT_EQ(mcdGetResultPlanCount(result), int(expected.plan.size()));
    EXPECT_EQ(std::memcmp(out.data(), expected.image.data.data(), out.size() * 4), 0);
    // Without an output view the image stays in the result; with alpha: 1 where none.
    MCDResult kept = mcdRunMethod(method, SharedDevice(), frame, nullptr);
    std::vector<float> rgba(size_t(layers.w) * layers.h * 4);
    MCDView rgbaView = mcdInterleaved(rgba.data(), MCD_FORMAT_FLOAT, layers.w, layers.h, 4);
    ASSERT_TRUE(mcdCopyResultImage(kept, &rgbaView)) << TakeError().second;
    for (size_t i = 0; i < expected.image.PixelCount(); ++i) {
        EXPECT_EQ(rgba[i * 4 + 1], expected.image.data[expected.image.PixelCount() + i]);
        EXPECT_EQ(rgba[i * 4 + 3], 1.f);
    }
    EXPECT_EQ(TakeError().first, MCD_ERROR_NONE);
    mcdReleaseResult(kept);
    mcdReleaseResult(result);
    mcdReleaseMethod(method);
    mcdReleaseFrame(frame);
}

// A result whose alpha-rim moved light into pixels of alpha 0 copies into a view with the
// alpha channel, which gets the moved alpha; a view of the colour's channels alone is
// refused (that colour over the caller's background would be a halo).
TEST_F(CApi, CopyResultImageKeepsTheRimsColourWithItsAlpha) {
    Layers layers;
    std::vector<float> alpha(size_t(layers.w) * layers.h, 0.7f);
    for (int y = 0; y < layers.h; ++y)
        for (int x = 0; x < 5; ++x) alpha[size_t(y) * layers.w + x] = 0.f;
    MCDFrame frame = layers.NewFrame();
    MCDView a = mcdInterleaved(alpha.data(), MCD_FORMAT_FLOAT, layers.w, layers.h, 1);
    ASSERT_TRUE(mcdSetFrameLayer(frame, "alpha", &a));
    MCDMethod method = mcdNewMethod("bayes");
    MCDResult kept = mcdRunMethod(method, SharedDevice(), frame, nullptr);
    ASSERT_NE(kept, nullptr) << TakeError().second;
    std::vector<float> rgb(size_t(layers.w) * layers.h * 3);
    MCDView rgbView = mcdInterleaved(rgb.data(), MCD_FORMAT_FLOAT, layers.w, layers.h, 3);
    EXPECT_FALSE(mcdCopyResultImage(kept, &rgbView));
    auto [code, message] = TakeError();
    EXPECT_EQ(code, MCD_ERROR_INVALID_ARGUMENT);
    EXPECT_NE(message.find("alpha-rim moved light and alpha into 13 pixel(s)"),
              std::string::npos)
        << message;
    std::vector<float> rgba(size_t(layers.w) * layers.h * 4);
    MCDView rgbaView = mcdInterleaved(rgba.data(), MCD_FORMAT_FLOAT, layers.w, layers.h, 4);
    ASSERT_TRUE(mcdCopyResultImage(kept, &rgbaView)) << TakeError().second;
    EXPECT_GT(rgba[size_t(4) * 4 + 3], 0.f);  // the rim at (4, 0) took coverage
    EXPECT_EQ(rgba[size_t(3) * 4 + 3], 0.f);  // (3, 0) is farther out
    mcdReleaseResult(kept);
    mcdReleaseMethod(method);
    mcdReleaseFrame(frame);
}

TEST_F(CApi, ErrorsAreCodesWithTheLibrarysMessage) {
    EXPECT_EQ(mcdNewMethod("nope"), nullptr);
    auto [code, message] = TakeError();
    EXPECT_EQ(code, MCD_ERROR_INVALID_ARGUMENT);
    EXPECT_NE(message.find("unknown method 'nope'"), std::string::npos) << message;
    EXPECT_EQ(TakeError().first, MCD_ERROR_NONE);  // taken

    MCDMethod method = mcdNewMethod("rhf");
    EXPECT_FALSE(mcdSetMethodFloat(method, "kappa", -5));
    EXPECT_EQ(TakeError().first, MCD_ERROR_INVALID_ARGUMENT);
    EXPECT_FALSE(mcdSetMethodBool(method, "no-such-parameter", true));
    EXPECT_EQ(TakeError().first, MCD_ERROR_INVALID_ARGUMENT);
    EXPECT_TRUE(mcdSetMethodFloat(method, "kappa", 0.5));
    EXPECT_STREQ(mcdGetMethodParamText(method, "kappa"), "0.5");

    // A frame without color.
    Layers layers;
    MCDFrame frame = mcdNewFrame();
    MCDView variance =
        mcdInterleaved(layers.varianceBuffer.data(), MCD_FORMAT_FLOAT, layers.w, layers.h, 3);
    ASSERT_TRUE(mcdSetFrameLayer(frame, "variance", &variance));
    MCDMethod bayes = mcdNewMethod("bayes");
    EXPECT_EQ(mcdRunMethod(bayes, SharedDevice(), frame, nullptr), nullptr);
    std::tie(code, message) = TakeError();
    EXPECT_EQ(code, MCD_ERROR_MISSING_LAYER) << message;
    EXPECT_NE(message.find("no layer 'color'"), std::string::npos) << message;
    mcdReleaseMethod(bayes);
    EXPECT_FALSE(mcdSetFrameLayer(frame, "color", nullptr));
    EXPECT_EQ(TakeError().first, MCD_ERROR_INVALID_ARGUMENT);
    std::vector<float> small(4);
    MCDView wrong = mcdInterleaved(small.data(), MCD_FORMAT_FLOAT, 2, 2, 1);
    EXPECT_FALSE(mcdSetFrameLayer(frame, "depth", &wrong));
    EXPECT_EQ(TakeError().first, MCD_ERROR_INVALID_ARGUMENT);
    // An output view without its memory: refused, not taken for no view.
    MCDFrame good = layers.NewFrame();
    MCDMethod run = mcdNewMethod("bayes");
    MCDView noData = mcdInterleaved(nullptr, MCD_FORMAT_FLOAT, layers.w, layers.h, 3);
    EXPECT_EQ(mcdRunMethod(run, SharedDevice(), good, &noData), nullptr);
    std::tie(code, message) = TakeError();
    EXPECT_EQ(code, MCD_ERROR_INVALID_ARGUMENT) << message;
    EXPECT_NE(message.find("the output view has no data"), std::string::npos) << message;
    mcdReleaseMethod(run);
    mcdReleaseFrame(good);
    EXPECT_STREQ(mcdErrorName(MCD_ERROR_NON_FINITE_INPUT), "non-finite input");
    EXPECT_STREQ(mcdErrorName(MCD_ERROR_CANCELLED), "cancelled");
    mcdReleaseFrame(frame);
    mcdReleaseMethod(method);
}

TEST_F(CApi, ProgressFunctionCancels) {
    Layers layers;
    MCDFrame frame = layers.NewFrame();
    MCDMethod method = mcdNewMethod("bayes");
    int calls = 0;
    mcdSetMethodProgressFunction(
        method,
        [](void *user, const char *, int, int) {
            ++*static_cast<int *>(user);
            return false;
        },
        &calls);
    std::vector<float> out(size_t(layers.w) * layers.h * 3, 9.f);
    MCDView view = mcdInterleaved(out.data(), MCD_FORMAT_FLOAT, layers.w, layers.h, 3);
    EXPECT_EQ(mcdRunMethod(method, SharedDevice(), frame, &view), nullptr);
    auto [code, message] = TakeError();
    EXPECT_EQ(code, MCD_ERROR_CANCELLED) << message;
    EXPECT_EQ(calls, 1);  // no submission after the one that was refused
    for (float v : out) ASSERT_EQ(v, 9.f);
    mcdReleaseMethod(method);
    mcdReleaseFrame(frame);
}

TEST_F(CApi, MethodsAndFramesAreListed) {
    ASSERT_EQ(mcdGetMethodCount(), int(MethodNames().size()) + 1);
    EXPECT_STREQ(mcdGetMethodName(0), "auto");
    EXPECT_EQ(mcdGetMethodName(mcdGetMethodCount()), nullptr);
    MCDMethod method = mcdNewMethod("awr");
    EXPECT_GT(mcdGetMethodParamCount(method), 0);
    EXPECT_STREQ(mcdGetMethodParamName(method, 0), Method("awr").Params()[0].name.c_str());
    mcdReleaseMethod(method);
    Layers layers;
    MCDFrame frame = layers.NewFrame();
    EXPECT_EQ(mcdGetFrameLayerCount(frame), 2);
    EXPECT_STREQ(mcdGetFrameLayerName(frame, 1), "variance");
    EXPECT_EQ(mcdGetFrameLayerChannels(frame, "color"), 3);
    EXPECT_EQ(mcdGetFrameLayerChannels(frame, "albedo"), 0);
    EXPECT_EQ(TakeError().first, MCD_ERROR_MISSING_LAYER);
    mcdReleaseFrame(frame);
}

// Strings the API hands out stay valid, each with its own text, until their handle is
// released (the header's promise), however many calls come between.
TEST_F(CApi, HandedStringsLiveAsLongAsTheirHandle) {
    MCDMethod method = mcdNewMethod("rhf");
    const char *kappa = mcdGetMethodParamText(method, "kappa");
    const char *nonFinite = mcdGetMethodParamText(method, "non-finite");
    ASSERT_NE(kappa, nullptr);
    const std::string kappaText = kappa;
    EXPECT_NE(kappaText, "refuse");
    EXPECT_STREQ(nonFinite, "refuse");
    Layers layers;
    MCDFrame frame = layers.NewFrame();
    const char *first = mcdGetFrameLayerName(frame, 0);
    const char *second = mcdGetFrameLayerName(frame, 1);
    // More layers, named longer than any string kept inline, after the names were taken.
    MCDView extra =
        mcdInterleaved(layers.varianceBuffer.data(), MCD_FORMAT_FLOAT, layers.w, layers.h, 3);
    for (int i = 0; i < 4; ++i)
        ASSERT_TRUE(mcdSetFrameLayer(
            frame, ("zz_a_layer_named_well_past_inline_strings_" + std::to_string(i)).c_str(),
            &extra));
    // Calls that once replaced the strings, then allocations that would reuse freed memory.
    std::vector<std::vector<std::string>> churn;
    for (int i = 0; i < 64; ++i) {
        mcdGetFrameLayerCount(frame);
        mcdGetFrameLayerName(frame, i % 2);
        mcdGetMethodParamText(method, i % 2 ? "kappa" : "knn");
        churn.emplace_back(2, std::string("zzzzzzzz"));
    }
    EXPECT_STREQ(first, "color");
    EXPECT_STREQ(second, "variance");
    EXPECT_EQ(kappa, mcdGetMethodParamText(method, "kappa"));
    EXPECT_EQ(std::string(kappa), kappaText);
    EXPECT_STREQ(nonFinite, "refuse");
    mcdReleaseFrame(frame);
    mcdReleaseMethod(method);
}

TEST_F(CApi, FilesRoundTripThroughViews) {
    Layers layers;
    std::string path = ::testing::TempDir() + "c_api_round_trip.exr";
    const char *names[] = {"color", "variance"};
    MCDView views[] = {
        mcdInterleaved(layers.colorBuffer.data(), MCD_FORMAT_FLOAT, layers.w, layers.h, 3),
        mcdInterleaved(layers.varianceBuffer.data(), MCD_FORMAT_FLOAT, layers.w, layers.h, 3)};
    ASSERT_TRUE(mcdWriteExr(path.c_str(), names, views, 2)) << TakeError().second;
    MCDFrame frame = mcdReadFrame(path.c_str(), nullptr, 0);
    ASSERT_NE(frame, nullptr) << TakeError().second;
    std::vector<float> back(layers.colorBuffer.size());
    MCDView view = mcdInterleaved(back.data(), MCD_FORMAT_FLOAT, layers.w, layers.h, 3);
    ASSERT_TRUE(mcdCopyFrameLayer(frame, "color", &view)) << TakeError().second;
    EXPECT_EQ(back, layers.colorBuffer);
    mcdReleaseFrame(frame);
    std::remove(path.c_str());
    EXPECT_EQ(mcdReadFrame(path.c_str(), nullptr, 0), nullptr);
    EXPECT_EQ(TakeError().first, MCD_ERROR_IO);
}

}  // namespace
}  // namespace mcd::test
