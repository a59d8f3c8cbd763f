// The operation formulas of `bench kernels` (tools/mcdenoise/kernel_ops.h) against counts
// made by walking each kernel's loops one operation at a time, on dispatches decoded from
// their push constants and grid as the recorder keeps them.
#include <gtest/gtest.h>

#include <cstring>
#include <optional>

#include "awr/shrink.h"
#include "rhf/distance.h"
#include "tools/mcdenoise/kernel_ops.h"

namespace mcd::tool {
namespace {

template <typename Push>
vk::KeptDispatch Kept(const char *kernel, const Push &push, uint32_t gx, uint32_t gy,
                      uint32_t gz) {
    vk::KeptDispatch d;
    d.timing.kernel = kernel;
    d.timing.groups = {gx, gy, gz};
    d.push.resize(sizeof(Push));
    std::memcpy(d.push.data(), &push, sizeof(Push));
    return d;
}

// rhf/distance.comp's interior path, walked: per centre of the strip and offset, each row
// of the patch, each centre's columns add a sum and a count, then count + 1e-4 and a divide.
TEST(KernelOps, RhfDistanceMatchesItsLoops) {
    for (int patchHalf : {0, 1, 3})
        for (int searchHalf : {1, 6}) {
            const int width = 37, rows = 5, side = 2 * searchHalf + 1;
            shader::RhfDistancePush push{width, 40, patchHalf, 0, 0, 40, 3, rows};
            vk::KeptDispatch d = Kept("rhf_distance", push, (width + 7) / 8, rows, side * side);
            double walked = 0;
            for (int r = 0; r < rows; ++r)
                for (int x = 0; x < width; ++x)
                    for (int o = 0; o < side * side; ++o) {
                        for (int ty = -patchHalf; ty <= patchHalf; ++ty)
                            for (int tx = -patchHalf; tx <= patchHalf; ++tx) walked += 2;
                        walked += 2;
                    }
            std::optional<double> flops = KernelFlops(d);
            ASSERT_TRUE(flops.has_value());
            EXPECT_EQ(*flops, walked)
                << "patch half " << patchHalf << ", search half " << searchHalf;
        }
}

// awr/shrink.comp: sqrt, a multiply, a subtract, a max and the sign's multiply per
// coefficient of every channel.
TEST(KernelOps, AwrShrinkMatchesItsLoops) {
    shader::AwrShrinkPush push{13, 7, 2, 1, 1.5f};
    vk::KeptDispatch d = Kept("awr_shrink", push, 1, 7, 3);
    double walked = 0;
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < 7; ++y)
            for (int x = 0; x < 13; ++x) walked += 5;
    EXPECT_EQ(KernelFlops(d).value_or(-1), walked);
}

// A kernel without a formula says so instead of counting nothing.
TEST(KernelOps, KernelWithoutFormulaHasNone) {
    vk::KeptDispatch d;
    d.timing.kernel = "pivot_fit";
    EXPECT_FALSE(KernelFlops(d).has_value());
    EXPECT_TRUE(KernelFlopsRule("pivot_fit").empty());
    EXPECT_FALSE(KernelFlopsRule("rhf_distance").empty());
}

}  // namespace
}  // namespace mcd::tool
