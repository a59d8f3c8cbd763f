// The stability campaign (issue #8): every method of `mcdenoise denoise`, run in-process
// with its defaults and with the options at and beyond their ranges, on stiff and extreme
// frames. Every run must either give a finite image of the frame's size or refuse with a
// message that names the offending layer; none may crash or return NaN/Inf. Each case is
// a small frame rendered with every layer group, then damaged, so every method has what
// it needs except what the case takes away.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <tuple>

#include "harness/errors.h"
#include "harness/gpu_fixture.h"
#include "tools/mcdenoise/denoise_method.h"
#include "tools/render/renderer.h"

namespace mcd::test {
namespace {

enum class Expect {
    Finite,           // must run and give finite output
    Refused,          // must be refused, naming `names`
    FiniteOrRefused,  // either, but refusal must name `names`
};

struct Case {
    std::string name;
    int width = 13, height = 11;
    std::function<void(io::Frame &)> damage;  // null: the rendered frame as is
    Expect expect = Expect::Finite;
    std::string names;  // what a refusal must mention; '|' separates alternatives (per method)
    std::map<std::string, std::string> options;  // per method: extra command-line options
};

io::Frame RenderedFrame(int width, int height, int spp = 4) {
    static std::map<std::tuple<int, int, int>, io::Frame> cache;
    auto key = std::make_tuple(width, height, spp);
    if (!cache.count(key)) {
        render::RenderOptions o;
        o.width = width, o.height = height, o.spp = spp;
        o.layers = render::kLayersAll;
        render::RenderResult r = render::Render(render::BuildScene("cornell"), o);
        io::Frame frame;
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
    add({"NaN color pixel", 13, 11, [](io::Frame &f) { f.layers["color"].At(1, 5, 7) = NAN; },
         Expect::FiniteOrRefused, "color has NaN/Inf at pixel (7, 5)"});
    add({"Inf color pixel", 13, 11,
         [](io::Frame &f) { f.layers["color"].At(0, 0, 0) = INFINITY; },
         Expect::FiniteOrRefused, "color has NaN/Inf at pixel (0, 0)"});
    add({"negative color", 13, 11, [](io::Frame &f) { f.layers["color"].At(2, 3, 3) = -5.f; },
         Expect::FiniteOrRefused, "negative value at pixel (3, 3)"});
    add({"all zero", 13, 11, [](io::Frame &f) {
             for (auto &[name, image] : f.layers)
                 if (name != "spp") Fill(image, 0.f);
         }});
    add({"constant", 13, 11, [](io::Frame &f) {
             Fill(f.layers["color"], 0.5f);
             Fill(f.layers["variance"], 0.01f);
         }});
    add({"range 1e-8..1e8", 13, 11, [](io::Frame &f) {
             Image &c = f.layers["color"];
             for (size_t i = 0; i < c.data.size(); ++i) c.data[i] = i % 2 ? 1e-8f : 1e8f;
         }});
    add({"firefly 1e6 x mean", 13, 11, [](io::Frame &f) {
             Image &c = f.layers["color"];
             double mean = 0;
             for (float v : c.data) mean += v;
             mean /= double(c.data.size());
             for (int ch = 0; ch < 3; ++ch) c.At(ch, 6, 6) = float(1e6 * mean);
         }});
    add({"variance zero", 13, 11, [](io::Frame &f) { Fill(f.layers["variance"], 0.f); }});
    add({"variance 1e30", 13, 11, [](io::Frame &f) { Fill(f.layers["variance"], 1e30f); }});
    add({"variance 3e38", 13, 11, [](io::Frame &f) { Fill(f.layers["variance"], 3e38f); }});
    add({"NaN variance", 13, 11, [](io::Frame &f) { f.layers["variance"].At(0, 2, 2) = NAN; },
         Expect::FiniteOrRefused, "variance has NaN/Inf at pixel (2, 2)"});
    add({"zero-sample pixels", 13, 11, [](io::Frame &f) {
             for (int x = 0; x < 13; ++x) {
                 f.layers["spp"].At(0, 4, x) = 0;
                 for (const char *layer : {"color", "variance", "min", "max"})
                     for (int c = 0; c < 3; ++c) f.layers[layer].At(c, 4, x) = 0;
                 Image &hist = f.layers["hist"];  // empty histograms, zero count
                 for (int c = 0; c < hist.channels; ++c) hist.At(c, 4, x) = 0;
             }
         }});
    add({"1 spp", 13, 11, [](io::Frame &f) { f = RenderedFrame(13, 11, 1); }});
    add({"color only", 13, 11,
         [](io::Frame &f) {
             for (auto it = f.layers.begin(); it != f.layers.end();)
                 it = it->first == "color" ? std::next(it) : f.layers.erase(it);
         },
         Expect::FiniteOrRefused, "needs a variance layer|Bin_0000|needs a pivot layer"});
    add({"awr cs 0", 13, 11, nullptr, Expect::Finite, "", {{"awr", "--cs 0"}}});
    add({"awr cs 100", 13, 11, nullptr, Expect::Finite, "", {{"awr", "--cs 100"}}});
    add({"awr 0 levels", 13, 11, nullptr, Expect::Finite, "", {{"awr", "--levels 0"}}});
    add({"awr too many levels",
         13,
         11,
         nullptr,
         Expect::Refused,
         "levels",
         {{"awr", "--levels 9"}}});
    add({"awr renorm 1e-6", 13, 11, nullptr, Expect::Finite, "", {{"awr", "--renorm 1e-6"}}});
    add({"awr renorm 1e6", 13, 11, nullptr, Expect::Finite, "", {{"awr", "--renorm 1e6"}}});
    add({"awr range variance",
         13,
         11,
         nullptr,
         Expect::Finite,
         "",
         {{"awr", "--variance range"}}});
    for (const char *options :
         {"--pn 0.3", "--pn 4", "--pn 0.1", "--pn 10", "--sn 0", "--sn 1000", "--noise auto",
          "--bayes-levels 0", "--spins 3", "--colour opponent", "--zeros denoise --keep-mean",
          "--log-floor 1e-12", "--hp-factor 1000"})
        add({fmt::format("bayes {}", options),
             13,
             11,
             nullptr,
             Expect::Finite,
             "",
             {{"bayes", options}}});
    for (const char *options :
         {"--kappa 0", "--kappa 1e30", "--knn 0", "--search-half 20", "--patch-half 20",
          "--patch-half 0", "--nscales 8", "--kappa 0 --knn 1"})
        add({fmt::format("rhf {}", options),
             13,
             11,
             nullptr,
             Expect::Finite,
             "",
             {{"rhf", options}}});
    // kNN beyond the search window is refused, naming it.
    for (const char *options : {"--knn 1681", "--search-half 0"})
        add({fmt::format("rhf {}", options),
             13,
             11,
             nullptr,
             Expect::Refused,
             "kNN",
             {{"rhf", options}}});
    add({"rhf NaN histogram bin", 13, 11,
         [](io::Frame &f) { f.layers["hist"].At(5, 3, 3) = NAN; }, Expect::FiniteOrRefused,
         "hist|Bin"});
    add({"bayes too many levels",
         13,
         11,
         nullptr,
         Expect::FiniteOrRefused,
         "levels",
         {{"bayes", "--bayes-levels 9"}}});
    add({"bayes auto on 1e-8..1e8",
         13,
         11,
         [](io::Frame &f) {
             Image &c = f.layers["color"];
             for (size_t i = 0; i < c.data.size(); ++i) c.data[i] = i % 3 ? 1e-8f : 1e8f;
         },
         Expect::Finite,
         "",
         {{"bayes", "--noise auto"}}});
    for (const char *options :
         {"--filter bilateral", "--max-radius 2", "--max-radius 64", "--target-noise 0",
          "--disagreement 0", "--sigma-weight 1 --good-noise 1e-6", "--robust-k 1e6",
          "--guides none --pivot-noise estimate", "--pivot-floor 1e6",
          "--filter bilateral --bilateral-radius 0"})
        add({fmt::format("pivot {}", options),
             13,
             11,
             nullptr,
             Expect::Finite,
             "",
             {{"pivot", options}}});
    return cases;
}

class StabilityCampaign : public GpuTest {};

TEST_F(StabilityCampaign, EveryMethodEveryCase) {
    int tried = 0, passed = 0;
    for (const Case &c : Cases()) {
        for (const tool::DenoiseMethod &listed : tool::DenoiseMethods()) {
            // Options given for other methods only: not this method's case.
            if (!c.options.empty() && !c.options.count(listed.name)) continue;
            SCOPED_TRACE(c.name + " / " + listed.name);
            tool::DenoiseMethod method = listed;
            CLI::App app;
            method.addOptions(&app);
            if (c.options.count(method.name)) app.parse(c.options.at(method.name), false);
            io::Frame frame = RenderedFrame(c.width, c.height);
            if (c.damage) c.damage(frame);
            ++tried;
            std::string outcome, error;
            try {
                tool::DenoiseResult result = method.run(Ctx(), frame);
                const Image &color = frame.Get("color");
                ASSERT_EQ(result.image.width, color.width);
                ASSERT_EQ(result.image.height, color.height);
                size_t bad = 0;
                for (float v : result.image.data) bad += !std::isfinite(v);
                EXPECT_EQ(bad, 0u) << "non-finite output values";
                EXPECT_NE(c.expect, Expect::Refused) << "ran where it should refuse";
                outcome = bad ? "NON-FINITE" : "finite";
                passed += !bad && c.expect != Expect::Refused;
            } catch (const Error &e) {
                error = e.what();
                EXPECT_NE(c.expect, Expect::Finite) << "refused: " << error;
                EXPECT_TRUE(NamesAny(error, c.names)) << error;
                outcome = "refused: " + error;
                passed += c.expect != Expect::Finite && NamesAny(error, c.names);
            }
            std::printf("[stability] %-22s %-6s %s\n", c.name.c_str(), method.name.c_str(),
                        outcome.c_str());
        }
    }
    std::printf("[stability] %d runs, %d as expected\n", tried, passed);
    EXPECT_EQ(passed, tried);
}

}  // namespace
}  // namespace mcd::test
