// What the operation-formula tests (kernel_ops_test.cpp, kernel_ops_nfor_test.cpp) share:
// the dispatches a method records on a small rendered frame, and the check of a kernel's
// formula against a walk of its shader's loops over each recorded dispatch.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "harness/frames.h"
#include "harness/gpu_fixture.h"
#include "host/api/device.h"
#include "host/vk/dispatch_count.h"
#include "mcdenoise/mcdenoise.h"
#include "tools/mcdenoise/kernel_ops.h"
#include "tools/mcdenoise/kernel_ops_formulas.h"
#include "tools/render/renderer.h"

namespace mcd::tool {

// The dispatches of one run of `method` (its parameters set by `configure`, which `variant`
// names) on a 37x29 cornell frame with every
// layer (odd sizes: partial workgroups and border windows), kept per method and variant for the
// process.
inline const std::vector<vk::KeptDispatch> &MethodDispatches(
    const std::string &method, const std::string &variant = "",
    const std::function<void(Method &)> &configure = nullptr,
    const std::vector<std::string> &without = {}) {
    static std::map<std::string, std::vector<vk::KeptDispatch>> runs;
    std::string key = method + " " + variant;
    auto it = runs.find(key);
    if (it != runs.end()) return it->second;
    render::RenderOptions options;
    options.width = 37, options.height = 29, options.spp = 4;
    options.layers = render::kLayersAll;
    Frame frame = test::RenderedFrame("cornell", options);
    for (const std::string &name : without) frame.layers.erase(name);
    Device device = api::BorrowDevice(test::TestContext());
    Method m(method);
    if (configure) configure(m);
    vk::KeepDispatches(true);
    m.Run(device, frame);
    vk::KeepDispatches(false);
    return runs[key] = vk::KeptDispatches();
}

// Call `visit(x, y, z)` for every invocation of `d`'s grid, `localX` invocations wide per
// workgroup (the kernels here are one row of invocations per workgroup).
inline void ForEachInvocation(const vk::KeptDispatch &d, int localX,
                              const std::function<void(int, int, int)> &visit) {
    for (uint32_t z = 0; z < d.timing.groups[2]; ++z)
        for (uint32_t y = 0; y < d.timing.groups[1]; ++y)
            for (uint32_t x = 0; x < d.timing.groups[0] * uint32_t(localX); ++x)
                visit(int(x), int(y), int(z));
}

// Each of `kernel`'s dispatches in `dispatches` (at least one) against its walk.
inline void ExpectFormulaMatchesWalk(
    const std::vector<vk::KeptDispatch> &dispatches, const std::string &kernel,
    const std::function<double(const vk::KeptDispatch &)> &walk) {
    int seen = 0;
    for (const vk::KeptDispatch &d : dispatches) {
        if (d.timing.kernel != kernel) continue;
        ++seen;
        std::optional<double> flops = KernelFlops(d);
        ASSERT_TRUE(flops.has_value()) << kernel << " has no formula";
        EXPECT_EQ(*flops, walk(d))
            << kernel << ", dispatch " << seen << " ('" << d.timing.label << "')";
    }
    EXPECT_GT(seen, 0) << "no " << kernel << " dispatch was recorded: the test checks nothing";
}

}  // namespace mcd::tool
