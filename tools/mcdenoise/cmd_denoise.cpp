// `mcdenoise denoise`: run a method (denoise_<name>.cpp) on a frame, time it, measure it
// against a reference when given one, and write the result.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <map>

#include "host/error.h"
#include "host/io/frame.h"
#include "host/metrics.h"
#include "tools/mcdenoise/commands.h"
#include "tools/mcdenoise/denoise_method.h"

namespace mcd::tool {
namespace {

// The GPU buffers a run allocated, by name with their sizes, and its peak.
std::string LedgerText(const vk::Context::MemoryLedger &ledger) {
    std::map<std::string, std::pair<int, double>> byName;
    for (const auto &[name, bytes] : ledger.allocations) {
        auto &[count, total] = byName[name];
        ++count, total += double(bytes);
    }
    std::string text =
        fmt::format("  GPU buffers: {} allocations, peak {:.2f} MB:", ledger.allocations.size(),
                    double(ledger.peak) / 1e6);
    for (const auto &[name, entry] : byName)
        text += fmt::format(" {}{} {:.2f} MB;", name,
                            entry.first > 1 ? fmt::format(" x{}", entry.first) : "",
                            entry.second / 1e6);
    if (ledger.allocations.empty()) text += " none";
    return text + "\n";
}

}  // namespace

void AddDenoiseCommand(CLI::App &app) {
    struct Options {
        std::string input, output, method = "awr", reference, preview;
        bool explain = false;
        DeviceOptions device;
    };
    auto opt = std::make_shared<Options>();
    auto methods = std::make_shared<std::vector<DenoiseMethod>>(DenoiseMethods());
    std::string names, summaries;
    for (const DenoiseMethod &m : *methods) {
        names += (names.empty() ? "" : ", ") + m.name;
        summaries += fmt::format("\n  {}: {}", m.name, m.summary);
    }
    CLI::App *cmd =
        app.add_subcommand("denoise", "Denoise a frame with one method:" + summaries);
    cmd->add_option("input", opt->input, "noisy frame (EXR with the layers the method needs)")
        ->required();
    cmd->add_option("-o,--output", opt->output, "denoised image (.exr or .png)")->required();
    cmd->add_option("--method", opt->method, names)->capture_default_str();
    cmd->add_option("--reference", opt->reference,
                    "converged image to measure the error against, before and after");
    cmd->add_option("--preview", opt->preview, "also write a tonemapped PNG");
    cmd->add_flag("--explain", opt->explain, "print what runs and what is left out, and why");
    opt->device.Add(cmd);
    for (const DenoiseMethod &m : *methods) m.addOptions(cmd);

    cmd->callback([opt, methods, names] {
        auto method =
            std::find_if(methods->begin(), methods->end(),
                         [&](const DenoiseMethod &m) { return m.name == opt->method; });
        if (method == methods->end())
            throw Error(fmt::format("unknown method '{}' (methods: {})", opt->method, names));
        CheckOutputPath(opt->output, {".exr", ".png"});
        if (!opt->preview.empty()) CheckOutputPath(opt->preview, {".png"});
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

        vk::Context context(opt->device.ContextOptions());
        context.ResetLedger();
        auto start = std::chrono::steady_clock::now();
        DenoiseResult result = method->run(context, frame);
        double wallMs =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count();
        double gpuMs = 0;
        for (const vk::DispatchTiming &t : result.timings) gpuMs += std::max(t.gpuMs, 0.0);
        if (opt->explain) {
            fmt::print("{} on {} ({}):\n", method->name, opt->input, context.Info().name);
            for (const std::string &step : result.plan) fmt::print("  {}\n", step);
            fmt::print("{}", LedgerText(context.Ledger()));
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
        WriteImage(opt->output, result.image,
                   {{"mcd:method", method->name}, {"mcd:source", opt->input}});
        if (!opt->preview.empty()) io::WritePng(opt->preview, result.image);
        fmt::print("{}: {} in {:.1f} ms ({:.1f} ms GPU, {} dispatches)\n", opt->output,
                   method->name, wallMs, gpuMs, result.timings.size());
        fmt::print("{}", errorLine);
    });
}

}  // namespace mcd::tool
