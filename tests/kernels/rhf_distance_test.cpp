// Kernel rhf/distance (RecordRhfDistance) alone against the reference's distances from the
// same stored pair terms (ref::RhfDistancesFromTerms): random term sums and counts with
// empty and vetoed pairs, whole frames and strips whose term buffers hold only the rows
// they need, patches shrunk at every border, odd sizes down to 1x1. The terms are finite
// by contract (terms.comp writes them), so there are no NaN cases.
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
#include "host/kernels/rhf_distance.h"
#include "host/vk/buffer.h"
#include "host/vk/recorder.h"

namespace mcd::test {
namespace {

constexpr double kUnitRoundoff = 0x1p-24;

struct DistanceCase {
    int w, h, b, patchHalf;
    int rowBase, rows;  // rows 0: the whole frame

    int Rows() const { return rows > 0 ? rows : h; }
    std::string Name() const {
        return fmt::format("{}x{}_b{}_w{}_rows{}to{}", w, h, b, patchHalf, rowBase,
                           rowBase + Rows());
    }
};

// Pair terms of every offset with dy >= 0: counts 0..60 (sum 0 with them) one in five,
// -1 (vetoed) one in forty; sums log-normal times the count, some fireflies.
void RandomTerms(const DistanceCase &c, uint64_t seed, Image *sum, Image *count) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> unit(0.f, 1.f);
    std::normal_distribution<float> normal(0.f, 1.f);
    int planes = (c.b + 1) * (2 * c.b + 1);
    *sum = Image(c.w, c.h, planes);
    *count = Image(c.w, c.h, planes);
    for (size_t i = 0; i < sum->Size(); ++i) {
        float u = unit(rng);
        float n = u < 0.2f ? 0.f : u < 0.225f ? -1.f : float(1 + rng() % 60);
        count->data[i] = n;
        float v = std::exp(normal(rng)) * std::max(n, 1.f);
        sum->data[i] = n == 0 ? 0.f : unit(rng) < 0.01f ? v * 1e4f : v;
    }
}

class RhfDistanceKernel : public GpuTestWithParam<DistanceCase> {};

// Each distance is a float sum of at most (2w + 1)^2 non-negative term sums (at most
// (2w + 1)^2 - 1 roundings of the running total, each within u of the final sum), the
// integer counts exactly, and one division: ((2w + 1)^2 + 2) u of the distance itself.
// Offsets whose patch leaves the image and vetoed pairs are -1 on both sides.
TEST_P(RhfDistanceKernel, MatchesReference) {
    const DistanceCase &c = GetParam();
    Image sum, count;
    RandomTerms(c, SeedFromName(c.Name()), &sum, &count);
    Image expected = ref::RhfDistancesFromTerms(sum, count, c.b, c.patchHalf);
    // The term buffers hold the rows the strip's patches and candidates reach.
    int termBase = std::max(0, c.rowBase - c.patchHalf - c.b);
    int termEnd = std::min(c.h, c.rowBase + c.Rows() + c.patchHalf);
    Image sumRows = sum.Crop(0, termBase, c.w, termEnd),
          countRows = count.Crop(0, termBase, c.w, termEnd);
    vk::Buffer sumGpu(Ctx(), sumRows.Size() * sizeof(float), "termSum"),
        countGpu(Ctx(), countRows.Size() * sizeof(float), "termCount");
    sumGpu.UploadFloats(sumRows.data);
    countGpu.UploadFloats(countRows.data);
    const int offsets = (2 * c.b + 1) * (2 * c.b + 1);
    vk::Buffer dist(Ctx(), size_t(offsets) * c.Rows() * c.w * sizeof(float), "dist");
    auto run = [&] {
        vk::Recorder recorder(Ctx());
        RecordRhfDistance(Ctx(), recorder, c.w, c.h, c.patchHalf, c.b, termBase,
                          termEnd - termBase, c.rowBase, c.Rows(), sumGpu, countGpu, dist);
        recorder.Submit();
        Image out(c.w, c.Rows(), offsets);
        out.data = dist.DownloadFloats(out.Size());
        return out;
    };
    Image got = run();
    Image want = expected.Crop(0, c.rowBase, c.w, c.rowBase + c.Rows());
    int side = 2 * c.patchHalf + 1;
    Tolerance tol{(side * side + 2) * kUnitRoundoff, 0, 1e-10};
    EXPECT_TRUE(ImagesMatch(want, got, {}, tol));
    int candidates = 0;
    for (float d : want.data) candidates += d >= 0;
    if (c.w * c.h > 1) {
        EXPECT_GT(candidates, c.w * c.Rows()) << "hardly any candidate";
    }
    EXPECT_TRUE(BitIdentical(got, run()));
}

std::vector<DistanceCase> Cases() {
    return {{1, 1, 1, 1, 0, 0},   {7, 1, 2, 1, 0, 0},    {1, 6, 2, 1, 0, 0},
            {13, 9, 2, 1, 0, 0},  {24, 17, 3, 2, 5, 6},  {17, 12, 3, 2, 0, 4},
            {30, 14, 6, 1, 0, 0}, {21, 15, 6, 1, 11, 4}, {9, 8, 1, 3, 0, 0}};
}

INSTANTIATE_TEST_SUITE_P(Cases, RhfDistanceKernel, testing::ValuesIn(Cases()),
                         [](const testing::TestParamInfo<DistanceCase> &info) {
                             return info.param.Name();
                         });

}  // namespace
}  // namespace mcd::test
