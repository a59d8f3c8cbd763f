// The registry of methods (host/api/registry.h): the lists derived from it agree with it,
// each entry makes its own front end, and auto's variants are well formed (each override a
// parameter of its method, one kernel slot and one map colour each).
#include <gtest/gtest.h>

#include <set>
#include <string>
#include <vector>

#include "host/api/registry.h"
#include "host/methods/auto.h"
#include "mcdenoise/mcdenoise.h"

namespace mcd::test {
namespace {

TEST(MethodRegistry, NamesAndFrontEndsDeriveFromIt) {
    std::vector<std::string> names;
    for (const api::MethodEntry &entry : api::Registry()) {
        names.push_back(entry.name);
        ASSERT_NE(entry.make, nullptr) << entry.name;
        EXPECT_EQ(entry.make()->Name(), entry.name);
        EXPECT_EQ(Method(entry.name).Name(), entry.name);
        EXPECT_EQ(api::FindMethod(entry.name), &entry);
    }
    EXPECT_EQ(MethodNames(), names);
    EXPECT_EQ(std::set<std::string>(names.begin(), names.end()).size(), names.size());
    EXPECT_EQ(api::FindMethod("auto"), nullptr) << "auto combines the registry's methods";
    EXPECT_EQ(Method("auto").Name(), "auto");
}

TEST(MethodRegistry, AutoVariantsAreWellFormed) {
    std::vector<api::RegisteredVariant> variants = api::AutoVariants();
    ASSERT_FALSE(variants.empty());
    EXPECT_LE(variants.size(), size_t(kAutoMaxCandidates));
    std::set<std::string> labels, colours;
    std::set<int> orders;
    for (const api::RegisteredVariant &v : variants) {
        labels.insert(v.variant->label);
        colours.insert(v.variant->colourName);
        orders.insert(v.variant->order);
        // Every override is a parameter of the method, of its type and in its range.
        Method method(v.method->name);
        for (const auto &[param, value] : v.variant->overrides)
            EXPECT_NO_THROW(method.Set(param, value)) << v.variant->label << ": " << param;
    }
    EXPECT_EQ(labels.size(), variants.size()) << "labels name the stages and plan lines";
    EXPECT_EQ(colours.size(), variants.size()) << "one map colour each";
    EXPECT_EQ(orders.size(), variants.size()) << "one run order each";
    for (size_t i = 1; i < variants.size(); ++i)
        EXPECT_LT(variants[i - 1].variant->order, variants[i].variant->order);
    // Each method's own parameters run before its variants; nfor's first run is its noise
    // from the frame, its own parameters (the variance layer) a second candidate after all
    // the others.
    for (const api::MethodEntry &entry : api::Registry()) {
        if (entry.name == "nfor") continue;
        EXPECT_TRUE(entry.variants.size() < 2 || entry.variants.front().overrides.empty())
            << entry.name;
    }
    const api::MethodEntry *nfor = api::FindMethod("nfor");
    ASSERT_EQ(nfor->variants.size(), 2u);
    EXPECT_FALSE(nfor->variants.front().overrides.empty());
    EXPECT_TRUE(nfor->variants.back().overrides.empty());
    EXPECT_EQ(nfor->variants.back().differsWith, std::vector<std::string>{"variance"});
    EXPECT_FALSE(nfor->variants.back().byDefault) << "nfor layer runs where named";
    EXPECT_EQ(variants.back().variant, &nfor->variants.back());
}

// The run order is part of the output: the candidates' order sets the combination's sums.
TEST(MethodRegistry, AutoRunOrderAndPickOrder) {
    std::vector<std::string> labels;
    for (const api::RegisteredVariant &v : api::AutoVariants())
        labels.push_back(v.variant->label);
    EXPECT_EQ(labels, (std::vector<std::string>{
                          "nfor", "rhf", "pivot", "pivot k0", "bayes", "awr", "rhf 2 scales",
                          "pivot no ids", "pivot k0 no ids", "bayes no split", "nfor layer"}));
    // Where the half-buffers weigh them (an accumulated frame): the two nfor candidates and
    // four others; SURE on a variance layer: all but nfor's and the pivot k0 variants; the
    // frame's own estimate: all but nfor's.
    std::vector<std::string> withHalves, withVariance, withOwn;
    for (const api::RegisteredVariant &v : api::AutoVariants()) {
        if (v.variant->estimates & api::AutoVariant::kHalves)
            withHalves.push_back(v.variant->label);
        if (v.variant->estimates & api::AutoVariant::kVariance)
            withVariance.push_back(v.variant->label);
        if (v.variant->estimates & api::AutoVariant::kOwn) withOwn.push_back(v.variant->label);
    }
    EXPECT_EQ(withHalves, (std::vector<std::string>{"nfor", "rhf", "pivot", "rhf 2 scales",
                                                    "pivot no ids", "nfor layer"}));
    EXPECT_EQ(withVariance,
              (std::vector<std::string>{"rhf", "pivot", "bayes", "awr", "rhf 2 scales",
                                        "pivot no ids", "bayes no split"}));
    EXPECT_EQ(withOwn.size(), labels.size() - 2);
    EXPECT_EQ(withOwn.front(), "rhf");
    std::vector<std::string> picks;
    for (const api::MethodEntry *m : api::PickOrder()) picks.push_back(m->name);
    EXPECT_EQ(picks, (std::vector<std::string>{"awr", "rhf", "bayes", "pivot"}));
}

}  // namespace
}  // namespace mcd::test
