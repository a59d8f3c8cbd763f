// Every kernel has a kernel-vs-reference case of its own, found by name: the cases of
// kernel <family>/<kernel> (shaders/<family>/<kernel>.comp) are the suite
// <Family><Kernel>Kernel (rhf/terms: RhfTermsKernel; parametrised: <Prefix>/RhfTermsKernel),
// each part of the path capitalised at '/' and '_'. The list of kernels comes from the
// build (cmake/Shaders.cmake); tests/kernels/kernel_coverage_test.cpp fails naming every
// kernel whose suite has no test. A check in every test process keeps the names honest:
// each test of a kernel's suite must dispatch that kernel, and no other one (its inputs
// are made on the CPU; the one exception, a Record function that records a second kernel,
// is listed in kernel_cases.cpp), or it fails.
#pragma once

#include <span>
#include <string>
#include <string_view>

namespace mcd::test {

// Every kernel the build compiles, as <family>/<kernel>, sorted.
std::span<const std::string_view> AllKernels();

// The suite that holds a kernel's cases: "rhf/terms" -> "RhfTermsKernel".
std::string KernelSuiteName(std::string_view kernel);

// The name the kernel's Record function gives its vk::KernelDesc, under which the context
// counts its dispatches: "rhf/terms" -> "rhf_terms".
std::string KernelDispatchName(std::string_view kernel);

// The kernel whose suite `suite` is ("RhfTermsKernel" or "Cases/RhfTermsKernel"), or empty.
std::string_view KernelOfSuite(std::string_view suite);

// Whether the per-test check of the kernels' suites is installed in this process.
bool KernelCaseCheckInstalled();

}  // namespace mcd::test
