// The calibration kernels of `bench kernels` (bench/stream, bench/fma) against their CPU
// reference, and the recorder's traffic accounting (vk::DispatchTiming's bytes, the kept
// dispatches' push constants) on kernels whose traffic is known: the stream kernel reads
// one buffer and writes another, AWR's shrinkage reads and writes one in place and reads a
// second.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "awr/shrink.h"
#include "bench/fma.h"
#include "bench/stream.h"
#include "cpu_reference/bench_calibrate.h"
#include "harness/compare.h"
#include "harness/gpu_fixture.h"
#include "harness/inputs.h"
#include "host/kernels/awr_shrink.h"
#include "host/kernels/bench_calibrate.h"
#include "host/vk/dispatch_count.h"
#include "host/vk/gpu_image.h"

namespace mcd::test {
namespace {

constexpr double kUnitRoundoff = 0x1p-24;

struct CalibrateCase {
    uint32_t count;  // vec4s
    InputKind kind;

    std::string Name() const { return fmt::format("{}_{}", count, InputKindName(kind)); }
};

std::vector<CalibrateCase> Cases() {
    std::vector<CalibrateCase> cases;
    for (uint32_t count : {1u, 3u, 255u, 257u, 4099u})
        for (InputKind kind : {InputKind::Uniform, InputKind::LogNormalFireflies,
                               InputKind::Constant, InputKind::NonFinite})
            cases.push_back({count, kind});
    return cases;
}

std::string CaseName(const ::testing::TestParamInfo<CalibrateCase> &info) {
    return info.param.Name();
}

// `count` vec4s of the case's kind, as floats.
std::vector<float> CaseInput(const CalibrateCase &c) {
    return MakeInput(c.kind, int(c.count), 1, 4, SeedFromName(c.Name())).data;
}

Image AsImage(std::vector<float> values) {
    Image image(int(values.size() / 4), 1, 4);
    image.data = std::move(values);
    return image;
}

class BenchStreamKernel : public GpuTestWithParam<CalibrateCase> {};

// A copy: bit for bit, NaN payloads included; and the dispatch's record counts the source
// read once and the destination written once, with the grid and push constants given.
TEST_P(BenchStreamKernel, CopiesAndCountsItsTraffic) {
    const CalibrateCase &c = GetParam();
    std::vector<float> in = CaseInput(c);
    // The destination larger than the copy: the accounting counts bound buffers whole.
    vk::Buffer src(Ctx(), in.size() * sizeof(float), "src"),
        dst(Ctx(), (in.size() + 8) * sizeof(float), "dst");
    src.UploadFloats(in);
    auto run = [&] {
        dst.UploadFloats(std::vector<float>(in.size() + 8, -7.f));
        vk::Recorder recorder(Ctx());
        RecordBenchStream(Ctx(), recorder, src, dst, c.count);
        vk::KeepDispatches(true);
        recorder.Submit();
        vk::KeepDispatches(false);
        EXPECT_EQ(recorder.Timings().size(), 1u);
        return AsImage(dst.DownloadFloats(in.size()));
    };
    Image got = run();
    EXPECT_TRUE(BitIdentical(AsImage(in), got));
    EXPECT_TRUE(BitIdentical(got, run()));
    std::vector<vk::KeptDispatch> kept = vk::KeptDispatches();
    ASSERT_EQ(kept.size(), 1u);
    const vk::DispatchTiming &t = kept[0].timing;
    EXPECT_EQ(t.kernel, "bench_stream");
    EXPECT_EQ(t.label, "bench.stream");
    EXPECT_EQ(t.bytesRead, 16u * c.count);
    EXPECT_EQ(t.bytesWritten, 16u * c.count + 32u);
    uint32_t groups = (c.count + BENCH_STREAM_LOCAL_SIZE - 1) / BENCH_STREAM_LOCAL_SIZE;
    EXPECT_EQ(t.groups[0], groups);
    EXPECT_EQ(t.groups[1], 1u);
    EXPECT_EQ(t.groups[2], 1u);
    ASSERT_EQ(kept[0].push.size(), sizeof(shader::BenchStreamPush));
    shader::BenchStreamPush push;
    std::memcpy(&push, kept[0].push.data(), sizeof(push));
    EXPECT_EQ(push.count, c.count);
}

INSTANTIATE_TEST_SUITE_P(Cases, BenchStreamKernel, ::testing::ValuesIn(Cases()), CaseName);

class BenchFmaKernel : public GpuTestWithParam<CalibrateCase> {};

// Each chain step rounds at most twice (fused or not): 2u |x| with |x| <= M, the chains'
// bound, and the contraction |scale| < 1 damps what came before, so a chain ends within
// (u + 2u / (1 - |scale|)) M of the exact one (u: the start's add); the three adds of the
// sum add 3u of 4M each. M = max(|x0| + 3, |offset| / (1 - |scale|)).
TEST_P(BenchFmaKernel, MatchesReferenceAndItsOperationCount) {
    const CalibrateCase &c = GetParam();
    const uint32_t iterations = 37;
    const float scale = 0.75f, offset = 0.25f;
    std::vector<float> in = CaseInput(c);
    uint64_t flops = 0;
    std::vector<double> exact = ref::BenchFma(in, iterations, scale, offset, &flops);
    EXPECT_EQ(double(flops), BenchFmaFlops(c.count, iterations));
    Image expected(int(c.count), 1, 4), magnitude(int(c.count), 1, 4);
    const double contraction = 1.0 / (1.0 - scale);
    const double bound = 4 * (1 + 2 * contraction) + 12;  // times u M
    for (size_t i = 0; i < in.size(); ++i) {
        expected.data[i] = float(exact[i]);
        double m = std::max(std::fabs(double(in[i])) + 3, offset * contraction);
        magnitude.data[i] = float(m);
    }
    vk::Buffer src(Ctx(), in.size() * sizeof(float), "src"),
        dst(Ctx(), in.size() * sizeof(float), "dst");
    src.UploadFloats(in);
    auto run = [&] {
        vk::Recorder recorder(Ctx());
        RecordBenchFma(Ctx(), recorder, src, dst, c.count, iterations, scale, offset);
        recorder.Submit();
        return AsImage(dst.DownloadFloats(in.size()));
    };
    Image got = run();
    // Plus one rounding of the reference's double result to float.
    EXPECT_TRUE(ImagesMatch(expected, got, magnitude, {(bound + 1) * kUnitRoundoff, 0, 1e-10}));
    EXPECT_TRUE(BitIdentical(got, run()));
}

INSTANTIATE_TEST_SUITE_P(Cases, BenchFmaKernel, ::testing::ValuesIn(Cases()), CaseName);

// In place: the shrinkage's coefficients are read and written, the variances only read.
TEST(VkRecorderTraffic, ReadWriteBindingCountsBothWays) {
    vk::Context &context = TestContext();
    vk::GpuImage coef(context, 9, 5, 3, "coef"), variance(context, 9, 5, 3, "variance");
    vk::Recorder recorder(context);
    RecordAwrShrink(context, recorder, coef, variance, 1, 1, 1.f);
    recorder.Submit();
    ASSERT_EQ(recorder.Timings().size(), 1u);
    const vk::DispatchTiming &t = recorder.Timings()[0];
    const uint64_t bytes = 9 * 5 * 3 * sizeof(float);
    EXPECT_EQ(t.kernel, "awr_shrink");
    EXPECT_EQ(coef.buffer.Bytes(), bytes);
    EXPECT_EQ(t.bytesRead, 2 * bytes);
    EXPECT_EQ(t.bytesWritten, bytes);
    EXPECT_EQ(t.groups[1], 5u);
    EXPECT_EQ(t.groups[2], 3u);
}

}  // namespace
}  // namespace mcd::test
