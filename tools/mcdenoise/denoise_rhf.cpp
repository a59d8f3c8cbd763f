// `mcdenoise denoise --method rhf`: Ray Histogram Fusion (host/methods/rhf.h). Needs the
// colour and the histograms (Bin_0000..Bin_{3n}, the renderer's `--layers hist` or any
// renderer writing the authors' layout).
#include <fmt/format.h>

#include <memory>

#include "cpu_reference/rhf.h"
#include "host/error.h"
#include "host/methods/rhf.h"
#include "tools/mcdenoise/denoise_method.h"

namespace mcd::tool {
namespace {

const Image &Histograms(const io::Frame &frame) {
    if (!frame.Has("hist"))
        throw Error(
            fmt::format("{}: rhf needs the histogram channels Bin_0000..Bin_{{3n}} "
                        "(render with --layers hist); the frame has none",
                        frame.path));
    return frame.Get("hist");
}

}  // namespace

DenoiseMethod RhfMethod() {
    auto opt = std::make_shared<RhfOptions>();
    DenoiseMethod method;
    method.name = "rhf";
    method.summary = "Ray Histogram Fusion (needs the Bin_* histogram channels)";
    method.addOptions = [opt](CLI::App *cmd) {
        cmd->add_option("--patch-half", opt->patchHalf,
                        "rhf: patch half-size w (patches are "
                        "(2w+1)^2)")
            ->capture_default_str()
            ->check(CLI::Range(0, 20));
        cmd->add_option("--search-half", opt->searchHalf,
                        "rhf: search half-window b (the window is (2b+1)^2)")
            ->capture_default_str()
            ->check(CLI::Range(0, 20));
        cmd->add_option("--kappa", opt->threshold,
                        "rhf: threshold on the normalised chi-square patch distance")
            ->capture_default_str()
            ->check(CLI::Range(0.f, 1e30f));
        cmd->add_option("--bright-veto", opt->brightVeto,
                        "rhf: leave a candidate patch out when one of its pixels differs from "
                        "its counterpart in the saturated bins (samples brighter than the "
                        "histogram's range) by more than this: those bins' terms over the "
                        "harmonic mean of the two sample counts. Beyond the authors' tool, "
                        "whose distance lets a visible light into dark patches at few samples; "
                        "0 is the authors' tool")
            ->capture_default_str()
            ->check(CLI::Range(0.f, 1e30f));
        cmd->add_option("--knn", opt->knn,
                        "rhf: nearest patches always averaged (finest scale)")
            ->capture_default_str()
            ->check(CLI::Range(0, 1681));
        cmd->add_option("--nscales", opt->scales,
                        "rhf: scales (fewer when a scale would be smaller than the search "
                        "window)")
            ->capture_default_str()
            ->check(CLI::Range(1, 8));
        cmd->add_flag(
            "--keep-negative", [opt](int64_t) { opt->clampNegative = false; },
            "rhf: keep negative output values, as the authors' tool does (by default the "
            "scale recombination's bicubic overshoot below 0 is clamped to 0)");
    };
    method.missing = [](const io::Frame &frame) -> std::string {
        return frame.Has("hist") ? "" : "no histogram channels (Bin_0000..)";
    };
    method.run = [opt](vk::Context &context, const io::Frame &frame) {
        RhfResult rhf = RhfDenoise(context, frame.Get("color"), Histograms(frame), *opt);
        DenoiseResult result;
        result.image = std::move(rhf.image);
        result.plan = std::move(rhf.plan);
        result.warnings = std::move(rhf.warnings);
        result.timings = std::move(rhf.timings);
        return result;
    };
    method.stages = [opt](vk::Context &context, const io::Frame &frame) {
        const Image &color = frame.Get("color"), &hist = Histograms(frame);
        RhfOptions options = *opt;
        options.keepStages = true;
        RhfResult gpu = RhfDenoise(context, color, hist, options);
        std::vector<Image> cpu;
        ref::Rhf(color, hist,
                 {options.patchHalf, options.searchHalf, double(options.threshold), options.knn,
                  options.scales, double(options.brightVeto)},
                 &cpu);
        if (cpu.size() != gpu.stages.size())
            throw Error(fmt::format("rhf diff: {} stages on the GPU, {} on the CPU",
                                    gpu.stages.size(), cpu.size()));
        std::vector<StagePair> pairs;
        for (size_t i = 0; i < cpu.size(); ++i)
            pairs.push_back(
                {gpu.stages[i].first, std::move(gpu.stages[i].second), std::move(cpu[i])});
        return pairs;
    };
    return method;
}

}  // namespace mcd::tool
