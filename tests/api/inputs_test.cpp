// api::Inputs::LayerId: a layer's identity in run memo keys, hashed once per frame and
// derived for a window's crop; two windows or two contents never share one.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <string>

#include "harness/inputs.h"
#include "host/api/front_end.h"
#include "host/common/parallel.h"
#include "host/error.h"
#include "host/methods/run_memo.h"
#include "mcdenoise/mcdenoise.h"

namespace mcd::test {
namespace {

Frame LayeredFrame(int width, int height) {
    Frame frame;
    frame.width = width, frame.height = height;
    frame.layers["color"] = MakeInput(InputKind::Uniform, width, height, 3, 7);
    frame.layers["hist"] = MakeInput(InputKind::Uniform, width, height, 13, 8);
    return frame;
}

// The samples per pixel a method reads off a frame: the spp layer's median (rounded), else
// the metadata's count (Cycles' key), else 0.
TEST(FrameSamplesPerPixel, LayerThenMetadataThenUnknown) {
    Frame frame = LayeredFrame(5, 3);
    {
        api::Inputs inputs(frame, false, "nfor");
        EXPECT_EQ(api::FrameSamplesPerPixel(inputs), 0);
    }
    frame.metadata["cycles.ViewLayer.samples"] = "16";
    {
        api::Inputs inputs(frame, false, "nfor");
        EXPECT_EQ(api::FrameSamplesPerPixel(inputs), 16);
    }
    Image spp(5, 3, 1, 8.f);
    spp.data[0] = 64.f, spp.data[1] = 64.f, spp.data[2] = 7.6f;
    frame.layers["spp"] = spp;
    {
        api::Inputs inputs(frame, false, "nfor");
        EXPECT_EQ(api::FrameSamplesPerPixel(inputs), 8);
    }
    frame.layers["spp"] = Image(5, 3, 1, 0.f);
    {
        api::Inputs inputs(frame, false, "nfor");
        EXPECT_EQ(api::FrameSamplesPerPixel(inputs), 0);
    }
}

// Missing() is "" only where the method can run: never on a frame without colour (none, or
// a layer named otherwise), whatever the method's own layers.
TEST(MethodMissing, AFrameWithoutColourRunsNoMethod) {
    Frame empty, misnamed;
    misnamed.layers["colour"] = Image(4, 3, 3, 0.5f);
    for (const std::string &name : {"auto", "bayes", "nfor", "pivot", "awr", "rhf"}) {
        EXPECT_EQ(Method(name).Missing(empty).rfind("no color layer", 0), 0u) << name;
        EXPECT_EQ(Method(name).Missing(misnamed).rfind("no color layer", 0), 0u) << name;
    }
    EXPECT_EQ(Method("bayes").Missing(empty), "no color layer");
    EXPECT_EQ(Method("rhf").Missing(empty).rfind("no color layer; no histogram", 0), 0u)
        << Method("rhf").Missing(empty);
    Frame plain;
    plain.layers["color"] = Image(4, 3, 3, 0.5f);
    EXPECT_EQ(Method("bayes").Missing(plain), "");
}

TEST(InputsLayerId, FrameLayersAreTheirValuesHash) {
    const Frame frame = LayeredFrame(23, 17);
    api::Inputs inputs(frame, false, "rhf");
    EXPECT_EQ(inputs.LayerId("hist"), MemoImageId(frame.layers.at("hist")));
    EXPECT_NE(inputs.LayerId("hist"), inputs.LayerId("color"));
    // A replaced layer is named by its new values.
    Image other = frame.layers.at("hist");
    other.data[5] += 1;
    inputs.Override("hist", other);
    EXPECT_EQ(inputs.LayerId("hist"), MemoImageId(other));
}

TEST(InputsLayerId, WindowsOfOneLayerShareOnlyTheirOwnWindow) {
    const Frame frame = LayeredFrame(23, 17);
    api::Inputs whole(frame, false, "rhf");
    api::Inputs left(whole, 0, 0, 12, 17), right(whole, 11, 0, 23, 17),
        leftAgain(whole, 0, 0, 12, 17), shorter(whole, 0, 0, 12, 16);
    EXPECT_NE(left.LayerId("hist"), right.LayerId("hist"));
    EXPECT_NE(left.LayerId("hist"), shorter.LayerId("hist"));
    EXPECT_NE(left.LayerId("hist"), left.LayerId("color"));
    // Another run's window of the same frame (auto's next candidate) keys alike.
    EXPECT_EQ(left.LayerId("hist"), leftAgain.LayerId("hist"));
    // After the frame's layer is replaced, a new window's crop is of the new values.
    const std::string before = left.LayerId("hist");
    Image other = frame.layers.at("hist");
    other.data[0] += 1;
    whole.Override("hist", other);
    api::Inputs after(whole, 0, 0, 12, 17);
    EXPECT_NE(after.LayerId("hist"), before);
    // A window's own layer (not a crop) is hashed.
    Image own = after.Get("hist");
    after.Override("hist", own);
    EXPECT_EQ(after.LayerId("hist"), MemoImageId(own));
}

// The crop's rows are copied in parts (forced: 1, 5 and 7, so part bounds fall inside
// planes and across them).
TEST(InputsLayerId, WindowCropsAreTheFramesValues) {
    const Frame frame = LayeredFrame(23, 17);
    const Image &hist = frame.layers.at("hist");
    for (int parts : {1, 5, 7}) {
        ForceParallelParts force(parts);
        api::Inputs whole(frame, false, "rhf");
        api::Inputs window(whole, 5, 3, 20, 15);
        const Image &crop = window.Get("hist");
        ASSERT_EQ(crop.width, 15);
        ASSERT_EQ(crop.height, 12);
        for (int c = 0; c < hist.channels; ++c)
            for (int y = 0; y < crop.height; ++y)
                for (int x = 0; x < crop.width; ++x)
                    ASSERT_EQ(crop.At(c, y, x), hist.At(c, y + 3, x + 5))
                        << parts << ": " << c << " " << x << " " << y;
    }
}

// ScopedOverrides puts each layer back as it was, moved, not copied: the frame's own layer
// is read in place again, a window's crop is the same crop, a repaired layer keeps its
// repair without a second warning, and each keeps its identity; also when the scope ends by
// an exception, and with a layer replaced twice in it.
TEST(InputsScopedOverrides, LayersComeBackAsTheyWere) {
    Frame frame = LayeredFrame(23, 17);
    frame.layers["variance"] = MakeInput(InputKind::Uniform, 23, 17, 3, 9);
    frame.layers["variance"].data[4] = std::numeric_limits<float>::quiet_NaN();
    api::Inputs whole(frame, false, "rhf");
    api::Inputs window(whole, 2, 1, 20, 15);
    const Image *frameHist = &whole.Get("hist");
    const Image *repaired = &whole.Get("variance");
    const Image *cropImage = &window.Get("color");
    const float *crop = cropImage->data.data();
    const std::string histId = whole.LayerId("hist"), cropId = window.LayerId("color");
    ASSERT_EQ(whole.warnings.size(), 1u);
    ASSERT_EQ(frameHist, &frame.layers.at("hist"));
    Image other = frame.layers.at("hist");
    other.data[3] += 1;
    try {
        api::ScopedOverrides scoped(whole), scopedWindow(window);
        scoped.Override("hist", other);
        scoped.Override("variance", Image(23, 17, 3));
        scoped.Override("variance", Image(23, 17, 1));
        scopedWindow.Override("color", Image(18, 14, 3));
        // A reference from before the scope sees the replacement, in place.
        EXPECT_EQ(&whole.Get("variance"), repaired);
        EXPECT_EQ(&window.Get("color"), cropImage);
        EXPECT_EQ(whole.LayerId("hist"), MemoImageId(other));
        EXPECT_EQ(whole.Get("variance").channels, 1);
        EXPECT_EQ(window.Get("color").data[0], 0.f);
        throw Error("the run failed", ErrorKind::Internal);
    } catch (const Error &) {
    }
    EXPECT_EQ(&whole.Get("hist"), frameHist);
    EXPECT_EQ(whole.LayerId("hist"), histId);
    EXPECT_EQ(&whole.Get("variance"), repaired);
    EXPECT_EQ(&window.Get("color"), cropImage);
    EXPECT_EQ(whole.Get("variance").data[4], 0.f);
    EXPECT_EQ(whole.Get("variance").channels, 3);
    EXPECT_EQ(whole.warnings.size(), 1u);
    EXPECT_EQ(window.Get("color").data.data(), crop);
    EXPECT_EQ(window.LayerId("color"), cropId);
}

// The identity a layer had comes back as it was, not hashed again: a planted sentinel id
// returns after the scope, and a window's crop is again named by its parent's identity
// and the window (rehashing its values would give another string).
TEST(InputsScopedOverrides, IdentityComesBackUnhashed) {
    const Frame frame = LayeredFrame(23, 17);
    api::Inputs whole(frame, false, "rhf");
    api::Inputs window(whole, 2, 1, 20, 15);
    api::Inputs::Held planted;
    planted.id = "planted id";
    whole.Put("hist", planted);
    ASSERT_EQ(whole.LayerId("hist"), "planted id");
    window.Get("color");
    const std::string cropId = api::Inputs(whole, 2, 1, 20, 15).LayerId("color");
    ASSERT_NE(cropId, MemoImageId(window.Get("color")));
    {
        api::ScopedOverrides scoped(whole), scopedWindow(window);
        scoped.Override("hist", Image(23, 17, 13));
        scopedWindow.Override("color", Image(18, 14, 3));
        EXPECT_EQ(whole.LayerId("hist"), MemoImageId(Image(23, 17, 13)));
    }
    EXPECT_EQ(whole.LayerId("hist"), "planted id");
    EXPECT_EQ(window.LayerId("color"), cropId);
}

// Inputs::Alias refuses a layer read from itself and a source that is not there, leaving
// the layer as it was; an alias follows later replacements of its source and is named.
TEST(InputsAlias, ChecksItsSourceAndFollowsIt) {
    const Frame frame = LayeredFrame(23, 17);
    api::Inputs whole(frame, false, "rhf");
    try {
        whole.Alias("hist", "hist");
        ADD_FAILURE() << "an alias of itself was taken";
    } catch (const Error &e) {
        EXPECT_NE(std::string(e.what()).find("read from itself"), std::string::npos)
            << e.what();
    }
    EXPECT_THROW(whole.Alias("hist", "no such layer"), Error);
    {
        api::ScopedOverrides scoped(whole);
        EXPECT_THROW(scoped.Alias("hist", "no such layer"), Error);
    }
    EXPECT_EQ(&whole.Get("hist"), &frame.layers.at("hist"));
    whole.Alias("extra", "hist");
    const std::vector<std::string> names = whole.Names();
    EXPECT_NE(std::find(names.begin(), names.end(), "extra"), names.end());
    Image other(23, 17, 13, 2.f);
    whole.Override("hist", other);
    EXPECT_EQ(whole.Get("extra").data, other.data);
}

// A layer read from another (auto's probes on half0's own layers): the source's values in
// place, not a copy, named by the source's identity, also through a window's crop; back to
// its own when the scope ends.
TEST(InputsScopedOverrides, AliasReadsTheSourceInPlace) {
    Frame frame = LayeredFrame(23, 17);
    frame.layers["half0.hist"] = MakeInput(InputKind::Uniform, 23, 17, 13, 10);
    api::Inputs whole(frame, false, "rhf");
    const std::string histId = whole.LayerId("hist");
    {
        api::ScopedOverrides scoped(whole);
        scoped.Alias("hist", "half0.hist");
        EXPECT_EQ(&whole.Get("hist"), &frame.layers.at("half0.hist"));
        EXPECT_EQ(whole.LayerId("hist"), MemoImageId(frame.layers.at("half0.hist")));
        api::Inputs window(whole, 4, 2, 15, 16);
        EXPECT_EQ(window.Get("hist").At(5, 3, 2), frame.layers.at("half0.hist").At(5, 5, 6));
        EXPECT_EQ(window.LayerId("hist"),
                  api::Inputs(whole, 4, 2, 15, 16).LayerId("half0.hist"));
        // Replaced again within the scope, then put back.
        scoped.Override("hist", Image(23, 17, 13));
        EXPECT_EQ(whole.Get("hist").data[0], 0.f);
    }
    EXPECT_EQ(&whole.Get("hist"), &frame.layers.at("hist"));
    EXPECT_EQ(whole.LayerId("hist"), histId);
}

}  // namespace
}  // namespace mcd::test
