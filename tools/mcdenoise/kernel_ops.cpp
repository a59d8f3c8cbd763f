#include "tools/mcdenoise/kernel_ops.h"

#include <cstring>
#include <functional>
#include <map>

#include "bench/fma.h"
#include "host/kernels/bench_calibrate.h"

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
