// `mcdenoise diff`: run a method on the GPU and on the CPU reference, stage by stage, and
// report how far apart they are, so users can check a kernel on their own frames and
// devices. --dump writes both sides of every stage as EXR.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "host/error.h"
#include "host/io/frame.h"
#include "tools/mcdenoise/commands.h"
#include "tools/mcdenoise/denoise_method.h"

namespace mcd::tool {
namespace {

struct StageError {
    double nmse = 0;    // sum (gpu - cpu)^2 / sum cpu^2, over elements finite on both
    double maxRel = 0;  // max |gpu - cpu| / max |cpu|
    size_t parity = 0;  // elements finite on one side only
};

StageError Measure(const Image &gpu, const Image &cpu) {
    StageError e;
    double num = 0, den = 0, maxDiff = 0, maxRef = 0;
    for (size_t i = 0; i < cpu.data.size(); ++i) {
        double g = gpu.data[i], c = cpu.data[i];
        if (std::isfinite(g) != std::isfinite(c)) {
            ++e.parity;
            continue;
        }
        if (!std::isfinite(c)) continue;
        num += (g - c) * (g - c);
        den += c * c;
        maxDiff = std::max(maxDiff, std::fabs(g - c));
        maxRef = std::max(maxRef, std::fabs(c));
    }
    e.nmse = den > 0 ? num / den : num;
    e.maxRel = maxRef > 0 ? maxDiff / maxRef : maxDiff;
    return e;
}

std::string FileName(const std::string &stage) {
    std::string name = stage;
    std::replace_if(
        name.begin(), name.end(), [](char c) { return !std::isalnum(c); }, '-');
    return name;
}

}  // namespace

void AddDiffCommand(CLI::App &app) {
    struct Options {
        std::string input, method = "awr", dump;
        double maxNmse = -1;
        DeviceOptions device;
    };
    auto opt = std::make_shared<Options>();
    auto methods = std::make_shared<std::vector<DenoiseMethod>>(DenoiseMethods());
    std::string names;
    for (const DenoiseMethod &m : *methods)
        if (m.stages) names += (names.empty() ? "" : ", ") + m.name;
    CLI::App *cmd = app.add_subcommand(
        "diff",
        "Run a method on the GPU and on the CPU reference and compare every stage (NMSE, max "
        "|gpu - cpu| / max |cpu|, non-finite parity); the method's options apply to both");
    cmd->add_option("input", opt->input, "frame (EXR with the layers the method needs)")
        ->required();
    cmd->add_option("--method", opt->method, names)->capture_default_str();
    cmd->add_option("--dump", opt->dump, "directory: write <stage>.gpu.exr and .cpu.exr here");
    cmd->add_option("--max-nmse", opt->maxNmse,
                    "fail (exit 1) when a stage's NMSE exceeds this or its non-finite "
                    "elements differ");
    opt->device.Add(cmd);
    for (const DenoiseMethod &m : *methods) m.addOptions(cmd);
    cmd->callback([opt, methods, names] {
        auto method = std::find_if(
            methods->begin(), methods->end(),
            [&](const DenoiseMethod &m) { return m.name == opt->method && m.stages; });
        if (method == methods->end())
            throw Error(fmt::format("diff: unknown method '{}' (methods with stages: {})",
                                    opt->method, names));
        if (!opt->dump.empty()) PrepareDirectory(opt->dump);
        io::Frame frame = io::ReadFrame(opt->input);
        vk::Context context(opt->device.ContextOptions());
        std::vector<StagePair> stages = method->stages(context, frame);
        fmt::print("{} on {} ({}), GPU against the CPU reference:\n", method->name, opt->input,
                   context.Info().name);
        fmt::print("  {:<24} {:>12} {:>16} {:>10}\n", "stage", "NMSE", "max rel error",
                   "parity");
        std::string worst;
        for (const StagePair &s : stages) {
            if (!s.gpu.SameShape(s.cpu))
                throw Error(
                    fmt::format("diff: stage {} is {}x{}x{} on the GPU, {}x{}x{} on the "
                                "CPU",
                                s.name, s.gpu.width, s.gpu.height, s.gpu.channels, s.cpu.width,
                                s.cpu.height, s.cpu.channels));
            StageError e = Measure(s.gpu, s.cpu);
            fmt::print("  {:<24} {:>12.3g} {:>16.3g} {:>10}\n", s.name, e.nmse, e.maxRel,
                       e.parity);
            if (opt->maxNmse >= 0 && worst.empty() && (e.nmse > opt->maxNmse || e.parity))
                worst = fmt::format(
                    "diff: stage {} is off: NMSE {:.3g} (--max-nmse {:.3g}), "
                    "{} elements finite on one side only",
                    s.name, e.nmse, opt->maxNmse, e.parity);
            if (!opt->dump.empty()) {
                std::filesystem::path dir(opt->dump);
                io::WriteExr((dir / (FileName(s.name) + ".gpu.exr")).string(),
                             {{"color", &s.gpu}});
                io::WriteExr((dir / (FileName(s.name) + ".cpu.exr")).string(),
                             {{"color", &s.cpu}});
            }
        }
        if (!worst.empty()) throw Error(worst);
    });
}

}  // namespace mcd::tool
