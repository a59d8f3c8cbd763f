// Mean brightness on heavy-tailed frames (issue 29): a method keeps its input's mean
// brightness where the light arrives in rare bright samples. Each frame fails without the
// restore's last coarse pass (pivot) or without rhf's restore of local means.
#include <gtest/gtest.h>

#include <cstdint>

#include "harness/gpu_fixture.h"
#include "host/api/device.h"
#include "host/metrics.h"
#include "mcdenoise/mcdenoise.h"
#include "tools/render/renderer.h"

namespace mcd {
namespace {

using test::GpuTest;

class HeavyTailBrightness : public GpuTest {
  protected:
    // The output's mean luminance over the input's, for `method` on `scene` rendered at
    // size x size, spp samples, every layer, seed `seed`.
    double Ratio(const char *method, const char *scene, int size, int spp, uint64_t seed) {
        render::RenderOptions options;
        options.width = options.height = size;
        options.spp = spp;
        options.seed = seed;
        options.layers = render::kLayersAll;
        render::RenderResult rendered = render::Render(render::BuildScene(scene), options);
        Frame frame;
        frame.width = frame.height = size;
        for (auto &[name, image] : rendered.layers) frame.layers[name] = std::move(image);
        Device device = api::BorrowDevice(Ctx());
        Result result = Method(method).Run(device, frame);
        return CompareImages(result.image, frame.layers.at("color")).brightness;
    }
};

// double-textured at 16 spp: pivot's robust fits leave the rare bright samples out, and
// the restore's fine scale gave only part of their energy back.
TEST_F(HeavyTailBrightness, PivotKeepsTheMeanOfDoubleTextured) {
    EXPECT_NEAR(Ratio("pivot", "double-textured", 64, 16, 3), 1, 0.02);
}

// relief-abc at 4 spp: rhf's patch weights average a firefly into its dark neighbours but
// not theirs into it.
TEST_F(HeavyTailBrightness, RhfKeepsTheMeanOfReliefAbc) {
    EXPECT_NEAR(Ratio("rhf", "relief-abc", 64, 4, 3), 1, 0.02);
}

}  // namespace
}  // namespace mcd
