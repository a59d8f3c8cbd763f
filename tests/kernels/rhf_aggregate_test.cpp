// Kernel rhf/aggregate (RecordRhfAggregate) alone against the reference's aggregation of a
// given selection (ref::RhfAggregate, eqs. 6-7): random selections of the candidates whose
// patches fit (centres selecting nothing included), colours uniform, with fireflies,
// constant and laced with NaN/Inf, patches shrunk at every border, odd sizes down to 1x1.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "cpu_reference/rhf_steps.h"
#include "harness/compare.h"
#include "harness/gpu_fixture.h"
#include "harness/inputs.h"
#include "host/kernels/rhf_aggregate.h"
#include "host/kernels/rhf_select.h"
#include "host/vk/buffer.h"
#include "host/vk/gpu_image.h"
#include "host/vk/recorder.h"

namespace mcd::test {
namespace {

constexpr double kUnitRoundoff = 0x1p-24;

struct AggregateCase {
    int w, h, b, patchHalf;
    InputKind kind;

    std::string Name() const {
        return fmt::format("{}x{}_b{}_w{}_{}", w, h, b, patchHalf, InputKindName(kind));
    }
};

// One centre in ten selects nothing; the others each candidate whose patch fits with
// probability 0.3 and themselves with 0.9.
Image RandomSelection(const AggregateCase &c, uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> unit(0.f, 1.f);
    const int side = 2 * c.b + 1;
    Image selected(c.w, c.h, side * side);
    for (int y = 0; y < c.h; ++y)
        for (int x = 0; x < c.w; ++x) {
            if (unit(rng) < 0.1f) continue;
            int w0 = std::min({c.patchHalf, x, y, c.w - 1 - x, c.h - 1 - y});
            for (int dy = -c.b; dy <= c.b; ++dy)
                for (int dx = -c.b; dx <= c.b; ++dx) {
                    int qx = x + dx, qy = y + dy;
                    if (qx < w0 || qx > c.w - 1 - w0 || qy < w0 || qy > c.h - 1 - w0) continue;
                    float p = dx == 0 && dy == 0 ? 0.9f : 0.3f;
                    selected.At((dy + c.b) * side + dx + c.b, y, x) = unit(rng) < p ? 1.f : 0.f;
                }
        }
    return selected;
}

// The selection as select.comp writes it: bit o % 32 of word o / 32, planar [word][y][x].
std::vector<uint32_t> MaskWords(const Image &selected, int b) {
    int words = RhfMaskWords(b);
    std::vector<uint32_t> mask(size_t(words) * selected.PixelCount(), 0u);
    for (int o = 0; o < selected.channels; ++o)
        for (size_t p = 0; p < selected.PixelCount(); ++p)
            if (selected.Plane(o)[p] != 0)
                mask[size_t(o / 32) * selected.PixelCount() + p] |= 1u << (o % 32);
    return mask;
}

class RhfAggregateKernel : public GpuTestWithParam<AggregateCase> {};

// Per pixel the kernel adds 1 / n_c over the at most (2w + 1)^2 patches covering it (each
// weight within u, their sum within (2w + 1)^2 u), multiplies (u) and adds at most
// (2b + 1)^2 weighted colours ((2b + 1)^2 u of the sum of their magnitudes), then divides by
// the estimate count (u): within ((2b + 1)^2 + (2w + 1)^2 + 4) u of the same aggregation
// of |colour| (the magnitude twin).
TEST_P(RhfAggregateKernel, MatchesReference) {
    const AggregateCase &c = GetParam();
    uint64_t seed = SeedFromName(c.Name());
    Image color = MakeInput(c.kind, c.w, c.h, 3, seed);
    Image selected = RandomSelection(c, seed + 1);
    Image expected = ref::RhfAggregate(color, selected, c.b, c.patchHalf);
    Image absolute = color;
    for (float &v : absolute.data) v = std::fabs(v);
    Image magnitude = ref::RhfAggregate(absolute, selected, c.b, c.patchHalf);
    std::vector<uint32_t> words = MaskWords(selected, c.b);
    vk::GpuImage colorGpu(Ctx(), c.w, c.h, 3, "color"), out(Ctx(), c.w, c.h, 3, "out");
    colorGpu.Upload(color);
    vk::Buffer mask(Ctx(), words.size() * sizeof(uint32_t), "mask");
    mask.Upload(words.data(), words.size() * sizeof(uint32_t));
    auto run = [&] {
        vk::Recorder recorder(Ctx());
        RecordRhfAggregate(Ctx(), recorder, colorGpu, mask, c.patchHalf, c.b, out);
        recorder.Submit();
        return out.Download();
    };
    Image got = run();
    int side = 2 * c.b + 1, patch = 2 * c.patchHalf + 1;
    Tolerance tol{(side * side + patch * patch + 4) * kUnitRoundoff, 0, 1e-10};
    EXPECT_TRUE(ImagesMatch(expected, got, magnitude, tol));
    EXPECT_TRUE(BitIdentical(got, run()));
}

std::vector<AggregateCase> Cases() {
    return {{1, 1, 1, 1, InputKind::Uniform},     {8, 1, 2, 1, InputKind::LogNormalFireflies},
            {1, 9, 2, 1, InputKind::Uniform},     {17, 13, 2, 1, InputKind::Uniform},
            {17, 13, 2, 1, InputKind::NonFinite}, {23, 19, 3, 2, InputKind::LogNormalFireflies},
            {31, 20, 6, 1, InputKind::Uniform},   {31, 20, 6, 1, InputKind::Constant},
            {12, 11, 1, 3, InputKind::Impulse}};
}

INSTANTIATE_TEST_SUITE_P(Cases, RhfAggregateKernel, testing::ValuesIn(Cases()),
                         [](const testing::TestParamInfo<AggregateCase> &info) {
                             return info.param.Name();
                         });

}  // namespace
}  // namespace mcd::test
