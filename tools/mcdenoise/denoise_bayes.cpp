// `mcdenoise denoise --method bayes`: Bayesian wavelet shrinkage in the log domain
// (Xu & Pattanaik; host/methods/bayes.h). With direct and indirect layers only the
// indirect part is denoised (section 4.1); otherwise the whole image, and the plan says so.
#include <fmt/format.h>

#include <cmath>
#include <memory>

#include "cpu_reference/bayes_denoise.h"

#include "host/error.h"
#include "host/methods/bayes.h"
#include "host/wavelet.h"
#include "tools/mcdenoise/denoise_method.h"

namespace mcd::tool {
namespace {

// --noise defaults to auto: on cornell and interior at 4/16/64 spp (README, Method bayes)
// the variance estimate beat the fixed s_n 0.19 in every row, by 0.3 to 2.2 dB PSNR.
// --bayes-transform defaults to swt: on the same six frames (scripts/bayes_transform.sh,
// 128x128, defaults otherwise) it beat the decimated DWT on all six, by 0.02 to 1.0 dB PSNR
// (relMSE 2% to 20% lower), and beat the DWT with 2 x 2 cycle spinning too, at about 3x
// the DWT's GPU time (bench bayes 1024x1024 RGB, Haar, quiet lavapipe: 394 ms vs 129 ms).
struct BayesCliOptions {
    std::string basis = "haar", noise = "auto", transform = "swt";
    int levels = 3, spins = 1;
    float sn = 0.19f, pn = 1.5f, hpFactor = 2.f, floorRel = 1e-3f;
    bool noSplit = false, keepMean = false;
    std::string zeros = "restore", colour = "rgb";

    BayesOptions Options() const {
        std::optional<WaveletBasis> parsed = ParseWavelet(basis);
        if (!parsed) throw Error("bayes: unknown wavelet basis '" + basis + "'");
        if (transform != "dwt" && transform != "swt")
            throw Error("--bayes-transform takes dwt or swt, not '" + transform + "'");
        if (noise != "fixed" && noise != "auto" && noise != "mad" && noise != "variance")
            throw Error("--noise takes fixed, auto, mad or variance, not '" + noise + "'");
        if (zeros != "restore" && zeros != "denoise")
            throw Error("--zeros takes restore or denoise, not '" + zeros + "'");
        if (colour != "rgb" && colour != "opponent")
            throw Error("--colour takes rgb or opponent, not '" + colour + "'");
        BayesOptions options;
        options.restoreZeros = zeros == "restore";
        options.keepMean = keepMean;
        options.spins = spins;
        options.opponent = colour == "opponent";
        options.basis = *parsed;
        options.transform = transform == "swt" ? BayesTransform::Swt : BayesTransform::Dwt;
        options.levels = levels;
        options.sn = sn;
        options.pn = pn;
        options.hpFactor = hpFactor;
        options.floorRel = floorRel;
        options.noiseAuto = noise == "auto" || noise == "mad";
        return options;
    }

    // --noise variance, or auto on a frame with a variance layer: point `options` at it;
    // say which estimate --noise auto took.
    void UseVariance(const io::Frame &frame, BayesOptions *options,
                     std::vector<std::string> *plan) const {
        bool has = frame.Has("variance");
        if (noise == "variance" && !has)
            throw Error("bayes: --noise variance needs a variance layer; the frame has none");
        if (noise == "variance" || (noise == "auto" && has)) {
            options->variance = &frame.Get("variance");
            if (noise == "auto")
                plan->push_back(
                    "--noise auto: the frame has a variance layer: noise per band "
                    "from it (--noise variance)");
        } else if (noise == "auto") {
            plan->push_back(
                "--noise auto: no variance layer: noise from the finest band's "
                "median |y| (--noise mad)");
        }
    }
};

}  // namespace

DenoiseMethod BayesMethod() {
    auto opt = std::make_shared<BayesCliOptions>();
    DenoiseMethod method;
    method.name = "bayes";
    method.summary =
        "Bayesian wavelet shrinkage in the log domain, Xu & Pattanaik (color; uses "
        "direct/indirect when present)";
    method.addOptions = [opt](CLI::App *cmd) {
        cmd->add_option("--bayes-wavelet", opt->basis, "bayes: haar, legall53 or cdf97")
            ->capture_default_str();
        cmd->add_option("--bayes-transform", opt->transform,
                        "bayes: swt (stationary, undecimated: shift-invariant; the default, "
                        "measured better than dwt on all six cornell/interior 4/16/64 spp "
                        "frames, at ~3x the GPU time and 3 levels + 1 image-sized planes per "
                        "channel) or dwt (the decimated DWT)")
            ->capture_default_str();
        cmd->add_option("--bayes-levels", opt->levels,
                        "bayes: wavelet levels (clamped to what the image allows)")
            ->capture_default_str()
            ->check(CLI::Range(0, 64));
        cmd->add_option("--sn", opt->sn,
                        "bayes: noise s_n in the log domain (paper: 0.19, 0.6)")
            ->capture_default_str()
            ->check(CLI::Range(0.f, 1e3f));
        cmd->add_option("--pn", opt->pn, "bayes: noise shape p_n (paper: 1.5)")
            ->capture_default_str()
            ->check(CLI::Range(0.1f, 10.f));
        cmd->add_option("--hp-factor", opt->hpFactor,
                        "bayes: the finest level's noise s is this times s_n (paper: 2)")
            ->capture_default_str()
            ->check(CLI::Range(1e-3f, 1e3f));
        cmd->add_option("--noise", opt->noise,
                        "bayes: fixed (use --sn/--pn), mad (s from the median absolute finest "
                        "HH coefficient), variance (s per band from the variance layer) or "
                        "auto (variance when the frame has the layer, else mad); shape --pn")
            ->capture_default_str();
        cmd->add_option("--log-floor", opt->floorRel,
                        "bayes: log floor relative to the channel's median positive value")
            ->capture_default_str()
            ->check(CLI::Range(1e-12f, 0.5f));
        cmd->add_option("--zeros", opt->zeros,
                        "bayes: restore (exact zeros stay 0, the paper's black) or denoise "
                        "(zeros are noise, as in low-spp renders)")
            ->capture_default_str();
        cmd->add_flag("--keep-mean", opt->keepMean,
                      "bayes: scale each channel to the input's mean (undoes the log "
                      "domain's geometric-mean bias)");
        cmd->add_option("--spins", opt->spins,
                        "bayes: shift invariance by cycle spinning over spins x spins shifts "
                        "(1: off; cost x spins^2)")
            ->capture_default_str()
            ->check(CLI::Range(1, 8));
        cmd->add_option("--colour", opt->colour,
                        "bayes: rgb (each log channel on its own) or opponent (log luminance "
                        "+ 2 log chroma)")
            ->capture_default_str();
        cmd->add_flag("--no-split", opt->noSplit,
                      "bayes: denoise the whole color even when direct/indirect exist");
    };
    method.run = [opt](vk::Context &context, const io::Frame &frame) {
        BayesOptions options = opt->Options();
        bool split = frame.Has("direct") && frame.Has("indirect");
        BayesResult bayes;
        DenoiseResult result;
        opt->UseVariance(frame, &options, &result.plan);
        if (split && !opt->noSplit) {
            bayes =
                BayesDenoiseSplit(context, frame.Get("direct"), frame.Get("indirect"), options);
        } else {
            bayes = BayesDenoise(context, frame.Get("color"), options);
            result.plan.push_back(
                split ? "no split (--no-split): the whole color is denoised"
                      : "no split: the frame has no direct and indirect layers, so the whole "
                        "color is denoised");
        }
        result.image = std::move(bayes.image);
        for (std::string &step : bayes.plan) result.plan.push_back(std::move(step));
        result.warnings = std::move(bayes.warnings);
        result.timings = std::move(bayes.timings);
        return result;
    };
    method.stages = [opt](vk::Context &context, const io::Frame &frame) {
        BayesOptions options = opt->Options();
        options.keepStages = true;
        std::vector<std::string> ignored;
        opt->UseVariance(frame, &options, &ignored);
        bool split = frame.Has("direct") && frame.Has("indirect") && !opt->noSplit;
        const Image &input = split ? frame.Get("indirect") : frame.Get("color");
        BayesResult gpu = split
                              ? BayesDenoiseSplit(context, frame.Get("direct"), input, options)
                              : BayesDenoise(context, input, options);
        ref::BayesRefOptions refOptions;
        refOptions.basis = options.basis;
        refOptions.swt = options.transform == BayesTransform::Swt;
        refOptions.levels = options.levels;
        refOptions.sn = options.sn;
        refOptions.pn = options.pn;
        refOptions.hpFactor = options.hpFactor;
        refOptions.floorRel = options.floorRel;
        refOptions.restoreZeros = options.restoreZeros;
        refOptions.opponent = options.opponent;
        refOptions.spins = options.spins;
        refOptions.keepMean = options.keepMean;
        refOptions.keepStages = true;
        // --noise auto: the estimate is host code on the downloaded coefficients, not a
        // kernel; the reference takes the GPU run's s_n so that the stages after it compare
        // the same model.
        if (options.noiseAuto && !options.variance) refOptions.snOverride = gpu.sn;
        // --noise variance: the reference makes its own estimate (ref::BayesVarianceNoise).
        refOptions.variance = options.variance;
        ref::BayesRefResult cpu = ref::BayesDenoise(input, refOptions);
        if (split) {
            // The direct layer added back, non-finite values as 0 (BayesDenoiseSplit).
            const Image &direct = frame.Get("direct");
            Image sum = cpu.image;
            for (size_t i = 0; i < sum.data.size(); ++i)
                sum.data[i] += std::isfinite(direct.data[i]) ? direct.data[i] : 0.f;
            gpu.stages.push_back({"split", gpu.image});
            cpu.stages.push_back({"split", sum});
        }
        if (gpu.stages.size() != cpu.stages.size())
            throw Error(fmt::format("bayes: {} stages on the GPU, {} on the CPU reference",
                                    gpu.stages.size(), cpu.stages.size()));
        std::vector<StagePair> pairs;
        for (size_t i = 0; i < gpu.stages.size(); ++i) {
            if (gpu.stages[i].first != cpu.stages[i].first)
                throw Error(fmt::format("bayes: stage {} is '{}' on the GPU, '{}' on the CPU",
                                        i, gpu.stages[i].first, cpu.stages[i].first));
            pairs.push_back({gpu.stages[i].first, std::move(gpu.stages[i].second),
                             std::move(cpu.stages[i].second)});
        }
        return pairs;
    };
    return method;
}

}  // namespace mcd::tool
