// `mcdenoise denoise`: run a method (denoise_<name>.cpp) on a frame, time it, measure it
// against a reference when given one, and write the result.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <map>

#include "host/error.h"
#include "host/io/frame.h"
#include "host/methods/pivot.h"
#include "host/metrics.h"
#include "tools/mcdenoise/commands.h"
#include "tools/mcdenoise/denoise_method.h"

namespace mcd::tool {
namespace {

// --demodulate: the frame's color-like layers divided by a guide layer, and what is needed
// to multiply back. Pixels whose guide is at or below 1e-3 x the channel mean are left
// as they are and keep their input in the output (as in the pivot method).
struct Demodulation {
    Image guide;
    std::vector<float> thresholds;
    std::string layer;
    std::string histograms;  // what rhf compared instead of the frame's hist, if it ran
};

Demodulation Demodulate(io::Frame &frame, const std::string &layer, const std::string &method) {
    if (layer != "pivot" && layer != "albedo")
        throw Error("--demodulate takes pivot or albedo, not '" + layer + "'");
    if (method == "pivot") throw Error("--demodulate: the pivot method divides by itself");
    if (method == "rhf") {
        // The histograms must be of the samples of color / guide: the renderer's zhist.
        if (layer != "pivot" || !frame.Has("zhist"))
            throw Error(fmt::format(
                "--demodulate {}: rhf needs histograms of the samples of color / {}, a "
                "'zhist' layer ({}; mcdenoise render --layers zhist writes it for the pivot)",
                layer, layer,
                layer == "pivot" ? fmt::format("{} has none", frame.path)
                                 : "only the pivot has them"));
        frame.layers["hist"] = frame.Get("zhist");
    }
    Demodulation d;
    if (method == "rhf") d.histograms = "zhist (histograms of the samples of color / pivot)";
    d.layer = layer;
    d.guide = frame.Get(layer);
    const Image &color = frame.Get("color");
    if (!d.guide.SameShape(color))
        throw Error(fmt::format("--demodulate: {} is {}x{}x{}, color {}x{}x{}", layer,
                                d.guide.width, d.guide.height, d.guide.channels, color.width,
                                color.height, color.channels));
    d.thresholds = PivotThresholds(d.guide, 1e-3f);
    for (auto &[name, image] : frame.layers) {
        int power = name == "variance" ? 2
                    : (name == "color" || name == "min" || name == "max" || name == "direct" ||
                       name == "indirect")
                        ? 1
                        : 0;
        if (power == 0 || !image.SameShape(color)) continue;
        for (int c = 0; c < image.channels; ++c)
            for (size_t i = 0; i < image.PixelCount(); ++i) {
                float g = d.guide.Plane(c)[i];
                if (g > d.thresholds[c]) image.Plane(c)[i] /= power == 2 ? g * g : g;
            }
    }
    return d;
}

void Remodulate(const Demodulation &d, const Image &input, DenoiseResult *result) {
    Image &image = result->image;
    for (int c = 0; c < image.channels; ++c)
        for (size_t i = 0; i < image.PixelCount(); ++i) {
            float g = d.guide.Plane(c)[i];
            image.Plane(c)[i] = g > d.thresholds[c] ? image.Plane(c)[i] * g : input.Plane(c)[i];
        }
    result->plan.insert(result->plan.begin(),
                        fmt::format("demodulated: the method ran on color / {} (pixels with {} "
                                    "<= 1e-3 x the channel mean keep their input), then "
                                    "multiplied back",
                                    d.layer, d.layer));
    if (!d.histograms.empty())
        result->plan.insert(result->plan.begin() + 1,
                            "demodulated: rhf compared the frame's " + d.histograms);
}

// `--method auto` tries the methods in this order and takes the first the frame has the
// layers for. The order is measured, not guessed: `bench quality` at 128x128 on the seven
// built-in scenes (README, "Error against run time"), ranked by the geometric mean over
// the scenes of the error at equal time (MC's error over the method's at the time MC
// takes to 64 spp), measured on quiet lavapipe after rhf became 2.3x faster and bayes took
// the undecimated transform: awr 2.39x, rhf 1.96x, bayes 1.26x, pivot 0.78x (pivot is the
// most accurate per sample on several scenes but the slowest here). Before, on loaded
// lavapipe: awr 2.43x, bayes 1.27x, rhf 0.97x, pivot 0.67x; timing moves rhf most.
constexpr const char *kAutoOrder[] = {"awr", "rhf", "bayes", "pivot"};

std::string AutoOrderText() {
    std::string text;
    for (const char *name : kAutoOrder) text += (text.empty() ? "" : " > ") + std::string(name);
    return text;
}

// The GPU buffers a run allocated, by name with their sizes, and its peak.
std::string LedgerText(const vk::Context::MemoryLedger &ledger) {
    std::map<std::string, std::pair<int, double>> byName;
    for (const auto &[name, bytes] : ledger.allocations) {
        auto &[count, total] = byName[name];
        ++count, total += double(bytes);
    }
    std::string text = fmt::format(
        "  GPU buffers: {} allocations, peak {:.2f} MB (staging for transfers not counted):",
        ledger.allocations.size(), double(ledger.peak) / 1e6);
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
        std::string input, output, method = "auto", reference, preview, demodulate;
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
    cmd->add_option("--method", opt->method,
                    "auto (the best method the frame's layers allow, by the measured order " +
                        AutoOrderText() + "), " + names)
        ->capture_default_str();
    cmd->add_option("--reference", opt->reference,
                    "converged image to measure the error against, before and after");
    cmd->add_option("--preview", opt->preview, "also write a tonemapped PNG");
    cmd->add_flag("--explain", opt->explain, "print what runs and what is left out, and why");
    cmd->add_option("--demodulate", opt->demodulate,
                    "divide the frame by its pivot or albedo layer before the method and "
                    "multiply back after (Ershov et al. 4.1: filter z = color / pivot with "
                    "any method but pivot; rhf then needs the frame's zhist layer, from "
                    "render --layers zhist, and the pivot)");
    opt->device.Add(cmd);
    for (const DenoiseMethod &m : *methods) m.addOptions(cmd);

    cmd->callback([opt, methods, names] {
        auto byName = [&](const std::string &name) {
            return std::find_if(methods->begin(), methods->end(),
                                [&](const DenoiseMethod &m) { return m.name == name; });
        };
        auto method = byName(opt->method);
        if (method == methods->end() && opt->method != "auto")
            throw Error(
                fmt::format("unknown method '{}' (methods: auto, {})", opt->method, names));
        CheckOutputPath(opt->output, {".exr", ".png"});
        if (!opt->preview.empty()) CheckOutputPath(opt->preview, {".png"});
        io::Frame frame = io::ReadFrame(opt->input);
        // auto: the first method in the measured order that the frame has the layers for.
        std::vector<std::string> autoPlan;
        if (opt->method == "auto") {
            for (const char *name : kAutoOrder) {
                auto candidate = byName(name);
                if (candidate == methods->end()) continue;
                std::string lacks = candidate->missing ? candidate->missing(frame) : "";
                bool demodulable = candidate->name != "pivot" &&
                                   (candidate->name != "rhf" ||
                                    (opt->demodulate == "pivot" && frame.Has("zhist")));
                if (lacks.empty() && (opt->demodulate.empty() || demodulable)) {
                    method = candidate;
                    break;
                }
                autoPlan.push_back(fmt::format(
                    "auto: left out {}: {}", name,
                    lacks.empty() ? "it cannot run on a demodulated frame" : lacks));
            }
            if (method == methods->end())
                throw Error(fmt::format("{}: --method auto found no method for this frame",
                                        opt->input));
            autoPlan.insert(autoPlan.begin(),
                            fmt::format("auto: {} (order by bench quality: {})", method->name,
                                        AutoOrderText()));
        }
        const Image color = frame.Get("color");  // a copy: --demodulate changes the frame
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
        Demodulation demodulation;
        if (!opt->demodulate.empty())
            demodulation = Demodulate(frame, opt->demodulate, method->name);
        DenoiseResult result = method->run(context, frame);
        if (!opt->demodulate.empty()) Remodulate(demodulation, color, &result);
        double wallMs =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count();
        double gpuMs = 0;
        for (const vk::DispatchTiming &t : result.timings) gpuMs += std::max(t.gpuMs, 0.0);
        if (opt->explain) {
            fmt::print("{} on {} ({}):\n", method->name, opt->input, context.Info().name);
            for (const std::string &step : autoPlan) fmt::print("  {}\n", step);
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
