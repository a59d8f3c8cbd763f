// `mcdenoise denoise --method rhf`: Ray Histogram Fusion (host/methods/rhf.h). Needs the
// colour and the histograms (Bin_0000..Bin_{3n}, the renderer's `--layers hist` or any
// renderer writing the authors' layout).
#include <fmt/format.h>

#include <cmath>
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

// Algorithm 3 on the CPU reference, keeping the images the GPU run keeps (RhfResult).
std::vector<Image> ReferenceStages(const Image &color, const Image &hist,
                                   const ref::RhfParams &p) {
    auto sigma = [](int s) { return 0.55 * std::sqrt(std::pow(4.0, s) - 1); };
    int scales = ref::RhfScalesUsed(color.width, color.height, p), n3 = hist.channels - 1;
    double total = 0;
    for (int i = 0; i < n3; ++i)
        for (size_t q = 0; q < hist.PixelCount(); ++q) total += hist.Plane(i)[q];
    std::vector<Image> stages;
    Image previous;
    for (int s = scales - 1; s >= 0; --s) {
        Image u = color, h = hist;
        double factor = 1;
        if (s > 0) {
            u = ref::RhfGaussianDownsample(color, s, sigma(s));
            h = ref::RhfGaussianDownsample(hist, s, sigma(s));
            double coarse = 0;
            for (int i = 0; i < n3; ++i)
                for (size_t q = 0; q < h.PixelCount(); ++q) coarse += h.Plane(i)[q];
            factor = coarse > 0 ? total / coarse : 1.0;
            for (float &v : h.data) v = float(v * factor);
            stages.push_back(u);
        }
        Image filtered = ref::RhfSingleScale(u, h, p.patchHalf, p.searchHalf, p.threshold,
                                             s == 0 ? p.knn : 0, p.brightVeto / factor);
        stages.push_back(filtered);
        if (s < scales - 1) {
            Image low = ref::RhfBicubicUpsample(
                ref::RhfGaussianDownsample(filtered, 1, sigma(1)), u.width, u.height);
            Image up = ref::RhfBicubicUpsample(previous, u.width, u.height);
            for (size_t i = 0; i < filtered.Size(); ++i)
                filtered.data[i] = float(double(filtered.data[i]) - low.data[i] + up.data[i]);
            stages.push_back(filtered);
        }
        previous = filtered;
    }
    return stages;
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
        if (!frame.Has("hist"))
            throw Error(
                fmt::format("{}: rhf needs the histogram channels Bin_0000..Bin_{{3n}} "
                            "(render with --layers hist); the frame has none",
                            frame.path));
        RhfResult rhf = RhfDenoise(context, frame.Get("color"), frame.Get("hist"), *opt);
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
        std::vector<Image> cpu =
            ReferenceStages(color, hist,
                            {options.patchHalf, options.searchHalf, double(options.threshold),
                             options.knn, options.scales, double(options.brightVeto)});
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
