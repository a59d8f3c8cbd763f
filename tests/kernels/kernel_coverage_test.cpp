// Every kernel the build compiles has a kernel-vs-reference case of its own: a suite named
// after it by the rule of harness/kernel_cases.h, holding at least one test that is not
// disabled. The per-test check installed with the harness makes sure those tests dispatch
// their kernel alone.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "harness/kernel_cases.h"

namespace mcd::test {
namespace {

// Tests per suite, parametrised prefixes stripped, disabled tests left out.
std::map<std::string, int> EnabledTestsPerSuite() {
    std::map<std::string, int> tests;
    const ::testing::UnitTest &unit = *::testing::UnitTest::GetInstance();
    for (int i = 0; i < unit.total_test_suite_count(); ++i) {
        const ::testing::TestSuite &suite = *unit.GetTestSuite(i);
        std::string name = suite.name();
        if (size_t slash = name.rfind('/'); slash != std::string::npos)
            name.erase(0, slash + 1);
        for (int j = 0; j < suite.total_test_count(); ++j)
            if (std::string(suite.GetTestInfo(j)->name()).rfind("DISABLED_", 0) != 0)
                tests[name] += 1;
    }
    return tests;
}

TEST(KernelCoverage, EveryKernelHasACaseOfItsOwn) {
    ASSERT_TRUE(KernelCaseCheckInstalled());
    ASSERT_FALSE(AllKernels().empty());
    std::map<std::string, int> tests = EnabledTestsPerSuite();
    std::vector<std::string> missing;
    for (std::string_view kernel : AllKernels()) {
        std::string suite = KernelSuiteName(kernel);
        if (tests[suite] == 0)
            missing.push_back(fmt::format("{} (shaders/{}.comp): no test in suite {} or */{}",
                                          kernel, kernel, suite, suite));
    }
    EXPECT_TRUE(missing.empty()) << fmt::format(
        "{} of {} kernels have no kernel-vs-reference case of their own:\n  {}\nA kernel's "
        "cases record it alone on seeded CPU inputs and diff it against its CPU reference "
        "(tests/harness/kernel_cases.h).",
        missing.size(), AllKernels().size(), fmt::join(missing, "\n  "));
}

// The list the build generated is the shader tree as it is now: every .comp, nothing else.
TEST(KernelCoverage, KernelListIsTheShaderTree) {
    namespace fs = std::filesystem;
    const fs::path shaders = fs::path(MCD_SOURCE_DIR) / "shaders";
    std::vector<std::string> found;
    for (const fs::directory_entry &entry : fs::recursive_directory_iterator(shaders))
        if (entry.is_regular_file() && entry.path().extension() == ".comp")
            found.push_back(fs::relative(entry.path(), shaders).replace_extension().string());
    std::sort(found.begin(), found.end());
    std::vector<std::string> listed(AllKernels().begin(), AllKernels().end());
    EXPECT_EQ(found, listed) << "rerun cmake: the kernel list predates the shader tree";
}

TEST(KernelCoverage, SuiteNamesFollowTheRule) {
    EXPECT_EQ(KernelSuiteName("rhf/terms"), "RhfTermsKernel");
    EXPECT_EQ(KernelSuiteName("bayes/swt_moments"), "BayesSwtMomentsKernel");
    EXPECT_EQ(KernelDispatchName("bayes/swt_moments"), "bayes_swt_moments");
    EXPECT_EQ(KernelOfSuite("Cases/RhfTermsKernel"), "rhf/terms");
    EXPECT_EQ(KernelOfSuite("RhfTermsKernel"), "rhf/terms");
    EXPECT_EQ(KernelOfSuite("RhfTermsKernelLimits"), "");
    EXPECT_EQ(KernelOfSuite("RhfKernel"), "");
}

}  // namespace
}  // namespace mcd::test
