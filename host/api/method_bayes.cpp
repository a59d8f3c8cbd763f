// Method `bayes`: Bayesian wavelet shrinkage in the log domain (Xu & Pattanaik;
// host/methods/bayes.h). With direct and indirect layers only the indirect part is denoised
// (section 4.1); otherwise the whole color, and the plan says so.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "cpu_reference/bayes_denoise.h"
#include "host/api/front_end.h"
#include "host/api/tiled_run.h"
#include "host/common/local_mean.h"
#include "host/io/hints.h"
#include "host/methods/bayes.h"
#include "host/wavelet.h"

namespace mcd::api {
namespace {

// The method's parameters, and whether the direct/indirect split is used.
struct BayesSettings {
    BayesParams method;
    bool noSplit = false;
};

class Bayes : public FrontEndOf<BayesSettings> {
  public:
    Bayes()
        : FrontEndOf(
              "bayes",
              {Nested(&BayesSettings::method,
                      EnumParam("bayes-wavelet", "haar, legall53 or cdf97", &BayesParams::basis,
                                {{"haar", WaveletBasis::Haar},
                                 {"legall53", WaveletBasis::LeGall53},
                                 {"cdf97", WaveletBasis::Cdf97}})),
               Nested(&BayesSettings::method,
                      EnumParam("bayes-transform",
                                "swt (stationary, undecimated: shift-invariant; the default, "
                                "measured better than dwt on all six cornell/interior 4/16/64 "
                                "spp frames, at ~3x the GPU time and 3 levels + 1 image-sized "
                                "planes per channel) or dwt (the decimated DWT)",
                                &BayesParams::transform,
                                {{"swt", BayesTransform::Swt}, {"dwt", BayesTransform::Dwt}})),
               Nested(
                   &BayesSettings::method,
                   IntParam("bayes-levels", "wavelet levels (clamped to what the image allows)",
                            &BayesParams::levels, 0, 64)),
               Nested(&BayesSettings::method,
                      FloatParam("sn", "noise s_n in the log domain (paper: 0.19, 0.6)",
                                 &BayesParams::sn, 0, 1e3)),
               Nested(&BayesSettings::method, FloatParam("pn", "noise shape p_n (paper: 1.5)",
                                                         &BayesParams::pn, 0.1, 10)),
               Nested(&BayesSettings::method,
                      FloatParam("hp-factor",
                                 "the finest level's noise s is this times s_n (paper: 2)",
                                 &BayesParams::hpFactor, 1e-3, 1e3)),
               Nested(&BayesSettings::method,
                      EnumParam("noise",
                                "fixed (use --sn/--pn), mad (s from the median absolute finest "
                                "HH coefficient, those exactly 0 left out: black pixels at the "
                                "log floor), variance (s per band from the variance "
                                "layer) or auto (variance when the frame has the layer, else "
                                "mad); shape --pn",
                                &BayesParams::noise,
                                {{"auto", BayesNoise::Auto},
                                 {"fixed", BayesNoise::Fixed},
                                 {"mad", BayesNoise::Mad},
                                 {"variance", BayesNoise::Variance}})),
               Nested(&BayesSettings::method,
                      FloatParam("log-floor",
                                 "log floor relative to the channel's median positive value",
                                 &BayesParams::floorRel, 1e-12, 0.5)),
               Nested(&BayesSettings::method,
                      EnumParam("zeros",
                                "restore (zeros inside black in their channel stay 0, the "
                                "paper's black; dark pixels lone among lit ones, samples that "
                                "missed the light, filled from their lit neighbours; other "
                                "zeros denoised; refused where the zeros kept black are too "
                                "dense to be black) or denoise (zeros are noise, as in low-spp "
                                "renders)",
                                &BayesParams::restoreZeros,
                                {{"restore", true}, {"denoise", false}})),
               Nested(&BayesSettings::method,
                      BoolParam("keep-mean",
                                "scale each channel to the input's mean (undoes the log "
                                "domain's geometric-mean bias)",
                                &BayesParams::keepMean)),
               Nested(&BayesSettings::method,
                      IntParam("bayes-mean-radius",
                               "restore the input's local means over tents of 8x, then 2x "
                               "this radius (the log domain darkens where the noise is large "
                               "relative to the signal; 0: off)",
                               &BayesParams::meanRadius, 0, 256)),
               Nested(&BayesSettings::method,
                      IntParam("spins",
                               "shift invariance by cycle spinning over spins x spins shifts "
                               "(1: off; cost x spins^2)",
                               &BayesParams::spins, 1, 8)),
               Nested(&BayesSettings::method,
                      EnumParam("colour",
                                "rgb (each log channel on its own) or opponent (log luminance "
                                "+ 2 log chroma)",
                                &BayesParams::opponent, {{"rgb", false}, {"opponent", true}})),
               BoolParam("no-split", "denoise the whole color even when direct/indirect exist",
                         &BayesSettings::noSplit)}) {}

    std::unique_ptr<FrontEnd> Clone() const override { return std::make_unique<Bayes>(*this); }
    std::string Summary() const override {
        return "Bayesian wavelet shrinkage in the log domain, Xu & Pattanaik (color; uses "
               "direct/indirect when present)";
    }
    std::vector<std::string> Uses() const override {
        return {"color", "variance", "direct", "indirect"};
    }
    std::string Missing(const Frame &frame) const override {
        return options.method.noise == BayesNoise::Variance && !frame.Has("variance")
                   ? io::Lacks(frame, "--noise variance needs a variance layer", {"variance"})
                   : "";
    }

    Result Run(vk::Context &context, Inputs &inputs, const RunOptions &run) const override {
        std::vector<std::string> plan;
        const Image *variance = Variance(inputs, &plan);
        RunSetup setup = SetupFor(inputs, run);
        setup.zerosDecided = zerosDecided;
        Result result;
        std::string mismatch = Split(inputs) ? SplitMismatch(inputs) : "";
        if (Split(inputs) && mismatch.empty()) {
            result = ResultOf(BayesDenoiseSplit(context, inputs.Get("direct"),
                                                inputs.Get("indirect"), options.method, setup,
                                                variance));
            if (run.keepStages) result.stages.push_back({"split", result.image});
        } else {
            result = ResultOf(
                BayesDenoise(context, inputs.Get("color"), options.method, setup, variance));
            plan.push_back(!mismatch.empty() ? "no split: " + mismatch
                           : options.noSplit && inputs.Has("direct") && inputs.Has("indirect")
                               ? "no split (--no-split): the whole color is denoised"
                               : "no split: the frame has no direct and indirect layers, so "
                                 "the whole color is denoised");
        }
        result.plan.insert(result.plan.begin(), plan.begin(), plan.end());
        return result;
    }

    // Bayes's noise estimate (the MAD of the finest bands) and log floor (the channel's
    // median) are frame-wide: tiles estimate their own. Beyond the device's memory the tiles
    // run with a halo of the filters' support at every level.
    TileNeeds Tiling(vk::Context &, Inputs &inputs) const override {
        const BayesParams &o = options.method;
        int levels = std::min(o.levels, MaxWaveletLevels(inputs.Width(), inputs.Height()));
        TileNeeds needs;
        needs.notLocal =
            "bayes estimates its noise (the finest bands' median absolute deviation, or the "
            "variance layer's band means) and its log floor (a median) per tile, not over the "
            "frame";
        int half = WaveletHalfSupport(o.basis);
        const int mean = o.meanRadius > 0 ? LocalMeanReach(o.meanRadius) : 0;
        // --zeros restore: the log stage's missed-sample fill reads the 3x3 neighbours before
        // the filters.
        const int fill = o.restoreZeros ? 1 : 0;
        needs.reach = 2 * half * ((1 << levels) - 1) + o.spins + mean + fill;
        needs.reachText = fmt::format(
            "{} analysis and synthesis filters reading {} sample(s) each way at 2^l for l < "
            "{}, the spins' shift, the local mean's coarse and fine tents {} and --zeros "
            "restore's 3x3 fill {}",
            WaveletName(o.basis), half, levels, mean, fill);
        needs.align = o.transform == BayesTransform::Dwt ? 1 << levels : 1;
        // Above the peak measured at 1080p (3 channels, swt, 3 levels). One binding
        // holds a channel's stationary coefficients (3 bands a level and the low band), or
        // the decimated transform of every channel.
        needs.bytesPerPixel = 160;
        needs.bindingBytesPerPixel = o.transform == BayesTransform::Swt
                                         ? 4.0 * (3 * levels + 1)
                                         : 4.0 * inputs.Get("color").channels;
        return needs;
    }

    // --zeros restore is refused or not on the whole frame (the layer the run denoises), once,
    // before any tile runs: a tile's zeros would decide for it alone, and a later tile could
    // fail after earlier ones ran. Auto's probe keeps its frame's decision the same way.
    std::unique_ptr<FrontEnd> ForTiles(vk::Context &, Inputs &whole) const override {
        auto tiled = std::make_unique<Bayes>(*this);
        if (zerosDecided || !options.method.restoreZeros) return tiled;
        if (Split(whole) && SplitMismatch(whole).empty()) {
            size_t rounded = 0;
            CheckBayesZeros(SplitIndirect(whole.Get("direct"), whole.Get("indirect"), &rounded),
                            options.method, " (indirect layer)");
        } else {
            CheckBayesZeros(whole.Get("color"), options.method);
        }
        tiled->zerosDecided = true;
        return tiled;
    }
    std::unique_ptr<FrontEnd> ForProbe(vk::Context &context, Inputs &run, bool) const override {
        return ForTiles(context, run);
    }

    std::vector<Stage> Reference(vk::Context &context, Inputs &inputs) const override {
        std::vector<std::string> ignored;
        const Image *variance = Variance(inputs, &ignored);
        bool split = Split(inputs) && SplitMismatch(inputs).empty();
        size_t rounded = 0;
        const Image input =
            split ? SplitIndirect(inputs.Get("direct"), inputs.Get("indirect"), &rounded)
                  : inputs.Get("color");
        ref::BayesRefRun r;
        r.keepStages = true;
        // --noise variance: the reference makes its own estimate (ref::BayesVarianceNoise).
        r.variance = variance;
        // --noise mad: the estimate is host code on the GPU's coefficients, not a kernel
        // (a median is not diffable); the reference takes the GPU run's s_n so that the
        // stages after it compare the same model.
        BayesNoise noise = options.method.noise;
        if (!variance && (noise == BayesNoise::Auto || noise == BayesNoise::Mad))
            r.madSn = BayesDenoise(context, input, options.method).sn;
        ref::BayesRefResult cpu = ref::BayesDenoise(input, options.method, r);
        std::vector<Stage> stages;
        for (auto &[name, image] : cpu.stages) stages.push_back({name, std::move(image)});
        if (split) {
            // The direct layer added back, non-finite values as 0 (BayesDenoiseSplit).
            const Image &direct = inputs.Get("direct");
            Image sum = cpu.image;
            for (size_t i = 0; i < sum.data.size(); ++i)
                sum.data[i] += std::isfinite(direct.data[i]) ? direct.data[i] : 0.f;
            stages.push_back({"split", std::move(sum)});
        }
        return stages;
    }

  private:
    bool Split(const Inputs &inputs) const {
        return inputs.Has("direct") && inputs.Has("indirect") && !options.noSplit;
    }

    // Where indirect holds negative light, denoising the split would change the image:
    // Blender's transparent film puts the Env pass in direct while Combined leaves the
    // background out, and accumulate's indirect = color - direct goes below 0 there. Why,
    // or empty when indirect's negative values stay within 1% of the colour's magnitude.
    // (direct + indirect may miss the colour by what neither holds: emitters seen directly.)
    // A tile decides on its whole frame, so that every tile decides alike.
    static std::string SplitMismatch(Inputs &inputs) {
        if (inputs.Width() == inputs.FrameWidth() && inputs.Height() == inputs.FrameHeight())
            return SplitMismatch(inputs.Get("color"), inputs.Get("indirect"));
        const Frame &frame = inputs.Source();
        return SplitMismatch(frame.Copy("color"), frame.Copy("indirect"));
    }

    static std::string SplitMismatch(const Image &color, const Image &indirect) {
        if (!color.SameShape(indirect)) return "";
        double negative = 0, total = 0;
        for (size_t i = 0; i < color.data.size(); ++i) {
            double c = color.data[i], n = indirect.data[i];
            if (!std::isfinite(c) || !std::isfinite(n)) continue;
            negative += std::max(-n, 0.0);
            total += std::fabs(c);
        }
        if (negative <= 0.01 * total) return "";
        return fmt::format(
            "indirect is negative by {:.3g}% of the color's magnitude (direct holds light the "
            "color leaves out: a transparent film's background?); the whole color is denoised",
            total > 0 ? 100 * negative / total : 100.0);
    }

    // The variance layer when the noise reads it (--noise variance, or auto on a frame with
    // one); say which estimate --noise auto took.
    const Image *Variance(Inputs &inputs, std::vector<std::string> *plan) const {
        BayesNoise noise = options.method.noise;
        bool has = inputs.Has("variance");
        if (noise == BayesNoise::Variance && !has)
            throw Error("bayes: --noise variance needs a variance layer; the frame has none",
                        ErrorKind::MissingLayer);
        if (noise == BayesNoise::Variance || (noise == BayesNoise::Auto && has)) {
            if (noise == BayesNoise::Auto)
                plan->push_back(
                    "--noise auto: the frame has a variance layer: noise per band from it "
                    "(--noise variance)");
            return &inputs.Get("variance");
        }
        if (noise == BayesNoise::Auto)
            plan->push_back(
                "--noise auto: no variance layer: noise from the finest band's median "
                "non-zero |y| (--noise mad)");
        return nullptr;
    }

    // Set by ForTiles: --zeros restore already judged on the whole frame.
    bool zerosDecided = false;
};

}  // namespace

std::unique_ptr<FrontEnd> BayesFrontEnd() {
    return std::make_unique<Bayes>();
}

}  // namespace mcd::api
