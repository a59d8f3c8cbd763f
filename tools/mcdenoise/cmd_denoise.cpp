// `mcdenoise denoise`: run a method of the library (include/mcdenoise/mcdenoise.h) on a
// frame, measure it against a reference when given one, and write the result.
#include <fmt/format.h>

#include <sys/resource.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <map>
#include <type_traits>
#include <variant>

#include "host/error.h"
#include "host/io/conventions.h"
#include "host/io/frame.h"
#include "host/metrics.h"
#include "tools/mcdenoise/commands.h"
#include "tools/mcdenoise/method_options.h"
#include "tools/mcdenoise/path_guard.h"

namespace mcd::tool {
namespace {

// The result written over its own input frame (--overwrite-input): every layer kept, the
// noisy color under kNoisyColorLayer (a second run keeps the first's, the render's own),
// the file's metadata with the provenance on top. A link to the frame stays one: the
// file it names is replaced.
void WriteOverInput(const io::Frame &frame, const Image &denoised,
                    const std::map<std::string, std::string> &provenance) {
    const Image &noisy =
        frame.Has(kNoisyColorLayer) ? frame.Get(kNoisyColorLayer) : frame.Get("color");
    std::vector<std::pair<std::string, const Image *>> layers = {{"color", &denoised},
                                                                 {kNoisyColorLayer, &noisy}};
    for (const auto &[name, image] : frame.layers)
        if (name != "color" && name != kNoisyColorLayer) layers.push_back({name, &image});
    std::map<std::string, std::string> metadata = frame.metadata;
    for (const auto &[key, value] : provenance) metadata[key] = value;
    io::WriteExr(std::filesystem::canonical(frame.path).string(), layers, metadata);
}

// The GPU buffers a run allocated, by name with their sizes, and its peak.
std::string LedgerText(const Result &result) {
    std::map<std::string, std::pair<int, double>> byName;
    for (const Allocation &a : result.allocations) {
        auto &[count, total] = byName[a.name];
        ++count, total += double(a.bytes);
    }
    std::string text = fmt::format(
        "  GPU buffers: {} allocations, peak {:.2f} MB (staging for transfers not counted):",
        result.allocations.size(), double(result.peakBytes) / 1e6);
    for (const auto &[name, entry] : byName)
        text += fmt::format(" {}{} {:.2f} MB;", name,
                            entry.first > 1 ? fmt::format(" x{}", entry.first) : "",
                            entry.second / 1e6);
    if (result.allocations.empty()) text += " none";
    return text + "\n";
}

// Every parameter of the method that ran, and those all methods share, as
// "name=value ..." with the values the run used (defaults included), so the output says
// how it was made.
std::string OptionsText(const Method &method, const std::string &ran) {
    std::string text;
    for (const ParamInfo &info : method.Params()) {
        if (!info.method.empty() && info.method != ran) continue;
        std::string value = std::visit(
            [](const auto &v) {
                if constexpr (std::is_same_v<std::decay_t<decltype(v)>, bool>)
                    return std::string(v ? "true" : "false");
                else
                    return fmt::format("{}", v);
            },
            method.Get(info.name));
        // Quoted when empty or spaced, so the string splits back into its parameters.
        if (value.empty() || value.find(' ') != std::string::npos) value = "\"" + value + "\"";
        text += fmt::format("{}{}={}", text.empty() ? "" : " ", info.name, value);
    }
    return text;
}

}  // namespace

void AddDenoiseCommand(CLI::App &app) {
    struct Options {
        std::string input, output, method = "auto", reference, preview;
        bool explain = false, overwriteInput = false;
        DeviceOptions device;
        MethodOptions methods;
    };
    auto opt = std::make_shared<Options>();
    CLI::App *cmd = app.add_subcommand(
        "denoise", "Denoise a frame with one method:" + MethodOptions::Summaries());
    cmd->add_option("input", opt->input, "noisy frame (EXR with the layers the method needs)")
        ->required();
    cmd->add_option("-o,--output", opt->output, "denoised image (.exr or .png)")->required();
    cmd->add_option("--method", opt->method,
                    "auto (" + Method("auto").Summary() + "), " + MethodOptions::Names())
        ->capture_default_str();
    cmd->add_option("--reference", opt->reference,
                    "converged image to measure the error against, before and after");
    cmd->add_option("--preview", opt->preview, "also write a tonemapped PNG");
    cmd->add_flag("--explain", opt->explain, "print what runs and what is left out, and why");
    cmd->add_flag("--overwrite-input", opt->overwriteInput,
                  "let -o be the input frame (.exr): the result becomes its color, the noisy "
                  "color is kept as layer " +
                      std::string(kNoisyColorLayer) + " and every other layer as it was");
    opt->device.Add(cmd);
    opt->methods.Add(cmd);

    cmd->callback([opt] {
        Method method = opt->methods.Make(opt->method);
        CheckOutputPath(opt->output, {".exr", ".png"});
        if (!opt->preview.empty()) CheckOutputPath(opt->preview, {".png"});
        // No output may be a file this run reads, unless the user says so for -o.
        bool inPlace = opt->overwriteInput && SameFile(opt->output, opt->input);
        if (inPlace && std::filesystem::path(opt->output).extension() != ".exr")
            throw Error(fmt::format(
                "--overwrite-input: '{}' would lose the frame's other layers; it needs an .exr "
                "output",
                opt->output));
        RefuseOverwritingInputs(
            {{"input", inPlace ? "" : opt->input,
              "write elsewhere, or pass --overwrite-input to replace the frame's color and "
              "keep its other layers"},
             {"--reference", opt->reference}},
            {{"-o", opt->output}, {"--preview", opt->preview}});
        if (inPlace)
            RefuseOverwritingInputs({{"input", opt->input}}, {{"--preview", opt->preview}});
        io::Frame frame = io::ReadFrame(opt->input);
        const Image &color = frame.Get("color");
        Image reference;
        if (!opt->reference.empty()) {
            reference = io::ReadImage(opt->reference);
            if (reference.width != color.width || reference.height != color.height)
                throw Error(fmt::format("reference {} is {}x{}, the frame {}x{}",
                                        opt->reference, reference.width, reference.height,
                                        color.width, color.height));
        }

        Device device(opt->device.Options());
        RunOptions run;
        // Planefit takes seconds to minutes on a CPU device: show how far it is on a
        // terminal (the line is overwritten, then ended).
        bool terminal = isatty(fileno(stderr));
        bool progressShown = false;
        if (terminal)
            run.progress = [&](const std::string &stage, int done, int total) {
                std::fprintf(stderr, "\r%s: %-6s %3d%%",
                             method.Name() == "auto" ? "denoise" : method.Name().c_str(),
                             stage.c_str(), 100 * done / total);
                progressShown = true;
            };
        Result result = method.Run(device, frame, run);
        if (progressShown) std::fprintf(stderr, "\n");
        if (opt->explain) {
            fmt::print("{} on {} ({}):\n", result.method, opt->input, device.Name());
            // How another renderer's layers were converted: the split and noise depend on it.
            if (auto it = frame.metadata.find(io::kConventionKey); it != frame.metadata.end())
                fmt::print("  frame {}\n", it->second);
            for (const std::string &step : result.plan) fmt::print("  {}\n", step);
            fmt::print("{}", LedgerText(result));
            // The process's own peak: the frame's layers, the copies and, on a CPU device,
            // the GPU buffers too.
            rusage usage{};
            getrusage(RUSAGE_SELF, &usage);
            fmt::print("  peak memory of the process (RSS): {:.0f} MB\n",
                       double(usage.ru_maxrss) * 1024 / 1e6);
        }
        for (const std::string &warning : result.warnings)
            fmt::print(stderr, "warning: {}\n", warning);
        // Measure before writing: a failure here must not leave a file behind.
        std::string errorLine;
        if (!reference.Empty()) {
            ErrorMetrics before = CompareImages(color, reference);
            ErrorMetrics after = CompareImages(result.image, reference);
            errorLine = fmt::format(
                "  error vs {}: relMSE {:.5g} -> {:.5g}, PSNR {:.2f} -> {:.2f} dB, SSIM {:.4f} "
                "-> {:.4f}{}\n",
                opt->reference, before.relMse, after.relMse, before.psnr, after.psnr,
                before.ssim, after.ssim,
                after.nonFinite ? fmt::format(" ({} non-finite output values)", after.nonFinite)
                                : "");
        }
        std::map<std::string, std::string> provenance = {
            {"mcd:method", result.method},
            {"mcd:source", opt->input},
            {"mcd:options", OptionsText(method, result.method)},
            {"mcd:version", Version()}};
        const Image *alpha = frame.Has("alpha") ? &frame.Get("alpha") : nullptr;
        if (inPlace)
            WriteOverInput(frame, result.image, provenance);
        else
            WriteImage(opt->output, result.image, provenance, alpha);
        if (!opt->preview.empty()) io::WritePngWithAlpha(opt->preview, result.image, alpha);
        fmt::print("{}: {} in {:.1f} ms ({:.1f} ms GPU, {} dispatches)\n", opt->output,
                   result.method, result.wallMs, result.GpuMs(), result.timings.size());
        fmt::print("{}", errorLine);
    });
}

}  // namespace mcd::tool
