#include "harness/kernel_cases.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cctype>
#include <cstdint>
#include <map>
#include <string>

#include "host/vk/dispatch_count.h"
#include "kernel_list.h"

namespace mcd::test {

std::span<const std::string_view> AllKernels() {
    return kKernels;
}

std::string KernelSuiteName(std::string_view kernel) {
    std::string name;
    bool upper = true;
    for (char c : kernel) {
        if (c == '/' || c == '_') {
            upper = true;
            continue;
        }
        name += upper ? char(std::toupper(uint8_t(c))) : c;
        upper = false;
    }
    return name + "Kernel";
}

std::string KernelDispatchName(std::string_view kernel) {
    std::string name(kernel);
    for (char &c : name)
        if (c == '/') c = '_';
    return name;
}

std::string_view KernelOfSuite(std::string_view suite) {
    // A value-parametrised suite is registered as <Prefix>/<Suite>.
    if (size_t slash = suite.rfind('/'); slash != std::string_view::npos)
        suite.remove_prefix(slash + 1);
    for (std::string_view kernel : kKernels)
        if (KernelSuiteName(kernel) == suite) return kernel;
    return {};
}

namespace {

// Kernels whose Record function records another kernel too, which their cases may then
// dispatch: RecordWaveletSynthesizeShrink's rows pass is the plain synthesis's,
// RecordNforGlintNoise's gate rows are RecordNforGlintRows's.
std::string_view CompanionOf(std::string_view kernel) {
    return kernel == "wavelet/synthesize_shrink" ? "wavelet_synthesize"
           : kernel == "nfor/glint"              ? "nfor_glint_rows"
                                                 : "";
}

// Checks after each test of a kernel's suite that the test dispatched that kernel, and
// only it: a case named after a kernel that runs another one, or none, fails with what it
// did run.
class KernelCaseCheck : public ::testing::EmptyTestEventListener {
  public:
    void OnTestStart(const ::testing::TestInfo &info) override {
        kernel = KernelOfSuite(info.test_suite_name());
        if (!kernel.empty()) before = vk::DispatchCounts();
    }

    void OnTestEnd(const ::testing::TestInfo &info) override {
        if (kernel.empty() || info.result()->Skipped()) return;
        const std::string own = KernelDispatchName(kernel);
        uint64_t ownCount = 0;
        std::string others;
        for (const auto &[name, count] : vk::DispatchCounts()) {
            auto it = before.find(name);
            uint64_t added = count - (it == before.end() ? 0 : it->second);
            if (added == 0) continue;
            if (name == own)
                ownCount = added;
            else if (name != CompanionOf(kernel))
                others += fmt::format("{}{} x{}", others.empty() ? "" : ", ", name, added);
        }
        if (ownCount == 0)
            ADD_FAILURE() << fmt::format(
                "{}.{} is in the suite of kernel {} but never dispatched it{}",
                info.test_suite_name(), info.name(), kernel,
                others.empty() ? "" : " (it dispatched " + others + ")");
        else if (!others.empty())
            ADD_FAILURE() << fmt::format(
                "{}.{} is in the suite of kernel {}, whose cases record it alone on inputs "
                "made on the CPU, but it also dispatched {}",
                info.test_suite_name(), info.name(), kernel, others);
    }

  private:
    std::string_view kernel;
    std::map<std::string, uint64_t> before;
};

// Appended when the tests start (after the flags have set the result printer, so that the
// printer reports the failures it adds), by an environment registered when this file is
// linked in: kernel_coverage_test.cpp calls KernelCaseCheckInstalled, so every process of
// mcd_tests has it.
struct KernelCaseCheckInstaller : ::testing::Environment {
    void SetUp() override {
        if (appended) return;  // SetUp runs again with every --gtest_repeat
        ::testing::UnitTest::GetInstance()->listeners().Append(new KernelCaseCheck);
        appended = true;
    }
    bool appended = false;
};
const bool installed =
    ::testing::AddGlobalTestEnvironment(new KernelCaseCheckInstaller) != nullptr;

}  // namespace

bool KernelCaseCheckInstalled() {
    return installed;
}

}  // namespace mcd::test
