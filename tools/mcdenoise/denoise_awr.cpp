// `mcdenoise denoise --method awr`: AWR's wavelet reconstruction (host/methods/awr.h).
#include <fmt/format.h>

#include <memory>

#include "cpu_reference/awr_reconstruct.h"
#include "cpu_reference/wavelet_analyze.h"
#include "cpu_reference/wavelet_sqanalyze.h"
#include "cpu_reference/wavelet_synthesize.h"
#include "host/error.h"
#include "host/methods/awr.h"
#include "host/wavelet.h"
#include "tools/mcdenoise/denoise_method.h"

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

struct AwrCliOptions {
    std::string basis = "cdf97", variance = "auto";
    int levels = -1, spins = 1;
    float cs = 1.f, renorm = 0.70710678f;

    AwrOptions Options() const {
        std::optional<WaveletBasis> parsed = ParseWavelet(basis);
        if (!parsed) throw Error("unknown wavelet basis '" + basis + "'");
        AwrOptions options;
        options.basis = *parsed;
        options.levels = levels;
        options.cs = cs;
        options.lowSum = options.highSum = renorm;
        options.spins = spins;
        return options;
    }
};

}  // namespace

DenoiseMethod AwrMethod() {
    auto opt = std::make_shared<AwrCliOptions>();
    DenoiseMethod method;
    method.name = "awr";
    method.summary =
        "Adaptive Wavelet Rendering's reconstruction (needs variance or min/max/spp)";
    method.addOptions = [opt](CLI::App *cmd) {
        cmd->add_option("--basis", opt->basis, "awr: haar, legall53 or cdf97")
            ->capture_default_str();
        cmd->add_option("--levels", opt->levels,
                        "awr: wavelet levels (default: as many as fit)")
            ->check(CLI::Range(0, 64));
        cmd->add_option("--cs", opt->cs, "awr: smoothing constant c_s (eq. 11)")
            ->capture_default_str()
            ->check(CLI::Range(0.f, 1e6f));
        cmd->add_option(
               "--renorm", opt->renorm,
               "awr: sum of the squared 1D filters in the variance DWT (paper: 2^-1/2)")
            ->capture_default_str()
            ->check(CLI::Range(1e-6f, 1e6f));
        cmd->add_option("--variance", opt->variance,
                        "awr: where the per-pixel variance comes from: auto (the variance "
                        "layer if present, else min/max/spp), range (the paper's "
                        "(max-min)^2/spp), layer")
            ->capture_default_str();
        cmd->add_option("--awr-spins", opt->spins,
                        "awr: cycle spinning over N x N shifts of the DWT's grid (1: the "
                        "paper's reconstruction; beyond the paper; cost x N^2)")
            ->capture_default_str()
            ->check(CLI::Range(1, 8));
    };
    method.run = [opt](vk::Context &context, const io::Frame &frame) {
        std::string why;
        Image variance = AwrVariance(frame, opt->variance, &why);
        AwrResult awr = AwrReconstruct(context, frame.Get("color"), variance, opt->Options());
        DenoiseResult result;
        result.image = std::move(awr.image);
        result.plan.push_back(why);
        for (std::string &step : awr.plan) result.plan.push_back(std::move(step));
        result.timings = std::move(awr.timings);
        return result;
    };
    method.missing = [opt](const io::Frame &frame) -> std::string {
        bool range = frame.Has("min") && frame.Has("max") && frame.Has("spp");
        if (opt->variance == "layer" && !frame.Has("variance")) return "no variance layer";
        if (opt->variance == "range" && !range) return "no min, max and spp layers";
        if (!range && !frame.Has("variance")) return "no variance layer nor min, max and spp";
        return "";
    };
    method.stages = [opt](vk::Context &context, const io::Frame &frame) {
        std::string why;
        Image variance = AwrVariance(frame, opt->variance, &why);
        const Image &color = frame.Get("color");
        AwrOptions options = opt->Options();
        options.keepStages = true;
        AwrResult gpu = AwrReconstruct(context, color, variance, options);
        if (gpu.stages.empty())
            throw Error("awr: nothing to compare: " +
                        (gpu.plan.empty() ? std::string("no stage ran") : gpu.plan.back()));
        int levels =
            options.levels < 0 ? MaxWaveletLevels(color.width, color.height) : options.levels;
        Image coef = ref::WaveletAnalyze(color, options.basis, levels);
        Image coefVariance = ref::WaveletSqAnalyze(variance, options.basis, levels,
                                                   options.lowSum, options.highSum);
        Image shrunk = ref::AwrShrink(coef, coefVariance, LevelExtent(color.width, levels),
                                      LevelExtent(color.height, levels), options.cs);
        Image out = ref::WaveletSynthesize(shrunk, options.basis, levels);
        Image spun;
        if (options.spins > 1)
            spun = ref::AwrReconstructSpun(color, variance, options.basis, levels, options.cs,
                                           options.lowSum, options.highSum, options.spins);
        const Image *cpu[] = {&coef, &coefVariance, &shrunk, &out, &spun};
        std::vector<StagePair> pairs;
        for (size_t i = 0; i < gpu.stages.size(); ++i)
            pairs.push_back({gpu.stages[i].first, std::move(gpu.stages[i].second), *cpu[i]});
        return pairs;
    };
    return method;
}

}  // namespace mcd::tool
