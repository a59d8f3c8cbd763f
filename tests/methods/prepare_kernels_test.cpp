// Kernels made ahead of a run (FrontEnd::PrepareKernels, Context::PrepareKernel): a method
// lists before its run exactly the kernels the run records on that frame (none left to
// build on the run's way, none for a layer the frame lacks), auto makes its candidates'
// ahead, and the build threads take those asked for now first.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <tuple>
#include <utility>
#include <vector>

#include "harness/frames.h"
#include "host/api/front_end.h"
#include "host/api/method_auto.h"
#include "host/api/registry.h"
#include "host/vk/build_pool.h"
#include "host/vk/context.h"
#include "mcdenoise/mcdenoise.h"
#include "tools/render/renderer.h"

namespace mcd::test {
namespace {

using Params = std::vector<std::pair<std::string, ParamValue>>;

// Cornell at 4 spp with the given layer groups, without the layers named in `drop`.
Frame CornellFrame(int width, int height, int layers, const std::vector<std::string> &drop) {
    render::RenderOptions options;
    options.width = width, options.height = height, options.spp = 4;
    options.layers = layers;
    Frame frame = RenderedFrame("cornell", options);
    frame.path = "cornell";
    for (const std::string &name : drop) frame.layers.erase(name);
    return frame;
}

std::set<std::string> KeysOf(const vk::Context &context) {
    std::vector<std::string> keys = context.KernelKeys();
    return {keys.begin(), keys.end()};
}

// The keys a method makes ahead on the frame, on a fresh context, and those its run asks
// for, on another.
std::pair<std::set<std::string>, std::set<std::string>> PreparedAndRun(const std::string &name,
                                                                       const Frame &frame,
                                                                       const Params &params) {
    std::unique_ptr<api::FrontEnd> method = api::FindMethod(name)->make();
    for (const auto &[param, value] : params) method->Set(param, value);
    std::set<std::string> prepared, ran;
    {
        vk::Context context(vk::ContextOptions{.pipelineThreads = 2});
        api::Inputs inputs(frame, false, name);
        method->PrepareKernels(context, inputs);
        prepared = KeysOf(context);
        EXPECT_EQ(context.Pipelines().prepared, int(prepared.size()));
    }
    {
        vk::Context context(vk::ContextOptions{.pipelineThreads = 2});
        api::Inputs inputs(frame, false, name);
        method->Run(context, inputs, RunOptions());
        ran = KeysOf(context);
    }
    return {prepared, ran};
}

struct PrepareCase {
    std::string method;
    int layers;
    std::vector<std::string> drop;
    Params params;
};

TEST(PrepareKernels, MethodsListExactlyTheKernelsTheirRunRecords) {
    using render::kLayersAll;
    const std::vector<PrepareCase> cases = {
        {"rhf", kLayersAll, {}, {}},
        {"rhf", kLayersAll, {}, {{"nscales", 2}}},
        {"rhf", kLayersAll, {}, {{"bright-pool", 0.f}}},
        {"pivot", kLayersAll, {}, {}},
        {"pivot", kLayersAll, {}, {{"guides", std::string("none")}}},
        {"pivot", kLayersAll, {"objectId", "partId"}, {}},
        {"pivot", kLayersAll, {"normal"}, {}},
        {"pivot", kLayersAll, {"variance"}, {{"pivot-edge", 0.f}}},
        {"pivot", kLayersAll, {"variance"}, {{"pivot-range", 0}, {"pivot-bound", 0.f}}},
        {"pivot", kLayersAll, {}, {{"filter", std::string("bilateral")}}},
    };
    for (const PrepareCase &c : cases) {
        // 37 x 29: no multiple of a block or a kernel's group.
        const Frame frame = CornellFrame(37, 29, c.layers, c.drop);
        auto [prepared, ran] = PreparedAndRun(c.method, frame, c.params);
        std::string what = c.method;
        for (const std::string &layer : c.drop) what += " without " + layer;
        for (const auto &[param, value] : c.params)
            what += " --" + param + " " + api::ParamValueText(value);
        EXPECT_FALSE(prepared.empty()) << what;
        EXPECT_EQ(prepared, ran) << what;
    }
}

// auto makes every candidate's kernels ahead before the first runs, and each of them is one a
// run then asked for; under a budget of the user's it makes none.
TEST(PrepareKernels, AutoMakesItsCandidatesKernelsAhead) {
    const Frame frame = CornellFrame(37, 29, render::kLayersAll, {});
    auto run = [&](bool budget) {
        vk::Context context(vk::ContextOptions{.pipelineThreads = 2});
        api::AutoFrontEnd method;
        if (budget) method.Set("budget", 3600.f);
        api::Inputs inputs(frame, false, "auto");
        method.Run(context, inputs, RunOptions());
        int rhfPivot = 0;
        for (const std::string &key : context.KernelKeys())
            if (key.rfind("rhf_", 0) == 0 || key.rfind("pivot_", 0) == 0) ++rhfPivot;
        return std::make_tuple(context.Pipelines().prepared, context.Pipelines().preparedUsed,
                               rhfPivot);
    };
    auto [prepared, used, rhfPivot] = run(false);
    EXPECT_GT(rhfPivot, 0);
    EXPECT_EQ(prepared, rhfPivot);
    EXPECT_EQ(used, prepared);
    auto [preparedUnderBudget, usedUnderBudget, rhfPivotUnderBudget] = run(true);
    EXPECT_EQ(preparedUnderBudget, 0);
    EXPECT_EQ(rhfPivotUnderBudget, rhfPivot);
}

// Two workers, each held by a task until its gate opens; the tasks queued after them run in
// the order `order` records, on the one worker released.
struct HeldPool {
    vk::BuildPool pool{2};
    std::promise<void> gates[2];
    std::atomic<int> held{0};
    std::mutex mutex;
    std::vector<std::string> order;

    HeldPool() {
        for (std::promise<void> &gate : gates) {
            std::shared_future<void> open = gate.get_future().share();
            pool.Run([this, open] {
                ++held;
                open.wait();
            });
        }
        while (held < 2) std::this_thread::yield();
    }
    ~HeldPool() {
        Open(0);
        Open(1);
        pool.Wait();
    }
    void Open(int gate) {
        if (!opened[gate]) gates[gate].set_value();
        opened[gate] = true;
    }
    std::function<void()> Note(std::string name) {
        return [this, name] {
            std::lock_guard<std::mutex> lock(mutex);
            order.push_back(name);
        };
    }
    // What has run by the time `expected` tasks have, or by a deadline (an ordering bug
    // fails the test rather than hanging it).
    std::vector<std::string> RunOn() {
        Open(0);
        // The first worker runs the queue; the second stays held.
        auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
        while (true) {
            {
                std::lock_guard<std::mutex> lock(mutex);
                if (order.size() >= expected || std::chrono::steady_clock::now() > deadline)
                    return order;
            }
            std::this_thread::yield();
        }
    }
    bool opened[2] = {false, false};
    size_t expected = 0;
};

TEST(PrepareKernels, BuildPoolTakesTasksAskedForNowBeforeThoseAhead) {
    HeldPool held;
    uint64_t a = 0, b = 0;
    held.pool.Run(held.Note("ahead 1"), true, &a);
    held.pool.Run(held.Note("ahead 2"), true, &b);
    held.pool.Run(held.Note("now"));
    held.pool.Hasten(b);
    EXPECT_NE(a, 0u);
    held.expected = 3;
    EXPECT_EQ(held.RunOn(), (std::vector<std::string>{"now", "ahead 2", "ahead 1"}));
}

TEST(PrepareKernels, BuildPoolRunsATaskNoWorkerTookInTheCaller) {
    HeldPool held;
    uint64_t ticket = 0;
    std::thread::id ranOn;
    auto note = held.Note("here");
    std::shared_future<void> done = held.pool.Run(
        [&] {
            ranOn = std::this_thread::get_id();
            note();
        },
        true, &ticket);
    held.pool.RunHere(ticket);
    ASSERT_EQ(done.wait_for(std::chrono::seconds(0)), std::future_status::ready);
    EXPECT_EQ(ranOn, std::this_thread::get_id());
    held.pool.RunHere(ticket);  // taken already: nothing
    // The task ran once, here: the worker released runs only the one queued after it.
    held.pool.Run(held.Note("next"), true);
    held.expected = 2;
    EXPECT_EQ(held.RunOn(), (std::vector<std::string>{"here", "next"}));
}

// Whether `pool`'s Wait returns within a few seconds; a Wait still blocked is left behind.
bool WaitsWithin(vk::BuildPool &pool) {
    auto returned = std::make_shared<std::promise<void>>();
    std::future<void> done = returned->get_future();
    std::thread waiter([&pool, returned] {
        pool.Wait();
        returned->set_value();
    });
    if (done.wait_for(std::chrono::seconds(10)) != std::future_status::ready) {
        waiter.detach();
        return false;
    }
    waiter.join();
    return true;
}

TEST(PrepareKernels, BuildPoolRunHereKeepsATasksErrorForItsWaiter) {
    auto held = std::make_unique<HeldPool>();
    uint64_t ticket = 0;
    std::shared_future<void> done =
        held->pool.Run([] { throw std::runtime_error("build failed"); }, true, &ticket);
    held->pool.RunHere(ticket);
    ASSERT_EQ(done.wait_for(std::chrono::seconds(0)), std::future_status::ready);
    EXPECT_THROW(done.get(), std::runtime_error);
    // Once the held workers go, nothing counts as running.
    held->Open(0);
    held->Open(1);
    if (!WaitsWithin(held->pool)) {
        held.release();  // its Wait would block too: left, not destroyed
        FAIL() << "Wait did not return after a task run here threw";
    }
}

TEST(PrepareKernels, BuildPoolDropsATaskNoWorkerTook) {
    HeldPool held;
    uint64_t ticket = 0;
    std::shared_future<void> done = held.pool.Run(held.Note("dropped"), true, &ticket);
    held.pool.Drop(ticket);
    // Ready at once, without the task: its promise is broken.
    ASSERT_EQ(done.wait_for(std::chrono::seconds(0)), std::future_status::ready);
    try {
        done.get();
        ADD_FAILURE() << "a dropped task's future holds no error";
    } catch (const std::future_error &error) {
        EXPECT_EQ(error.code(), std::future_errc::broken_promise);
    }
    held.pool.Drop(ticket);  // gone already: nothing
    // Queued ahead after it: the worker released would run the dropped task first.
    held.pool.Run(held.Note("next"), true);
    held.expected = 1;
    EXPECT_EQ(held.RunOn(), (std::vector<std::string>{"next"}));
}

}  // namespace
}  // namespace mcd::test
