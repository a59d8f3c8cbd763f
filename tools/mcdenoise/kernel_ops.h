// Floating-point operations of a kernel's dispatch, from the kernel's loop structure and
// the dispatch's push constants, grid and specialization constants: one formula per kernel
// (kernel_ops.cpp; nfor's in kernel_ops_nfor.cpp), and docs/performance.md lists what each
// counts. Each operator the source writes counts once: an add, subtract, multiply, divide,
// square root, min or max one, a multiply-add two, a transcendental (exp, log, exp2, log2,
// sinh, asinh) one; negation, abs, a multiply by a constant sign, comparisons, selects,
// conversions, integer index arithmetic, loads, stores and branches none. Loops over the
// frame count their in-frame steps exactly; where a kernel skips work by its data (a zero
// weight, an emitter, a bin no pair counts) the rule says which path is counted and the
// bound says what that makes the count. `bench kernels` sets them against the device's
// calibrated rate.
#pragma once

#include <optional>
#include <string>

#include "host/vk/dispatch_count.h"

namespace mcd::tool {

// What a count is where the kernel's work depends on its data: the work done (Exact), at
// most it (AtMost: the count takes no data-dependent shortcut) or at least it (AtLeast).
enum class OpsBound { Exact, AtMost, AtLeast };

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

// How the formula of `kernel` bounds its work (Exact for a kernel without one).
OpsBound KernelFlopsBound(const std::string &kernel);

}  // namespace mcd::tool
