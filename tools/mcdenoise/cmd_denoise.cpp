// `mcdenoise denoise`: run a method on a frame. Methods so far: awr (reconstruction).
#include <fmt/format.h>

#include <chrono>

#include "host/error.h"
#include "host/io/frame.h"
#include "host/methods/awr.h"
#include "host/metrics.h"
#include "tools/mcdenoise/commands.h"

namespace mcd::tool {
namespace {

// The per-pixel variance of the mean AWR needs, from the layers the frame has. `auto`
// prefers the frame's variance layer: measured on dof-arealight at 128x128 and 32 spp, it
// halves plain Monte Carlo's relMSE after reconstruction (0.0027 -> 0.0014), while the
// paper's range bound, (max - min)^2 / spp, over-smooths and doubles it (-> 0.0050).
Image AwrVariance(const io::Frame &frame, const std::string &source, std::string *why) {
    bool range = frame.Has("min") && frame.Has("max") && frame.Has("spp");
    bool layer = frame.Has("variance");
    if (source == "layer" || (source == "auto" && layer)) {
        if (!layer)
            throw Error(fmt::format("{}: --variance layer needs a variance layer", frame.path));
        *why = "variance of the mean from the frame's variance layer";
        return frame.Get("variance");
    }
    if (source == "range" || source == "auto") {
        if (!range)
            throw Error(
                fmt::format("{}: awr needs a variance layer or min, max and spp layers; "
                            "the frame has neither",
                            frame.path));
        *why = "variance of the mean from the sample range, (max - min)^2 / spp (AWR 4.2)";
        return AwrVarianceFromRange(frame.Get("min"), frame.Get("max"), frame.Get("spp"));
    }
    throw Error("--variance takes auto, range or layer, not '" + source + "'");
}

}  // namespace

void AddDenoiseCommand(CLI::App &app) {
    struct Options {
        std::string input, output, method = "awr", basis = "cdf97", variance = "auto",
                                   reference, preview;
        int levels = -1;
        float cs = 1.f, renorm = 0.70710678f;
        bool explain = false;
        DeviceOptions device;
    };
    auto opt = std::make_shared<Options>();
    CLI::App *cmd = app.add_subcommand(
        "denoise",
        "Denoise a frame: --method awr (rhf, bayes and pivot come with issues #4, "
        "#6 and #7)");
    cmd->add_option("input", opt->input, "noisy frame (EXR with the layers the method needs)")
        ->required();
    cmd->add_option("-o,--output", opt->output, "denoised image (.exr or .png)")->required();
    cmd->add_option("--method", opt->method, "awr")->capture_default_str();
    cmd->add_option("--basis", opt->basis, "awr: haar, legall53 or cdf97")
        ->capture_default_str();
    cmd->add_option("--levels", opt->levels, "awr: wavelet levels (default: as many as fit)")
        ->check(CLI::Range(0, 64));
    cmd->add_option("--cs", opt->cs, "awr: smoothing constant c_s (eq. 11)")
        ->capture_default_str()
        ->check(CLI::Range(0.f, 1e6f));
    cmd->add_option("--renorm", opt->renorm,
                    "awr: sum of the squared 1D filters in the variance DWT (paper: 2^-1/2)")
        ->capture_default_str()
        ->check(CLI::Range(1e-6f, 1e6f));
    cmd->add_option("--variance", opt->variance,
                    "awr: where the per-pixel variance comes from: auto (the variance layer "
                    "if present, else min/max/spp), range (the paper's (max-min)^2/spp), layer")
        ->capture_default_str();
    cmd->add_option("--reference", opt->reference,
                    "converged image to measure the error against, before and after");
    cmd->add_option("--preview", opt->preview, "also write a tonemapped PNG");
    cmd->add_flag("--explain", opt->explain, "print what runs and what is left out, and why");
    opt->device.Add(cmd);
    cmd->callback([opt] {
        if (opt->method != "awr")
            throw Error(
                fmt::format("method '{}' is not available yet (awr is; rhf, bayes and "
                            "pivot come with issues #4, #6 and #7)",
                            opt->method));
        std::optional<WaveletBasis> basis = ParseWavelet(opt->basis);
        if (!basis) throw Error("unknown wavelet basis '" + opt->basis + "'");
        CheckOutputPath(opt->output, {".exr", ".png"});
        if (!opt->preview.empty()) CheckOutputPath(opt->preview, {".png"});
        io::Frame frame = io::ReadFrame(opt->input);
        const Image &color = frame.Get("color");
        std::string why;
        Image variance = AwrVariance(frame, opt->variance, &why);
        Image reference;
        if (!opt->reference.empty()) {
            reference = io::ReadImage(opt->reference);
            if (reference.width != color.width || reference.height != color.height)
                throw Error(fmt::format("reference {} is {}x{}, the frame {}x{}",
                                        opt->reference, reference.width, reference.height,
                                        color.width, color.height));
        }

        AwrOptions options;
        options.basis = *basis;
        options.levels = opt->levels;
        options.cs = opt->cs;
        options.lowSum = options.highSum = opt->renorm;
        vk::Context context(opt->device.ContextOptions());
        auto start = std::chrono::steady_clock::now();
        AwrResult result = AwrReconstruct(context, color, variance, options);
        double wallMs =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count();
        double gpuMs = 0;
        for (const vk::DispatchTiming &t : result.timings) gpuMs += std::max(t.gpuMs, 0.0);
        if (opt->explain) {
            fmt::print("awr on {} ({}):\n  {}\n", opt->input, context.Info().name, why);
            for (const std::string &step : result.plan) fmt::print("  {}\n", step);
        }
        // Measure before writing: a failure here must not leave a file behind.
        std::string errorLine;
        if (!reference.Empty()) {
            ErrorMetrics before = CompareImages(color, reference);
            ErrorMetrics after = CompareImages(result.image, reference);
            errorLine = fmt::format(
                "  error vs {}: relMSE {:.5g} -> {:.5g}, PSNR {:.2f} -> {:.2f} dB, SSIM {:.4f} "
                "-> "
                "{:.4f}{}\n",
                opt->reference, before.relMse, after.relMse, before.psnr, after.psnr,
                before.ssim, after.ssim,
                after.nonFinite ? fmt::format(" ({} non-finite output values)", after.nonFinite)
                                : "");
        }
        WriteImage(opt->output, result.image,
                   {{"mcd:method", "awr"}, {"mcd:source", opt->input}});
        if (!opt->preview.empty()) io::WritePng(opt->preview, result.image);
        fmt::print("{}: awr in {:.1f} ms ({:.1f} ms GPU, {} dispatches)\n", opt->output, wallMs,
                   gpuMs, result.timings.size());
        fmt::print("{}", errorLine);
    });
}

}  // namespace mcd::tool
