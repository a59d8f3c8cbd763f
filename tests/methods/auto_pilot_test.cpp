// auto's time rule (issue #32): on a pilot square a candidate whose share is small beside a
// cheaper one that ran before it is left out of the frame's run (host/api/method_auto.h,
// PilotLeavesOut), and the whole method runs the pilot only where the frame holds 16
// squares and SURE on the variance layer weighs the candidates.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <algorithm>
#include <string>
#include <vector>

#include "harness/gpu_fixture.h"
#include "host/api/device.h"
#include "host/api/method_auto.h"
#include "mcdenoise/mcdenoise.h"
#include "tools/render/renderer.h"

namespace mcd::test {
namespace {

using api::PilotCandidate;
using api::PilotLeavesOut;

// The candidates' times and shares as --explain gave them on cornell 480x270, 8 spp, every
// layer (the brief of issue #32): "pivot no ids" kept 15.0% for 0.98 s beside "rhf 2
// scales"' 23.5% for 0.53 s.
std::vector<PilotCandidate> CornellShares() {
    return {{"rhf", 0.99, 23.2},          {"pivot", 1.47, 22.8},
            {"bayes", 0.30, 7.8},         {"rhf 2 scales", 0.53, 23.5},
            {"pivot no ids", 0.98, 15.0}, {"bayes no split", 0.28, 7.6}};
}

TEST(AutoPilotRule, LeavesOutASmallShareBesideACheaperCandidate) {
    const std::vector<std::string> why = PilotLeavesOut(CornellShares(), 0.75);
    ASSERT_EQ(why.size(), 6u);
    for (size_t k = 0; k < why.size(); ++k)
        EXPECT_EQ(why[k].empty(), k != 4) << k << ": " << why[k];
    EXPECT_NE(why[4].find("rhf 2 scales's 23.5% in 0.53 s"), std::string::npos) << why[4];
    EXPECT_NE(why[4].find("did not earn its time"), std::string::npos) << why[4];
}

TEST(AutoPilotRule, KeepsWhatNoCheaperEarlierCandidateOutweighs) {
    std::vector<PilotCandidate> pilot = CornellShares();
    // Its share at 0.75 of the cheaper one's or more: it stays.
    pilot[4].share = 0.75 * 23.5;
    EXPECT_TRUE(PilotLeavesOut(pilot, 0.75)[4].empty());
    // One that took not under 0.75 of its time is no measure for it.
    pilot = CornellShares();
    pilot[3].seconds = 0.75 * 0.98;
    EXPECT_TRUE(PilotLeavesOut(pilot, 0.75)[4].empty());
    // A cheaper candidate after it is not compared: its time may have come from it (the
    // run memo).
    pilot = CornellShares();
    std::swap(pilot[3], pilot[4]);
    EXPECT_TRUE(PilotLeavesOut(pilot, 0.75)[3].empty());
    // The first always stays; a ratio of 0 leaves none out.
    pilot = {{"slow", 9, 1}, {"fast", 1, 99}};
    EXPECT_TRUE(PilotLeavesOut(pilot, 1)[0].empty());
    for (const std::string &why : PilotLeavesOut(CornellShares(), 0)) EXPECT_TRUE(why.empty());
    // One left out is no measure for those after it: "b" is only compared with "a".
    pilot = {{"a", 1, 10}, {"b", 2, 5}, {"c", 3, 4}};
    std::vector<std::string> why = PilotLeavesOut(pilot, 0.75);
    EXPECT_FALSE(why[1].empty());
    EXPECT_NE(why[2].find("a's 10.0%"), std::string::npos) << why[2];
}

class AutoPilot : public GpuTest {};

std::string Plan(const Result &result) {
    return fmt::format("{}", fmt::join(result.plan, "\n"));
}

bool Has(const std::string &plan, const std::string &text) {
    return plan.find(text) != std::string::npos;
}

// The pilot runs where the frame holds 16 squares, and what it leaves out does not run; on a
// smaller frame, or with --auto-pilot 0, nothing changes.
TEST_F(AutoPilot, RunsOnFramesOfFourSquaresAndLeavesOutWhatItSays) {
    render::RenderOptions options;
    options.width = 64, options.height = 48, options.spp = 4;
    options.layers = render::kLayersAll;
    render::RenderResult rendered = render::Render(render::BuildScene("cornell"), options);
    Frame frame;
    frame.width = options.width, frame.height = options.height;
    for (auto &[name, image] : rendered.layers) frame.layers[name] = std::move(image);
    Device device = api::BorrowDevice(Ctx());

    Method byDefault("auto");
    Result small = byDefault.Run(device, frame);
    EXPECT_FALSE(Has(Plan(small), "auto: pilot on")) << Plan(small);

    Method piloted("auto");
    piloted.Set("auto-pilot", 12);
    // Every candidate with a smaller share than a cheaper one before it is left out.
    piloted.Set("auto-pilot-share", 1.f);
    Result result = piloted.Run(device, frame);
    const std::string plan = Plan(result);
    EXPECT_TRUE(Has(plan, "auto: pilot on the 12x12 square at (24, 16)")) << plan;
    int out = 0;
    for (const std::string &line : result.plan) {
        if (!line.starts_with("auto: left out ") || !Has(line, "on the pilot square")) continue;
        ++out;
        std::string label = line.substr(15, line.find(':', 15) - 15);
        EXPECT_EQ(std::count(result.candidates.begin(), result.candidates.end(), label), 0)
            << label;
    }
    EXPECT_EQ(result.candidates.size() + out, small.candidates.size()) << plan;

    // A frame under 16 squares runs no pilot, nor does --auto-pilot 0.
    piloted.Set("auto-pilot", 14);
    EXPECT_FALSE(Has(Plan(piloted.Run(device, frame)), "auto: pilot on"));
    piloted.Set("auto-pilot", 0);
    Result off = piloted.Run(device, frame);
    EXPECT_FALSE(Has(Plan(off), "auto: pilot on"));
    EXPECT_EQ(off.candidates, small.candidates);
}

}  // namespace
}  // namespace mcd::test
