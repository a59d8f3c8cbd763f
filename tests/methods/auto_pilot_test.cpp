// auto's pilot (issue #32): on a pilot square a candidate whose share is small beside an
// earlier candidate of its own method is left out of the frame's run (host/api/method_auto.h,
// PilotLeavesOut), from the pilot's shares alone, never its times; and the whole method runs
// the pilot only where the frame holds 16 squares and SURE on the variance layer weighs the
// candidates.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <algorithm>
#include <cstring>
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

// The rule reads no clock: a pilot candidate carries no time to judge by.
template <typename T>
constexpr bool kHasSeconds = requires(T c) {
    c.seconds;
};
static_assert(!kHasSeconds<PilotCandidate>);

// The candidates' shares on the pilot square as --explain gave them on glossy-cornell
// 480x270, 8 spp, every layer, --auto-pilot 128.
std::vector<PilotCandidate> GlossyShares() {
    return {{"rhf", "rhf", 12.2},
            {"pivot", "pivot", 18.7},
            {"bayes", "bayes", 32.4},
            {"rhf 2 scales", "rhf", 17.7},
            {"pivot no ids", "pivot", 18.6},
            {"bayes no split", "bayes", 0.4}};
}

TEST(AutoPilotRule, LeavesOutASmallShareBesideItsMethodsEarlierCandidate) {
    const std::vector<std::string> why = PilotLeavesOut(GlossyShares(), 0.75);
    ASSERT_EQ(why.size(), 6u);
    for (size_t k = 0; k < why.size(); ++k)
        EXPECT_EQ(why[k].empty(), k != 5) << k << ": " << why[k];
    EXPECT_NE(why[5].find("its share was 0.4%, under 0.75 of bayes's 32.4%"), std::string::npos)
        << why[5];
    // Its method's earlier candidate at 0.75 of the share or more: it stays.
    std::vector<PilotCandidate> pilot = GlossyShares();
    pilot[4].share = 0.75 * 18.7 - 0.1;
    EXPECT_NE(PilotLeavesOut(pilot, 0.75)[4].find("pivot's 18.7%"), std::string::npos);
    pilot[4].share = 0.75 * 18.7;
    EXPECT_TRUE(PilotLeavesOut(pilot, 0.75)[4].empty());
}

TEST(AutoPilotRule, ComparesOnlyEarlierCandidatesOfTheSameMethod) {
    // A small share beside another method's large one stays ("pivot no ids" beside "bayes").
    std::vector<PilotCandidate> pilot = GlossyShares();
    pilot[4].share = 1;
    pilot[1].share = 1.2;
    EXPECT_TRUE(PilotLeavesOut(pilot, 0.75)[4].empty());
    // A candidate of its method after it is not compared: it may have reused its work (the
    // run memo).
    pilot = GlossyShares();
    std::swap(pilot[2], pilot[5]);
    EXPECT_TRUE(PilotLeavesOut(pilot, 0.75)[2].empty());
    EXPECT_TRUE(PilotLeavesOut(pilot, 0.75)[5].empty());
    // The first always stays; a ratio of 0 leaves none out.
    pilot = {{"a", "m", 1}, {"b", "m", 99}};
    EXPECT_TRUE(PilotLeavesOut(pilot, 1)[0].empty());
    for (const std::string &why : PilotLeavesOut(GlossyShares(), 0)) EXPECT_TRUE(why.empty());
    // One left out is no measure for those after it: "c" is only compared with "a".
    pilot = {{"a", "m", 10}, {"b", "m", 5}, {"c", "m", 4}};
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

bool SameBits(const Image &a, const Image &b) {
    return a.data.size() == b.data.size() &&
           std::memcmp(a.data.data(), b.data.data(), a.data.size() * sizeof(float)) == 0;
}

// The pilot runs where the frame holds 16 squares, and what it leaves out does not run; a
// rerun gives the same candidates and bits; on a smaller frame, or with --auto-pilot 0,
// nothing changes, nor where the rule leaves none out.
TEST_F(AutoPilot, RunsOnFramesOfSixteenSquaresAndLeavesOutWhatItSays) {
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
    // Every candidate with a smaller share than its method's earlier one is left out.
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
    ASSERT_GT(out, 0) << plan;
    EXPECT_EQ(result.candidates.size() + out, small.candidates.size()) << plan;
    EXPECT_FALSE(SameBits(result.image, small.image));
    // The same frame and options: the same candidates and bits, whatever the clock said.
    Result again = piloted.Run(device, frame);
    EXPECT_EQ(again.candidates, result.candidates);
    EXPECT_TRUE(SameBits(again.image, result.image));

    // The pilot leaving none out changes no bit.
    piloted.Set("auto-pilot-share", 0.f);
    Result none = piloted.Run(device, frame);
    EXPECT_TRUE(Has(Plan(none), "auto: pilot on")) << Plan(none);
    EXPECT_EQ(none.candidates, small.candidates);
    EXPECT_TRUE(SameBits(none.image, small.image));

    // A frame under 16 squares runs no pilot, nor does --auto-pilot 0.
    piloted.Set("auto-pilot-share", 1.f);
    piloted.Set("auto-pilot", 14);
    EXPECT_FALSE(Has(Plan(piloted.Run(device, frame)), "auto: pilot on"));
    piloted.Set("auto-pilot", 0);
    Result off = piloted.Run(device, frame);
    EXPECT_FALSE(Has(Plan(off), "auto: pilot on"));
    EXPECT_EQ(off.candidates, small.candidates);
    EXPECT_TRUE(SameBits(off.image, small.image));
}

}  // namespace
}  // namespace mcd::test
