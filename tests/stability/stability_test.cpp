// The stability campaign (issue #8): every method of `mcdenoise denoise`, run in-process
// with its defaults and with the options at and beyond their ranges, on stiff and extreme
// frames. Every run must either give a finite image of the frame's size or refuse with a
// message that names the offending layer; none may crash or return NaN/Inf. Each case is
// a small frame rendered with every layer group, then damaged, so every method has what
// it needs except what the case takes away.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <tuple>
#include <utility>
#include <vector>

#include "harness/errors.h"
#include "harness/gpu_fixture.h"
#include "host/api/device.h"
#include "mcdenoise/mcdenoise.h"
#include "tools/render/renderer.h"

namespace mcd::test {
namespace {

using Params = std::vector<std::pair<std::string, ParamValue>>;

enum class Expect {
    Finite,           // must run and give finite output
    Refused,          // must be refused, naming `names`
    FiniteOrRefused,  // either, but refusal must name `names`
};

struct Case {
    std::string name;
    int width = 13, height = 11;
    std::function<void(Frame &)> damage;  // null: the rendered frame as is
    Expect expect = Expect::Finite;
    std::string names;  // what a refusal must mention; '|' separates alternatives (per method)
    std::map<std::string, Params> options;  // per method: parameters set
};

Frame RenderedFrame(int width, int height, int spp = 4) {
    static std::map<std::tuple<int, int, int>, Frame> cache;
    auto key = std::make_tuple(width, height, spp);
    if (!cache.count(key)) {
        render::RenderOptions o;
        o.width = width, o.height = height, o.spp = spp;
        o.layers = render::kLayersAll;
        render::RenderResult r = render::Render(render::BuildScene("cornell"), o);
        Frame frame;
        frame.path = fmt::format("cornell {}x{} at {} spp", width, height, spp);
        frame.width = width, frame.height = height;
        for (auto &[name, image] : r.layers) frame.layers[name] = std::move(image);
        cache[key] = frame;
    }
    return cache[key];
}

// Whether `error` mentions one of the '|'-separated alternatives in `names`.
bool NamesAny(const std::string &error, const std::string &names) {
    size_t start = 0;
    while (true) {
        size_t bar = names.find('|', start);
        if (Contains(error, names.substr(start, bar - start))) return true;
        if (bar == std::string::npos) return false;
        start = bar + 1;
    }
}

void Fill(Image &image, float value) {
    std::fill(image.data.begin(), image.data.end(), value);
}

std::vector<Case> Cases() {
    std::vector<Case> cases;
    auto add = [&](Case c) { cases.push_back(std::move(c)); };
    add({"clean 13x11"});
    for (auto [w, h] : {std::pair{1, 1}, {1, 9}, {9, 1}, {2, 2}, {63, 5}, {65, 3}, {57, 2}})
        add({fmt::format("size {}x{}", w, h), w, h});
    add({"NaN color pixel", 13, 11, [](Frame &f) { f.layers["color"].At(1, 5, 7) = NAN; },
         Expect::FiniteOrRefused,  // bayes with direct/indirect does not read color
         "layer 'color' of cornell 13x11 at 4 spp has 1 NaN/Inf value, the "
         "first at pixel (7, 5), channel 1"});
    add({"NaN color pixel, zero",
         13,
         11,
         [](Frame &f) { f.layers["color"].At(1, 5, 7) = NAN; },
         Expect::Finite,
         "",
         {{"awr", Params{{"non-finite", std::string("zero")}}},
          {"bayes", Params{{"non-finite", std::string("zero")}}},
          {"pivot", Params{{"non-finite", std::string("zero")}}},
          {"rhf", Params{{"non-finite", std::string("zero")}}}}});
    add({"Inf color pixel", 13, 11, [](Frame &f) { f.layers["color"].At(0, 0, 0) = INFINITY; },
         Expect::FiniteOrRefused, "the first at pixel (0, 0), channel 0"});
    add({"negative color", 13, 11, [](Frame &f) { f.layers["color"].At(2, 3, 3) = -5.f; },
         Expect::FiniteOrRefused, "negative value at pixel (3, 3)"});
    add({"all zero", 13, 11, [](Frame &f) {
             for (auto &[name, image] : f.layers)
                 if (name != "spp") Fill(image, 0.f);
         }});
    add({"constant", 13, 11, [](Frame &f) {
             Fill(f.layers["color"], 0.5f);
             Fill(f.layers["variance"], 0.01f);
         }});
    add({"range 1e-8..1e8", 13, 11, [](Frame &f) {
             Image &c = f.layers["color"];
             for (size_t i = 0; i < c.data.size(); ++i) c.data[i] = i % 2 ? 1e-8f : 1e8f;
         }});
    add({"firefly 1e6 x mean", 13, 11, [](Frame &f) {
             Image &c = f.layers["color"];
             double mean = 0;
             for (float v : c.data) mean += v;
             mean /= double(c.data.size());
             for (int ch = 0; ch < 3; ++ch) c.At(ch, 6, 6) = float(1e6 * mean);
         }});
    add({"variance zero", 13, 11, [](Frame &f) { Fill(f.layers["variance"], 0.f); }});
    add({"variance 1e30", 13, 11, [](Frame &f) { Fill(f.layers["variance"], 1e30f); }});
    add({"variance 3e38", 13, 11, [](Frame &f) { Fill(f.layers["variance"], 3e38f); }});
    add({"NaN variance", 13, 11, [](Frame &f) { f.layers["variance"].At(0, 2, 2) = NAN; },
         Expect::FiniteOrRefused,
         "layer 'variance' of cornell 13x11 at 4 spp has 1 NaN/Inf "
         "value, the first at pixel (2, 2)"});
    add({"zero-sample pixels", 13, 11, [](Frame &f) {
             for (int x = 0; x < 13; ++x) {
                 f.layers["spp"].At(0, 4, x) = 0;
                 for (const char *layer : {"color", "variance", "min", "max"})
                     for (int c = 0; c < 3; ++c) f.layers[layer].At(c, 4, x) = 0;
                 Image &hist = f.layers["hist"];  // empty histograms, zero count
                 for (int c = 0; c < hist.channels; ++c) hist.At(c, 4, x) = 0;
             }
         }});
    add({"1 spp", 13, 11, [](Frame &f) { f = RenderedFrame(13, 11, 1); }});
    add({"color only", 13, 11,
         [](Frame &f) {
             for (auto it = f.layers.begin(); it != f.layers.end();)
                 it = it->first == "color" ? std::next(it) : f.layers.erase(it);
         },
         Expect::FiniteOrRefused, "needs a variance layer|Bin_0000|needs a pivot layer"});
    add({"awr cs 0", 13, 11, nullptr, Expect::Finite, "", {{"awr", Params{{"cs", 0.f}}}}});
    add({"awr cs 100", 13, 11, nullptr, Expect::Finite, "", {{"awr", Params{{"cs", 100.f}}}}});
    add({"awr 0 levels",
         13,
         11,
         nullptr,
         Expect::Finite,
         "",
         {{"awr", Params{{"levels", 0}}}}});
    add({"awr too many levels",
         13,
         11,
         nullptr,
         Expect::Refused,
         "levels",
         {{"awr", Params{{"levels", 9}}}}});
    add({"awr renorm 1e-6",
         13,
         11,
         nullptr,
         Expect::Finite,
         "",
         {{"awr", Params{{"renorm", 1e-6f}}}}});
    add({"awr renorm 1e6",
         13,
         11,
         nullptr,
         Expect::Finite,
         "",
         {{"awr", Params{{"renorm", 1e6f}}}}});
    add({"awr range variance",
         13,
         11,
         nullptr,
         Expect::Finite,
         "",
         {{"awr", Params{{"variance", std::string("range")}}}}});
    for (const auto &[label, options] : std::vector<std::pair<std::string, Params>>{
             {"--pn 0.3", Params{{"pn", 0.3f}}},
             {"--pn 4", Params{{"pn", 4.f}}},
             {"--pn 0.1", Params{{"pn", 0.1f}}},
             {"--pn 10", Params{{"pn", 10.f}}},
             {"--sn 0", Params{{"sn", 0.f}}},
             {"--sn 1000", Params{{"sn", 1000.f}}},
             {"--noise auto", Params{{"noise", std::string("auto")}}},
             {"--bayes-levels 0", Params{{"bayes-levels", 0}}},
             {"--spins 3", Params{{"spins", 3}}},
             {"--colour opponent", Params{{"colour", std::string("opponent")}}},
             {"--zeros denoise --keep-mean",
              Params{{"zeros", std::string("denoise")}, {"keep-mean", true}}},
             {"--log-floor 1e-12", Params{{"log-floor", 1e-12f}}},
             {"--hp-factor 1000", Params{{"hp-factor", 1000.f}}}})
        add({fmt::format("bayes {}", label),
             13,
             11,
             nullptr,
             Expect::Finite,
             "",
             {{"bayes", options}}});
    for (const auto &[label, options] : std::vector<std::pair<std::string, Params>>{
             {"--kappa 0", Params{{"kappa", 0.f}}},
             {"--kappa 1e30", Params{{"kappa", 1e30f}}},
             {"--knn 0", Params{{"knn", 0}}},
             {"--search-half 20", Params{{"search-half", 20}}},
             {"--patch-half 20", Params{{"patch-half", 20}}},
             {"--patch-half 0", Params{{"patch-half", 0}}},
             {"--nscales 8", Params{{"nscales", 8}}},
             {"--kappa 0 --knn 1", Params{{"kappa", 0.f}, {"knn", 1}}}})
        add({fmt::format("rhf {}", label),
             13,
             11,
             nullptr,
             Expect::Finite,
             "",
             {{"rhf", options}}});
    // kNN beyond the search window is refused, naming it.
    for (const auto &[label, options] : std::vector<std::pair<std::string, Params>>{
             {"--knn 1681", Params{{"knn", 1681}}},
             {"--search-half 0", Params{{"search-half", 0}}}})
        add({fmt::format("rhf {}", label),
             13,
             11,
             nullptr,
             Expect::Refused,
             "kNN",
             {{"rhf", options}}});
    add({"rhf NaN histogram bin", 13, 11, [](Frame &f) { f.layers["hist"].At(5, 3, 3) = NAN; },
         Expect::FiniteOrRefused, "hist|Bin"});
    add({"bayes too many levels",
         13,
         11,
         nullptr,
         Expect::FiniteOrRefused,
         "levels",
         {{"bayes", Params{{"bayes-levels", 9}}}}});
    add({"bayes auto on 1e-8..1e8",
         13,
         11,
         [](Frame &f) {
             Image &c = f.layers["color"];
             for (size_t i = 0; i < c.data.size(); ++i) c.data[i] = i % 3 ? 1e-8f : 1e8f;
         },
         Expect::Finite,
         "",
         {{"bayes", Params{{"noise", std::string("auto")}}}}});
    for (const auto &[label, options] : std::vector<std::pair<std::string, Params>>{
             {"--filter bilateral", Params{{"filter", std::string("bilateral")}}},
             {"--max-radius 2", Params{{"max-radius", 2}}},
             {"--max-radius 64", Params{{"max-radius", 64}}},
             {"--target-noise 0", Params{{"target-noise", 0.f}}},
             {"--disagreement 0", Params{{"disagreement", 0.f}}},
             {"--sigma-weight 1 --good-noise 1e-6",
              Params{{"sigma-weight", 1.f}, {"good-noise", 1e-6f}}},
             {"--robust-k 1e6", Params{{"robust-k", 1e6f}}},
             {"--guides none --pivot-noise estimate",
              Params{{"guides", std::string("none")},
                     {"pivot-noise", std::string("estimate")}}},
             {"--pivot-floor 1e6", Params{{"pivot-floor", 1e6f}}},
             {"--filter bilateral --bilateral-radius 0",
              Params{{"filter", std::string("bilateral")}, {"bilateral-radius", 0}}}})
        add({fmt::format("pivot {}", label),
             13,
             11,
             nullptr,
             Expect::Finite,
             "",
             {{"pivot", options}}});
    return cases;
}

// One run: a case on one method (cases that set parameters run only on their methods).
struct Run {
    size_t index;
    std::string method;
};

std::vector<Run> Runs() {
    std::vector<Run> runs;
    std::vector<Case> cases = Cases();
    for (size_t i = 0; i < cases.size(); ++i)
        for (const std::string &method : MethodNames())
            if (cases[i].options.empty() || cases[i].options.count(method))
                runs.push_back({i, method});
    return runs;
}

std::string RunName(const testing::TestParamInfo<Run> &info) {
    std::string name = Cases()[info.param.index].name + "_" + info.param.method;
    for (char &c : name)
        if (!std::isalnum((unsigned char)c)) c = '_';
    return fmt::format("{:03}_{}", info.index, name);
}

class StabilityCampaign : public GpuTest, public testing::WithParamInterface<Run> {};

TEST_P(StabilityCampaign, FiniteOrRefusedByName) {
    const Case c = Cases()[GetParam().index];
    Method method(GetParam().method);
    if (c.options.count(method.Name()))
        for (const auto &[name, value] : c.options.at(method.Name())) method.Set(name, value);
    Frame frame = RenderedFrame(c.width, c.height);
    if (c.damage) c.damage(frame);
    Device device = api::BorrowDevice(Ctx());
    std::string outcome;
    try {
        Result result = method.Run(device, frame);
        const Image &color = frame.Get("color");
        ASSERT_EQ(result.image.width, color.width);
        ASSERT_EQ(result.image.height, color.height);
        size_t bad = 0;
        for (float v : result.image.data) bad += !std::isfinite(v);
        EXPECT_EQ(bad, 0u) << "non-finite output values";
        EXPECT_NE(c.expect, Expect::Refused) << "ran where it should refuse";
        outcome = bad ? "NON-FINITE" : "finite";
    } catch (const Error &e) {
        std::string error = e.what();
        EXPECT_NE(c.expect, Expect::Finite) << "refused: " << error;
        EXPECT_TRUE(NamesAny(error, c.names)) << error;
        // A refused input is the input's failure, never one of the library's.
        EXPECT_NE(e.Kind(), ErrorKind::Internal) << error;
        outcome = "refused: " + error;
    }
    std::printf("[stability] %-22s %-6s %s\n", c.name.c_str(), method.Name().c_str(),
                outcome.c_str());
}

INSTANTIATE_TEST_SUITE_P(Cases, StabilityCampaign, testing::ValuesIn(Runs()), RunName);

}  // namespace
}  // namespace mcd::test
