// `mcdenoise diff`: run a method on the GPU and on the CPU reference, stage by stage, and
// report how far apart they are, so users can check a kernel on their own frames and
// devices. --dump writes both sides of every stage as EXR.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "host/error.h"
#include "host/io/frame.h"
#include "host/metrics.h"
#include "host/wavelet.h"
#include "tools/mcdenoise/commands.h"
#include "tools/mcdenoise/method_options.h"
#include "tools/mcdenoise/path_guard.h"
#include "tools/mcdenoise/usage.h"

namespace mcd::tool {
namespace {

std::string FileName(const std::string &stage) {
    std::string name = stage;
    std::replace_if(
        name.begin(), name.end(), [](char c) { return !std::isalnum(c); }, '-');
    return name;
}

struct DiffOptions {
    std::string input, method = "awr", dump;
    double maxNmse = -1;
    DeviceOptions device;
    MethodOptions methods;
};

// Refuse a stage on one side only: an error of the method.
void CheckStagesPaired(const std::string &method, const std::vector<Stage> &gpu,
                       const std::vector<Stage> &cpu) {
    std::string unpaired;
    for (const Stage &s : gpu)
        if (std::none_of(cpu.begin(), cpu.end(),
                         [&](const Stage &c) { return c.name == s.name; }))
            unpaired += fmt::format(" '{}' (GPU only)", s.name);
    for (const Stage &c : cpu)
        if (std::none_of(gpu.begin(), gpu.end(),
                         [&](const Stage &s) { return c.name == s.name; }))
            unpaired += fmt::format(" '{}' (CPU only)", c.name);
    if (!unpaired.empty())
        throw Error(fmt::format("{}: stages without a twin:{}", method, unpaired),
                    ErrorKind::Internal);
}

// One row per stage, the stages dumped on request; the first stage over --max-nmse, as
// the error to end with ("" when none is).
std::string PrintStages(const DiffOptions &opt, const std::vector<Stage> &gpu,
                        const std::vector<Stage> &cpu) {
    fmt::print("  {:<24} {:>12} {:>16} {:>10}\n", "stage", "NMSE", "max rel error", "parity");
    std::string worst;
    for (const Stage &g : gpu) {
        const Image &c = std::find_if(cpu.begin(), cpu.end(), [&](const Stage &s) {
                             return s.name == g.name;
                         })->image;
        if (!g.image.SameShape(c))
            throw Error(
                fmt::format("diff: stage {} is {}x{}x{} on the GPU, {}x{}x{} on the CPU",
                            g.name, g.image.width, g.image.height, g.image.channels, c.width,
                            c.height, c.channels),
                ErrorKind::Internal);
        ElementDifference e = MeasureDifference(g.image, c);
        fmt::print("  {:<24} {:>12.3g} {:>16.3g} {:>10}\n", g.name, e.nmse, e.maxRel, e.parity);
        if (opt.maxNmse >= 0 && worst.empty() && (e.nmse > opt.maxNmse || e.parity))
            worst = fmt::format(
                "diff: stage {} is off: NMSE {:.3g} (--max-nmse {:.3g}), "
                "{} elements finite on one side only",
                g.name, e.nmse, opt.maxNmse, e.parity);
        if (!opt.dump.empty()) {
            PrepareDirectory(opt.dump);
            std::filesystem::path dir(opt.dump);
            io::WriteExr((dir / (FileName(g.name) + ".gpu.exr")).string(),
                         {{"color", &g.image}});
            io::WriteExr((dir / (FileName(g.name) + ".cpu.exr")).string(), {{"color", &c}});
        }
    }
    return worst;
}

// Why a run left no stage to compare, in one sentence: a frame too small for any wavelet
// level (awr's transform needs a side of 2 pixels), else the reason the plan gives.
Error NothingToCompare(const std::string &method, const io::Frame &frame,
                       const std::vector<std::string> &plan) {
    std::string reason = "no stage ran";
    const std::string leftOut = "left out: ";
    for (const std::string &line : plan)
        if (line.rfind(leftOut, 0) == 0) {
            reason = line.substr(leftOut.size());
            break;
        }
    if (MaxWaveletLevels(frame.width, frame.height) == 0 &&
        reason.find("(0 levels)") != std::string::npos)
        return Error(fmt::format("diff: {} has nothing to compare on '{}': a {}x{} frame is "
                                 "too small for its wavelet transform (at least 2 pixels on a "
                                 "side); diff a larger frame",
                                 method, frame.path, frame.width, frame.height),
                     ErrorKind::InvalidArgument);
    return Error(fmt::format("diff: {} has nothing to compare on '{}': it left out {}", method,
                             frame.path, reason),
                 ErrorKind::InvalidArgument);
}

void RunDiff(const DiffOptions &opt) {
    if (opt.method == "auto")
        throw Error(fmt::format("diff: unknown method 'auto' (methods with stages: {})",
                                MethodOptions::Names()),
                    ErrorKind::InvalidArgument);
    Method method = opt.methods.Make(opt.method);
    // The stages' names come with the run; refuse an input a stage's file could be.
    RefuseInputsInDirectory({{"input", opt.input}}, {"--dump", opt.dump},
                            [](const std::string &name) {
                                return name.ends_with(".gpu.exr") || name.ends_with(".cpu.exr");
                            });
    if (!opt.dump.empty()) CheckDirectory(opt.dump, "--dump");
    CheckInputFile(opt.input);
    io::Frame frame = io::ReadFrame(opt.input);
    Device device(opt.device.Options());
    RunOptions run;
    run.keepStages = true;
    Result gpu = method.Run(device, frame, run);
    std::vector<Stage> cpu = method.Reference(device, frame);
    if (gpu.stages.empty()) throw NothingToCompare(method.Name(), frame, gpu.plan);
    CheckStagesPaired(method.Name(), gpu.stages, cpu);
    fmt::print("{} on {} ({}), GPU against the CPU reference:\n", method.Name(), opt.input,
               device.Name());
    if (std::string worst = PrintStages(opt, gpu.stages, cpu); !worst.empty())
        throw Error(worst, ErrorKind::Internal);
}

}  // namespace

void AddDiffCommand(CLI::App &app) {
    auto opt = std::make_shared<DiffOptions>();
    CLI::App *cmd = app.add_subcommand(
        "diff",
        "Compare a method's GPU stages with its CPU reference on a frame\n\n"
        "Runs the method on the GPU and on the CPU reference and compares every stage (NMSE, "
        "max |gpu - cpu| / max |cpu|, non-finite parity); the method's options apply to both.");
    cmd->add_option("input", opt->input, "frame (EXR with the layers the method needs)")
        ->required();
    cmd->add_option("--method", opt->method, MethodOptions::Names())->capture_default_str();
    cmd->add_option("--dump", opt->dump, "directory: write <stage>.gpu.exr and .cpu.exr here");
    CheckRange(cmd->add_option("--max-nmse", opt->maxNmse,
                               "fail (exit 3) when a stage's NMSE exceeds this or its "
                               "non-finite elements differ"),
               0, 1e30, false);
    opt->device.Add(cmd);
    opt->methods.Add(cmd);
    cmd->callback([opt] { RunDiff(*opt); });
}

}  // namespace mcd::tool
