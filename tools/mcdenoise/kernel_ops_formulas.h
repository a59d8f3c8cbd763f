// The pieces kernel_ops.cpp and the per-method formula files share: a formula's record, the
// push constants of a kept dispatch, and counts of the in-frame pairs of a window walk.
#pragma once

#include <algorithm>
#include <cstring>
#include <functional>
#include <map>
#include <string>

#include "host/vk/dispatch_count.h"
#include "tools/mcdenoise/kernel_ops.h"

namespace mcd::tool {

struct Formula {
    std::string rule;
    std::function<double(const vk::KeptDispatch &)> flops;
    OpsBound bound = OpsBound::Exact;
};
using FormulaMap = std::map<std::string, Formula>;

// The push constants as the kernel's struct (zeros where the dispatch gave fewer bytes).
template <typename Push>
Push PushOf(const vk::KeptDispatch &d) {
    Push push{};
    std::memcpy(&push, d.push.data(), std::min(d.push.size(), sizeof(Push)));
    return push;
}

// Pairs (x, u) of positions in [0, n) with |u - x| <= r: a window walk's in-frame steps
// along one axis, summed over the line.
double WindowPairs(int n, int r);

// Triples (x, u, t) with (x, u) as WindowPairs and |t| <= f, x + t and u + t both in
// [0, n): a patch comparison's in-frame steps along one axis.
double PatchTriples(int n, int r, int f);

// nfor's kernels (kernel_ops_nfor.cpp).
const FormulaMap &NforFormulas();

}  // namespace mcd::tool
