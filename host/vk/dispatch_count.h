// Dispatches recorded in this process, by kernel name (KernelDesc::name), over all contexts:
// the tests check with it that a kernel's cases run that kernel (tests/harness/
// kernel_cases.h).
#pragma once

#include <cstdint>
#include <map>
#include <string>

namespace mcd::vk {

void CountDispatch(const std::string &kernel);
std::map<std::string, uint64_t> DispatchCounts();

}  // namespace mcd::vk
