// StagedRun, the recording helper every method runs through: stages are taken only when
// kept, each at the point of the run where it is named (or after the last submission for
// StageAtEnd), in the order named; timings gather across submissions; Finish appends.
#include <gtest/gtest.h>

#include <array>
#include <string>
#include <vector>

#include "harness/compare.h"
#include "harness/gpu_fixture.h"
#include "harness/inputs.h"
#include "host/kernels/bayes_mix.h"
#include "host/methods/staged_run.h"
#include "host/vk/gpu_image.h"

namespace mcd::test {
namespace {

class StagedRunTest : public GpuTest {};

// The image times `m`, on the host in float as the kernel does it: the expected stages.
Image Mixed(const Image &in, const std::array<float, 9> &m) {
    vk::GpuImage gpu(TestContext(), in.width, in.height, 3, "test.mix");
    gpu.Upload(in);
    vk::Recorder recorder(TestContext());
    RecordBayesMix(TestContext(), recorder, gpu, m);
    recorder.Submit();
    return gpu.Download();
}

TEST_F(StagedRunTest, StagesInOrderAtTheirPoint) {
    Image input = MakeInput(InputKind::Uniform, 9, 7, 3, SeedFromName("staged run"));
    std::array<float, 9> m = BayesOpponent(), back = BayesOpponentInverse();
    Image once = Mixed(input, m), twice = Mixed(once, back);
    vk::GpuImage image(Ctx(), 9, 7, 3, "test.image");
    image.Upload(input);
    StagedRun run(Ctx(), true);
    EXPECT_TRUE(run.KeepsStages());
    run.StageAtEnd("end", image);
    RecordBayesMix(Ctx(), run.Recorder(), image, m);
    run.Stage("once", image);
    run.AddStage("host", input);
    RecordBayesMix(Ctx(), run.Recorder(), image, back);
    run.Plan("mixed twice");
    run.Warn("nothing wrong");
    MethodResult result;
    result.plan.push_back("before");
    run.Finish(result);
    ASSERT_EQ(result.stages.size(), 3u);
    EXPECT_EQ(result.stages[0].first, "end");
    EXPECT_TRUE(BitIdentical(result.stages[0].second, twice));
    EXPECT_EQ(result.stages[1].first, "once");
    EXPECT_TRUE(BitIdentical(result.stages[1].second, once));
    EXPECT_EQ(result.stages[2].first, "host");
    EXPECT_TRUE(BitIdentical(result.stages[2].second, input));
    EXPECT_EQ(result.plan, (std::vector<std::string>{"before", "mixed twice"}));
    EXPECT_EQ(result.warnings, std::vector<std::string>{"nothing wrong"});
    // Two dispatches in two submissions.
    ASSERT_EQ(result.timings.size(), 2u);
    EXPECT_EQ(result.timings[0].label, result.timings[1].label);
}

TEST_F(StagedRunTest, WithoutStagesNothingIsTakenNorSubmitted) {
    Image input = MakeInput(InputKind::Uniform, 9, 7, 3, SeedFromName("staged run"));
    vk::GpuImage image(Ctx(), 9, 7, 3, "test.image");
    image.Upload(input);
    StagedRun run(Ctx(), false);
    EXPECT_FALSE(run.KeepsStages());
    RecordBayesMix(Ctx(), run.Recorder(), image, BayesOpponent());
    run.Stage("once", image);
    run.StageAtEnd("end", image);
    run.AddStage("host", input);
    run.Stage("made", [] { return Image(1, 1, 1); });
    // No submission yet: the stage calls left the dispatch recorded.
    EXPECT_TRUE(run.Timings().empty());
    EXPECT_EQ(run.Recorder().DispatchCount(), 1u);
    MethodResult result;
    run.Finish(result);
    EXPECT_TRUE(result.stages.empty());
    EXPECT_EQ(result.timings.size(), 1u);
    EXPECT_TRUE(BitIdentical(image.Download(), Mixed(input, BayesOpponent())));
}

}  // namespace
}  // namespace mcd::test
