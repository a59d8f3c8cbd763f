// `mcdenoise bench auto`: where auto's time goes on one frame: the pipelines it builds, each
// candidate's run and probe, the noise estimate and the combination's passes, and what is
// left for the host (uploads, downloads, host loops).
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>

#include "host/api/device.h"
#include "host/error.h"
#include "mcdenoise/io.h"
#include "tools/mcdenoise/commands.h"
#include "tools/mcdenoise/method_options.h"
#include "tools/render/renderer.h"

namespace mcd::tool {
namespace {

using Clock = std::chrono::steady_clock;

struct AutoBenchOptions {
    std::string input, size = "256x256", scene = "cornell", layers = "all";
    int spp = 16, repeats = 1, pipelines = 6;
    DeviceOptions device;
    MethodOptions methods;
};

// The frame: read from a file, or rendered with the given layer groups.
Frame BenchFrame(const AutoBenchOptions &opt) {
    if (!opt.input.empty()) return ReadFrame(opt.input);
    render::RenderOptions options;
    ParseSize(opt.size, &options.width, &options.height);
    options.spp = opt.spp;
    options.layers = opt.layers == "all" ? int(render::kLayersAll) : 0;
    if (opt.layers != "all" && opt.layers != "none")
        throw Error("bench auto: --layers is all or none", ErrorKind::InvalidArgument);
    render::RenderResult result = render::Render(render::BuildScene(opt.scene), options);
    Frame frame;
    frame.path = fmt::format("{} {} at {} spp", opt.scene, opt.size, opt.spp);
    for (auto &[name, image] : result.layers) {
        frame.width = image.width, frame.height = image.height;
        frame.layers[name] = std::move(image);
    }
    return frame;
}

// The GPU milliseconds of a run's dispatches by what ran them: the part of the label before
// ": " (a candidate, or its probe), or the kernel's own name (auto's passes).
std::vector<std::pair<std::string, double>> GpuByPart(const Result &result) {
    std::vector<std::pair<std::string, double>> parts;
    for (const Timing &t : result.timings) {
        size_t at = t.label.find(": ");
        std::string part = at == std::string::npos ? t.label : t.label.substr(0, at);
        auto it = std::find_if(parts.begin(), parts.end(),
                               [&](const auto &p) { return p.first == part; });
        if (it == parts.end())
            parts.push_back({part, std::max(t.gpuMs, 0.0)});
        else
            it->second += std::max(t.gpuMs, 0.0);
    }
    return parts;
}

// The pipelines built since `from`, and the slowest of them.
void PrintPipelines(Device &device, size_t from, int slowest) {
    const auto &each = api::ContextOf(device).Pipelines().each;
    std::vector<std::pair<std::string, double>> built(each.begin() + long(from), each.end());
    double total = 0;
    for (const auto &[name, seconds] : built) total += seconds;
    std::sort(built.begin(), built.end(),
              [](const auto &a, const auto &b) { return a.second > b.second; });
    fmt::print("  pipelines: {} built in {:.3f} s;", built.size(), total);
    for (size_t i = 0; i < std::min<size_t>(size_t(std::max(slowest, 0)), built.size()); ++i)
        fmt::print(" {} {:.0f} ms;", built[i].first, built[i].second * 1e3);
    fmt::print("\n");
}

void PrintRun(const Result &result, double wallMs, std::clock_t cpuTicks) {
    double gpu = 0;
    for (const auto &[part, ms] : GpuByPart(result)) {
        fmt::print("    {:<28} {:10.1f} ms GPU\n", part, ms);
        gpu += ms;
    }
    for (const std::string &line : result.plan)
        if (line.rfind("auto: ran ", 0) == 0) fmt::print("    {}\n", line.substr(6));
    fmt::print(
        "  run: {:.1f} ms wall ({:.1f} ms CPU of every thread), {:.1f} ms GPU, {:.1f} ms "
        "neither (pipelines, uploads, downloads, host loops)\n",
        wallMs, 1e3 * double(cpuTicks) / CLOCKS_PER_SEC, gpu, wallMs - gpu);
}

void BenchAuto(const AutoBenchOptions &opt) {
    Method method = opt.methods.Make("auto");
    Clock::time_point start = Clock::now();
    Frame frame = BenchFrame(opt);
    fmt::print("bench auto: {} ({}x{}, {} layers) made in {:.0f} ms\n", frame.path, frame.width,
               frame.height, frame.layers.size(),
               std::chrono::duration<double, std::milli>(Clock::now() - start).count());
    start = Clock::now();
    Device device(opt.device.Options());
    fmt::print("  device {} opened in {:.0f} ms\n", device.Name(),
               std::chrono::duration<double, std::milli>(Clock::now() - start).count());
    for (int r = 0; r <= std::max(opt.repeats, 1); ++r) {
        size_t before = api::ContextOf(device).Pipelines().each.size();
        start = Clock::now();
        std::clock_t cpu = std::clock();
        Result result = method.Run(device, frame);
        double wall = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
        fmt::print("{}:\n", r == 0 ? "first run (builds the pipelines)" : "timed run");
        PrintPipelines(device, before, opt.pipelines);
        PrintRun(result, wall, std::clock() - cpu);
        std::fflush(stdout);
    }
}

}  // namespace

void AddBenchAutoCommand(CLI::App *bench) {
    auto opt = std::make_shared<AutoBenchOptions>();
    CLI::App *command = bench->add_subcommand(
        "auto",
        "Where auto's time goes on a frame: pipelines, each candidate and its probe, the "
        "noise estimate, the combination's passes and the host's share; a first run, then "
        "timed runs in the same process");
    command->add_option("input", opt->input, "a frame (default: render one)")
        ->check(CLI::ExistingFile);
    command->add_option("--size", opt->size, "rendered frame's size WxH")
        ->capture_default_str();
    command->add_option("--scene", opt->scene, "scene to render")->capture_default_str();
    command->add_option("--spp", opt->spp, "samples per pixel")->capture_default_str();
    command->add_option("--layers", opt->layers, "all (every layer group) or none")
        ->capture_default_str();
    command->add_option("--pipelines", opt->pipelines, "how many of the slowest builds to name")
        ->capture_default_str();
    command->add_option("--repeat", opt->repeats, "timed runs after the first")
        ->capture_default_str();
    opt->device.Add(command);
    opt->methods.Add(command, "auto");
    command->callback([opt] { BenchAuto(*opt); });
}

}  // namespace mcd::tool
