// nfor with a run memo (host/methods/run_memo.h): the prefiltered features taken from an
// earlier run on the same features give the output a run without the memo gives, bit for
// bit, whatever the colour; runs whose features or prefilter options differ do not share.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <algorithm>
#include <random>
#include <string>

#include "harness/compare.h"
#include "harness/gpu_fixture.h"
#include "harness/inputs.h"
#include "host/methods/nfor.h"
#include "host/methods/run_memo.h"

namespace mcd::test {
namespace {

// Noisy colour and features (so that the prefilter's noise estimate is not zero), no
// variance layer: the colour's noise is estimated from the frame too.
struct MemoFrame {
    Image color, albedo, normal, depth;
};

MemoFrame MakeMemoFrame(int w, int h, const std::string &name) {
    std::mt19937_64 rng(SeedFromName(name));
    std::uniform_real_distribution<float> unit(0, 1);
    MemoFrame f{Image(w, h, 3), Image(w, h, 3), Image(w, h, 3), Image(w, h, 1)};
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            for (int c = 0; c < 3; ++c) {
                float albedo = (x / 5 + y / 4) % 2 ? 0.2f + 0.1f * c : 0.7f - 0.1f * c;
                f.albedo.At(c, y, x) = albedo * (0.9f + 0.2f * unit(rng));
                f.color.At(c, y, x) = albedo * (0.5f + unit(rng));
                f.normal.At(c, y, x) = (c == 1 ? 1.f : 0.f) + 0.1f * (unit(rng) - 0.5f);
            }
            f.depth.At(0, y, x) = 2 + 0.01f * x + 0.05f * unit(rng);
        }
    return f;
}

NforInputs InputsOf(const MemoFrame &f, const Image &color) {
    NforInputs in;
    in.color = &color;
    in.albedo = &f.albedo;
    in.normal = &f.normal;
    in.depth = &f.depth;
    return in;
}

class NforMemo : public GpuTest {};

TEST_F(NforMemo, SharedFeaturesAreBitIdentical) {
    for (auto [w, h] : {std::pair{27, 19}, std::pair{1, 1}, std::pair{9, 1}}) {
        MemoFrame f = MakeMemoFrame(w, h, fmt::format("nfor memo {}x{}", w, h));
        // auto's probe on the half-buffers: another colour, the same features.
        MemoFrame other = MakeMemoFrame(w, h, fmt::format("nfor memo half {}x{}", w, h));
        NforOptions run, probe, wider;
        run.radius = 4;
        probe.radius = 3;
        probe.bandwidths = {1.f};
        wider = run;
        wider.prefilterPatch = 0;  // another prefilter: its own entry
        RunMemo memo;
        // The first run on these features prefilters them; the next takes them from it.
        auto prefilters = [&](const NforOptions &o) {
            NforResult r = NforDenoise(Ctx(), InputsOf(f, other.color), o, &memo);
            return std::count_if(r.timings.begin(), r.timings.end(),
                                 [](const auto &t) { return t.label == "nfor.prefilter"; });
        };
        EXPECT_GT(prefilters(run), 0);
        EXPECT_EQ(prefilters(probe), 0);
        for (const NforOptions *o : {&run, &probe, &wider})
            for (const Image *color : {&f.color, &other.color}) {
                SCOPED_TRACE(fmt::format("{}x{}, options {}, colour {}", w, h,
                                         o == &run     ? "run"
                                         : o == &probe ? "probe"
                                                       : "wider",
                                         color == &f.color ? "the frame's" : "another"));
                EXPECT_TRUE(
                    BitIdentical(NforDenoise(Ctx(), InputsOf(f, *color), *o).image,
                                 NforDenoise(Ctx(), InputsOf(f, *color), *o, &memo).image));
            }
        EXPECT_EQ(memo.Size(), 2u);
        // Other features: another entry, and the output of a run without the memo.
        EXPECT_TRUE(
            BitIdentical(NforDenoise(Ctx(), InputsOf(other, other.color), run).image,
                         NforDenoise(Ctx(), InputsOf(other, other.color), run, &memo).image));
        EXPECT_EQ(memo.Size(), 3u);
    }
}

}  // namespace
}  // namespace mcd::test
