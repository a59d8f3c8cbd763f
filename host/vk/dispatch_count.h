// Dispatches recorded in this process, by kernel name (KernelDesc::name), over all contexts:
// the tests check with it that a kernel's cases run that kernel (tests/harness/
// kernel_cases.h). And, while asked to, every submitted dispatch's record with its push
// constants: `bench kernels` derives bytes and operations per pixel from them.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "host/vk/recorder.h"

namespace mcd::vk {

void CountDispatch(const std::string &kernel);
std::map<std::string, uint64_t> DispatchCounts();

// A submitted dispatch: its timing and traffic, the push constants it was given and its
// kernel's specialization constants.
struct KeptDispatch {
    DispatchTiming timing;
    std::vector<uint8_t> push;
    std::vector<std::pair<uint32_t, int32_t>> specialization;  // constant_id, value

    // The value of constant `id`, or `otherwise` where the kernel does not set it.
    int32_t Spec(uint32_t id, int32_t otherwise) const {
        for (auto [at, value] : specialization)
            if (at == id) return value;
        return otherwise;
    }
};
// On: forget the kept dispatches and keep each dispatch recorded from now on (its record
// is kept when its submission completes). Off: stop keeping.
void KeepDispatches(bool on);
bool KeepingDispatches();
void KeepDispatch(KeptDispatch dispatch);
std::vector<KeptDispatch> KeptDispatches();

}  // namespace mcd::vk
