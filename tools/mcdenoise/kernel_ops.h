// Floating-point operations of a kernel's dispatch, from the kernel's loop structure and
// the dispatch's push constants and grid: one formula per kernel, here and nowhere else
// (docs/performance.md lists what each counts). An add, multiply, divide, square root or
// comparison-free min/max counts one, an FMA two; integer index arithmetic, loads, stores
// and branches count none. `bench kernels` sets them against the device's calibrated rate.
#pragma once

#include <optional>
#include <string>

#include "host/vk/dispatch_count.h"

namespace mcd::tool {

// The operations of `dispatch`, or nothing for a kernel without a formula.
std::optional<double> KernelFlops(const vk::KeptDispatch &dispatch);

// The bytes `dispatch` touches where it touches part of the buffers it binds: a wavelet
// level's line pass filters the top-left region of whole-image buffers (each filtered
// position's value read and written once, 4 bytes each, and the variance a
// synthesize-shrink pass reads beside it); an SWT pass reads and writes a few planes of
// all levels' coefficients. Nothing for other kernels: the recorder's count of
// the bound buffers is theirs.
std::optional<double> KernelTouchedBytes(const vk::KeptDispatch &dispatch);

// What the formula of `kernel` counts, in a line (empty for a kernel without one).
std::string KernelFlopsRule(const std::string &kernel);

}  // namespace mcd::tool
