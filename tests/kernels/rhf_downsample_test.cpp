// Kernel rhf/downsample (RecordRhfDownsample) alone against the reference's Gaussian
// sampler D_s (ref::RhfGaussianDownsample): steps 2 and 4 with the scales' sigmas and one
// other, its taps from RhfGaussianTaps (so a wrong tap is caught too), one to seven planes,
// odd sizes down to 1x1, values uniform, with fireflies, constant and laced with NaN/Inf.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <cmath>
#include <string>
#include <vector>

#include "cpu_reference/rhf.h"
#include "harness/compare.h"
#include "harness/gpu_fixture.h"
#include "harness/inputs.h"
#include "host/kernels/rhf_downsample.h"
#include "host/vk/buffer.h"
#include "host/vk/recorder.h"

namespace mcd::test {
namespace {

constexpr double kUnitRoundoff = 0x1p-24;

struct DownsampleCase {
    int w, h, planes, s;
    double sigma;
    InputKind kind;

    std::string Name() const {
        return fmt::format("{}x{}x{}_s{}_sigma{}_{}", w, h, planes, s, int(sigma * 100),
                           InputKindName(kind));
    }
};

class RhfDownsampleKernel : public GpuTestWithParam<DownsampleCase> {};

// Each pass is a float dot product of 2r + 1 positive taps (each rounded to float: u) with
// the values: within (2r + 3) u of sum g |x|; the second pass carries the first's error
// through taps summing to 1. With the reference's own rounding: (4r + 8) u of the same
// sampler applied to |x| (the magnitude twin; the taps are positive).
TEST_P(RhfDownsampleKernel, MatchesReference) {
    const DownsampleCase &c = GetParam();
    const int step = 1 << c.s, dw = (c.w + step - 1) / step, dh = (c.h + step - 1) / step;
    Image in = MakeInput(c.kind, c.w, c.h, c.planes, SeedFromName(c.Name()));
    Image expected = ref::RhfGaussianDownsample(in, c.s, c.sigma);
    Image absolute = in;
    for (float &v : absolute.data) v = std::fabs(v);
    Image magnitude = ref::RhfGaussianDownsample(absolute, c.s, c.sigma);
    std::vector<float> taps = RhfGaussianTaps(c.sigma, step);
    const int radius = int(taps.size() / 2);
    vk::Buffer src(Ctx(), in.Size() * sizeof(float), "src"),
        weights(Ctx(), taps.size() * sizeof(float), "weights"),
        scratch(Ctx(), size_t(c.planes) * c.h * dw * sizeof(float), "scratch"),
        dst(Ctx(), size_t(c.planes) * dh * dw * sizeof(float), "dst");
    src.UploadFloats(in.data);
    weights.UploadFloats(taps);
    auto run = [&] {
        vk::Recorder recorder(Ctx());
        RecordRhfDownsample(Ctx(), recorder, src, c.w, c.h, c.planes, step, weights, radius,
                            scratch, dst);
        recorder.Submit();
        Image out(dw, dh, c.planes);
        out.data = dst.DownloadFloats(out.Size());
        return out;
    };
    Image got = run();
    EXPECT_TRUE(
        ImagesMatch(expected, got, magnitude, {(4 * radius + 8) * kUnitRoundoff, 0, 1e-10}));
    EXPECT_TRUE(BitIdentical(got, run()));
}

std::vector<DownsampleCase> Cases() {
    const double s1 = 0.55 * std::sqrt(3.0), s2 = 0.55 * std::sqrt(15.0);
    return {{1, 1, 3, 1, s1, InputKind::Uniform},
            {2, 1, 1, 1, s1, InputKind::Uniform},
            {1, 7, 3, 2, s2, InputKind::LogNormalFireflies},
            {17, 13, 3, 1, s1, InputKind::Uniform},
            {17, 13, 7, 1, s1, InputKind::LogNormalFireflies},
            {33, 20, 3, 2, s2, InputKind::Uniform},
            {33, 20, 3, 2, s2, InputKind::NonFinite},
            {26, 9, 2, 1, 1.3, InputKind::Constant},
            {70, 5, 3, 1, s1, InputKind::Impulse}};
}

INSTANTIATE_TEST_SUITE_P(Cases, RhfDownsampleKernel, testing::ValuesIn(Cases()),
                         [](const testing::TestParamInfo<DownsampleCase> &info) {
                             return info.param.Name();
                         });

}  // namespace
}  // namespace mcd::test
