#include "tools/mcdenoise/kernel_ops.h"

#include <cstring>
#include <functional>
#include <map>

#include "awr/shrink.h"
#include "bench/fma.h"
#include "host/kernels/bench_calibrate.h"
#include "rhf/distance.h"

namespace mcd::tool {
namespace {

// The push constants as the kernel's struct (zeros where the dispatch gave fewer bytes).
template <typename Push>
Push PushOf(const vk::KeptDispatch &d) {
    Push push{};
    std::memcpy(&push, d.push.data(), std::min(d.push.size(), sizeof(Push)));
    return push;
}

struct Formula {
    std::string rule;
    std::function<double(const vk::KeptDispatch &)> flops;
};

const std::map<std::string, Formula> &Formulas() {
    static const std::map<std::string, Formula> formulas = {
        {"bench_fma",
         {"iterations x 4 chains x 4 lanes x 2 (FMA) + 28 per invocation (shaders/bench/fma.h)",
          [](const vk::KeptDispatch &d) {
              auto p = PushOf<shader::BenchFmaPush>(d);
              return BenchFmaFlops(p.count, p.iterations);
          }}},
        {"bench_stream", {"none: a copy", [](const vk::KeptDispatch &) { return 0.0; }}},
        // Per coefficient: sqrt, cs * sqrt, |w| - t, max, sign(w) * (...).
        {"awr_shrink",
         {"5 per coefficient of the grid (the kept low-low band counted too)",
          [](const vk::KeptDispatch &d) {
              auto p = PushOf<shader::AwrShrinkPush>(d);
              return 5.0 * p.width * p.height * d.timing.groups[2];
          }}},
        // Per (centre, offset): the patch's (2w + 1)^2 term pairs each add to the sum and
        // the count, then count + 1e-4 and one divide; every output as an interior one.
        {"rhf_distance",
         {"(2 (2w+1)^2 + 2) per centre and offset, border centres counted as interior ones",
          [](const vk::KeptDispatch &d) {
              auto p = PushOf<shader::RhfDistancePush>(d);
              double side = 2.0 * p.patchHalf + 1;
              return (2 * side * side + 2) * p.width * p.rows * d.timing.groups[2];
          }}},
    };
    return formulas;
}

}  // namespace

std::optional<double> KernelFlops(const vk::KeptDispatch &dispatch) {
    auto it = Formulas().find(dispatch.timing.kernel);
    if (it == Formulas().end()) return std::nullopt;
    return it->second.flops(dispatch);
}

std::string KernelFlopsRule(const std::string &kernel) {
    auto it = Formulas().find(kernel);
    return it == Formulas().end() ? "" : it->second.rule;
}

}  // namespace mcd::tool
