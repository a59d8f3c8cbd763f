// api::Inputs::LayerId: a layer's identity in run memo keys, hashed once per frame and
// derived for a window's crop; two windows or two contents never share one.
#include <gtest/gtest.h>

#include <string>

#include "harness/inputs.h"
#include "host/api/front_end.h"
#include "host/common/parallel.h"
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

}  // namespace
}  // namespace mcd::test
