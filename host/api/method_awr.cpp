// Method `awr`: AWR's wavelet reconstruction (host/methods/awr.h) on the frame's color and
// per-pixel variance of the mean, from the variance layer or the sample range.
#include <fmt/format.h>

#include <algorithm>

#include "cpu_reference/awr_reconstruct.h"
#include "cpu_reference/exact_pixels.h"
#include "cpu_reference/highlights.h"
#include "cpu_reference/input_minimum.h"
#include "host/api/front_end.h"
#include "host/api/tiled_run.h"
#include "host/common/exact_pixels.h"
#include "host/common/highlights.h"
#include "host/common/input_minimum.h"
#include "host/io/hints.h"
#include "host/methods/awr.h"
#include "host/wavelet.h"

namespace mcd::api {
namespace {

// The method's parameters, and where the variance comes from.
struct AwrSettings {
    AwrParams method;
    // auto prefers the variance layer: the paper's range bound, (max - min)^2 / spp,
    // over-smooths (README, Method awr).
    std::string variance = "auto";
    // Highlights taken out before the reconstruction (host/common/highlights.h); 0: off.
    float highlights = 16;
    // The output raised to the input's minimum over windows of this radius
    // (host/common/input_minimum.h); 0: off.
    int clamp = 1;
};

// The window radius of the highlights' medians.
constexpr int kHighlightRadius = 3;

// Crests are cut within this distance of highlights, to the input's maximum over 3x3.
constexpr int kCrestReach = 6;

// How far the energy moved into exact pixels goes back: the finest levels' reach.
constexpr int kExactReach = 8;

bool HasRange(const Frame &frame) {
    return frame.Has("min") && frame.Has("max") && frame.Has("spp");
}

class Awr : public FrontEndOf<AwrSettings> {
  public:
    Awr()
        : FrontEndOf(
              "awr",
              {Nested(&AwrSettings::method,
                      EnumParam("basis", "haar, legall53 or cdf97", &AwrParams::basis,
                                {{"haar", WaveletBasis::Haar},
                                 {"legall53", WaveletBasis::LeGall53},
                                 {"cdf97", WaveletBasis::Cdf97}})),
               Nested(&AwrSettings::method,
                      IntParam("levels", "wavelet levels (-1: as many as fit)",
                               &AwrParams::levels, -1, 64)),
               Nested(&AwrSettings::method, FloatParam("cs", "smoothing constant c_s (eq. 11)",
                                                       &AwrParams::cs, 0, 1e6)),
               Nested(&AwrSettings::method,
                      FloatParam("renorm",
                                 "sum of the squared 1D filters in the variance DWT (paper: "
                                 "2^-1/2)",
                                 &AwrParams::renorm, 1e-6, 1e6)),
               ChoiceParam("variance",
                           "where the per-pixel variance comes from: auto (the variance "
                           "layer if present, else min/max/spp), range (the paper's "
                           "(max-min)^2/spp), layer",
                           &AwrSettings::variance, {"auto", "range", "layer"}),
               Nested(&AwrSettings::method,
                      IntParam("awr-spins",
                               "cycle spinning over N x N shifts of the DWT's grid (1: the "
                               "paper's reconstruction; beyond the paper; cost x N^2)",
                               &AwrParams::spins, 1, 8)),
               FloatParam(
                   "awr-highlights",
                   fmt::format(
                       "a pixel over this times the median of its 7x7 window (channels "
                       "summed), with 2 of its 8 neighbours so too and 2 of its standard "
                       "deviations above that median, is a highlight: reconstructed at "
                       "the median and given its input back after, so a light's energy "
                       "does not ring into the dim pixels around it; highlights then grow "
                       "up to 4 rings into a light's interior, not past k x the frame's "
                       "mean, and a region still growing after that (a large light) is "
                       "given its grown pixels back; with a max layer, pixels over k x "
                       "their median and the frame's mean whose largest sample is no more "
                       "than {} x the highlights' median one (fixed) are highlights too, "
                       "as are those over k / {} x the mean with at least {} of their 8 "
                       "neighbours over k x their medians (and 1e-3 x the mean) and that "
                       "sample no more than {} x (a glint's streak; fixed) "
                       "(beyond the paper; 0: off)",
                       kSparseLightSampleRatio, 1 / kStreakMeanShare, kStreakNeighbours,
                       kStreakSampleRatio),
                   &AwrSettings::highlights, 0, 1e6),
               IntParam(
                   "awr-clamp",
                   fmt::format("the output raised to the minimum of the input over the "
                               "(2N+1)^2 window around each pixel, per channel: the "
                               "synthesis's troughs (dark spots beside highlights) are "
                               "cut; values within {} pixels of a highlight, and {} past "
                               "a large light's rim (a light over k x the frame's mean, "
                               "{} standard deviations above 0), are lowered to the "
                               "input's maximum over the same window, highlights, lights "
                               "and rims left out, and within {} of a full light's "
                               "interior held between their own input and the mean of "
                               "their {}x{} window minus and plus {} of its standard "
                               "deviations (crests and troughs; beyond the paper; 0: all "
                               "off)",
                               kCrestReach, kLightRimReach, kLightRimSigmas, kFullLightReach,
                               2 * kRimMeanRadius + 1, 2 * kRimMeanRadius + 1, kRimCutSigmas),
                   &AwrSettings::clamp, 0, 8)}) {}

    std::unique_ptr<FrontEnd> Clone() const override { return std::make_unique<Awr>(*this); }
    std::string Summary() const override {
        return "Adaptive Wavelet Rendering's reconstruction (needs variance or min/max/spp)";
    }

    std::vector<std::string> Uses() const override {
        return {"color", "variance", "min", "max", "spp"};
    }

    std::string Missing(const Frame &frame) const override {
        const std::string &source = options.variance;
        if (source == "layer" && !frame.Has("variance"))
            return io::Lacks(frame, "no variance layer", {"variance"});
        if (source == "range" && !HasRange(frame))
            return io::Lacks(frame, "no min, max and spp layers", {"min", "max", "spp"});
        if (!HasRange(frame) && !frame.Has("variance"))
            return io::Lacks(frame, "no variance layer nor min, max and spp", {"variance"});
        return "";
    }

    Result Run(vk::Context &context, Inputs &inputs, const RunOptions &run) const override {
        std::string why;
        Image variance = Variance(inputs, &why);
        const Image &color = inputs.Get("color");
        std::string sparseWhyOff;
        HighlightSplit split = Split(color, variance, inputs, &sparseWhyOff);
        Result result = ResultOf(AwrReconstruct(context, split.count ? split.base : color,
                                                split.count ? split.baseVariance : variance,
                                                options.method, SetupFor(inputs, run)));
        result.plan.insert(result.plan.begin(), why);
        if (split.count) {
            AddHighlights(color, split, &result.image);
            result.plan.push_back(fmt::format(
                "highlights: {} pixels over {} x their 7x7 median (with 2 of 8 neighbours, 2 "
                "standard deviations above it, or 1 neighbour, 4 above) and {} grown from them "
                "reconstructed at that median and given their input back",
                split.count - split.grown - split.sparse, options.highlights, split.grown));
            if (split.sparse)
                result.plan.push_back(fmt::format(
                    "sparse lights: {} pixels over {} x their 7x7 median and the frame's mean "
                    "whose largest sample is at most {} x the highlights' median one (a "
                    "light's reflection few samples saw), or over {} x the mean with at least "
                    "{} "
                    "of 8 neighbours over k x their medians and that sample at most {} x (a "
                    "glint's streak), and a two-pixel reflection's dimmer pixel (the only "
                    "neighbour over its median of one, with no other neighbour so itself, not "
                    "a highlight, its largest sample at most {} x the light's), taken out as "
                    "highlights too",
                    split.sparse, options.highlights, kSparseLightSampleRatio,
                    kStreakMeanShare * options.highlights, kStreakNeighbours,
                    kStreakSampleRatio, kPartnerSampleRatio));
            if (run.keepStages && !result.stages.empty())
                result.stages.push_back({"highlights", result.image});
        }
        if (!sparseWhyOff.empty())
            result.plan.push_back(fmt::format(
                "sparse lights off: {} (a light's reflection few samples saw is filtered as a "
                "firefly)",
                sparseWhyOff));
        size_t exact = KeepExactPixels(color, variance, &result.image, kExactReach);
        result.plan.push_back(fmt::format(
            "exact pixels: {} values with zero variance (every sample equal, not black) keep "
            "their input; the energy moved into them goes back to the values within {} that "
            "lost it",
            exact, kExactReach));
        // An idle run (the output is the input) has no stages to add to.
        if (run.keepStages && !result.stages.empty())
            result.stages.push_back({"exact pixels", result.image});
        if (options.clamp > 0) {
            size_t clamped = RaiseToInputMinimum(color, options.clamp, &result.image);
            result.plan.push_back(fmt::format(
                "troughs cut: {} values below the input's minimum over their {}x{} window "
                "raised to it",
                clamped, 2 * options.clamp + 1, 2 * options.clamp + 1));
            if (run.keepStages && !result.stages.empty())
                result.stages.push_back({"input minimum", result.image});
            if (split.count) {
                size_t lowered = LowerToInputMaximumNearHighlights(
                    color, split.highlight, kCrestReach, options.clamp, &result.image);
                result.plan.push_back(fmt::format(
                    "crests near lights cut: {} values within {} of a highlight above the "
                    "input's maximum over their {}x{} window (highlights left out) lowered to "
                    "it",
                    lowered, kCrestReach, 2 * options.clamp + 1, 2 * options.clamp + 1));
                if (run.keepStages && !result.stages.empty())
                    result.stages.push_back({"input maximum near lights", result.image});
            }
            CutBeyondLightRims(color, variance, inputs, run, &result);
        }
        return result;
    }

    // The decimated DWT's coarse bands span the frame (levels -1: as many as it allows), so
    // tiles cannot give the untiled result; beyond the device's memory the tiles run at
    // most kTileLevels levels with a halo of the filters' support at those levels.
    TileNeeds Tiling(vk::Context &, Inputs &inputs) const override {
        int levels = TileLevels(inputs.Width(), inputs.Height());
        int channels = inputs.Get("color").channels;
        TileNeeds needs;
        needs.notLocal = fmt::format(
            "awr's decimated DWT ({} levels on the whole frame) has coarse bands whose support "
            "spans it, and its grid depends on the frame's size; a tile runs {} level(s); the "
            "highlights' undo of a still-growing light spans its whole connected region "
            "(unbounded); the tiles read the frame's mean for the highlights and the lights "
            "beyond whose rims crests are cut, its highlights' median largest sample for the "
            "sparse lights and whether its max layer serves them and the rims (passed in)",
            options.method.levels < 0 ? MaxWaveletLevels(inputs.Width(), inputs.Height())
                                      : options.method.levels,
            levels);
        // Analysis and synthesis at 2^l per level l, and the spins' shifts.
        int half = WaveletHalfSupport(options.method.basis);
        // The highlights read their neighbours' windows, grow and look one ring further; a
        // sparse light's partner reads the light's neighbours (one ring further again); the
        // crests near them read theirs; the rim cut reads a full light within kFullLightReach
        // and its neighbours, and lights and rims over its window; the clamp its window.
        const int highlights =
            options.highlights > 0
                ? std::max({kHighlightRadius + 1 + kHighlightGrowRounds + 1 + 1 + kCrestReach,
                            1 + kLightRimReach + 1, kFullLightReach + 1, kRimMeanRadius + 1})
                : 0;
        needs.reach =
            2 * half * ((1 << levels) - 1) + options.method.spins + highlights + options.clamp;
        needs.reachText = fmt::format(
            "{} analysis and synthesis filters reading {} sample(s) each way at 2^l for l < "
            "{}, the spins' shift, {} for the highlights' windows, growth and its check "
            "round, the sparse lights' partners and the crest cut (or the lights' rims and the "
            "cut beyond them, whichever reads further), and {} for the input's minimum",
            WaveletName(options.method.basis), half, levels, highlights, options.clamp);
        needs.align = 1 << levels;
        needs.bytesPerPixel = 4.0 * channels * 4;
        needs.bindingBytesPerPixel = 4.0 * channels;
        return needs;
    }

    std::unique_ptr<FrontEnd> ForTiles(vk::Context &, Inputs &whole) const override {
        auto copy = std::make_unique<Awr>(*this);
        copy->options.method.levels = TileLevels(whole.Width(), whole.Height());
        // The highlights' floor and growth stop read the whole frame's mean, not the tile's,
        // and the sparse lights compare with the whole frame's highlights.
        if (options.highlights > 0 && whole.Has("color")) {
            const Image &color = whole.Get("color");
            copy->frameMean = HighlightFrameMean(color);
            copy->sparseWhyOff = SparseLightsOff(whole, color);
            copy->lightSample = 0;
            if (whole.Has("max") && copy->sparseWhyOff.empty()) {
                std::string why;
                Image variance = Variance(whole, &why);
                if (Splits(color, variance))
                    copy->lightSample = HighlightSampleMedian(
                        whole.Get("max"), SplitHighlights(color, &variance, options.highlights,
                                                          kHighlightRadius, copy->frameMean)
                                              .highlight);
            }
        }
        return copy;
    }

    std::vector<Stage> Reference(vk::Context &, Inputs &inputs) const override {
        std::string why;
        Image variance = Variance(inputs, &why);
        std::vector<std::pair<std::string, Image>> cpu;
        const Image &color = inputs.Get("color");
        Image base, baseVariance;
        std::vector<char> highlight;
        if (Splits(color, variance)) {
            highlight = ref::SplitHighlights(color, &variance, options.highlights,
                                             kHighlightRadius, &base, &baseVariance);
            if (inputs.Has("max") && SparseLightsOff(inputs, color).empty())
                ref::AddSparseLights(color, &variance, inputs.Get("max"), options.highlights,
                                     kHighlightRadius, lightSample, &highlight, &base,
                                     &baseVariance);
        }
        bool any = std::find(highlight.begin(), highlight.end(), 1) != highlight.end();
        Image out = ref::AwrReconstruct(any ? base : color, any ? baseVariance : variance,
                                        options.method, &cpu);
        if (any) {
            ref::AddHighlights(color, base, highlight, &out);
            if (!cpu.empty()) cpu.emplace_back("highlights", out);
        }
        ref::KeepExactPixels(color, variance, &out, kExactReach);
        if (!cpu.empty()) cpu.emplace_back("exact pixels", out);
        if (options.clamp > 0) {
            ref::RaiseToInputMinimum(color, options.clamp, &out);
            if (!cpu.empty()) cpu.emplace_back("input minimum", out);
            if (any) {
                ref::LowerToInputMaximumNearHighlights(color, highlight, kCrestReach,
                                                       options.clamp, &out);
                if (!cpu.empty()) cpu.emplace_back("input maximum near lights", out);
            }
            if (Splits(color, variance)) {
                std::string rimsOff;
                ref::ClampBeyondLightRims(color, variance, RimSamples(inputs, color, &rimsOff),
                                          options.highlights, frameMean, kLightRimReach,
                                          options.clamp, &out);
                if (!cpu.empty()) cpu.emplace_back("window bounds beyond light rims", out);
            }
        }
        std::vector<Stage> stages;
        for (auto &[name, image] : cpu) stages.push_back({name, std::move(image)});
        return stages;
    }

  private:
    // Set by ForTiles: the whole frame's mean for the highlights and its highlights' median
    // largest sample for the sparse lights (-1: the input's own), and why the sparse lights
    // are off there.
    double frameMean = -1, lightSample = -1;
    std::string sparseWhyOff;

    // Whether highlights are split: on, and inputs awr accepts (it refuses the others,
    // naming them).
    bool Splits(const Image &color, const Image &variance) const {
        if (!(options.highlights > 0) || !color.SameShape(variance)) return false;
        for (float v : variance.data)
            if (!(std::isfinite(v) && v >= 0)) return false;
        return true;
    }
    // The highlights and, with a max layer that serves them, the sparse lights; why the max
    // layer does not serve them in *whyOff.
    HighlightSplit Split(const Image &color, const Image &variance, Inputs &inputs,
                         std::string *whyOff) const {
        if (!Splits(color, variance)) return HighlightSplit();
        HighlightSplit split =
            SplitHighlights(color, &variance, options.highlights, kHighlightRadius, frameMean);
        *whyOff = lightSample >= 0 ? sparseWhyOff : SparseLightsOff(inputs, color);
        if (inputs.Has("max") && whyOff->empty())
            AddSparseLights(color, &variance, inputs.Get("max"), options.highlights,
                            kHighlightRadius, lightSample, &split);
        return split;
    }

    // The frame's mean the lights read: the whole frame's in a tile.
    double MeanOf(const Image &color) const {
        return frameMean >= 0 ? frameMean : HighlightFrameMean(color);
    }
    // The max layer the light rims read, where it serves (else none: lights without rims,
    // why in *whyOff); a tile reads the whole frame's decision, as the sparse lights do.
    const Image *RimSamples(Inputs &inputs, const Image &color, std::string *whyOff) const {
        *whyOff = !inputs.Has("max") ? "the frame has no max layer"
                  : lightSample >= 0 ? sparseWhyOff
                                     : SparseLightsOff(inputs, color);
        return whyOff->empty() ? &inputs.Get("max") : nullptr;
    }
    // Values beyond the rims of lights sure of themselves held (a large light's noisy rim
    // spread into the dim pixels past it), with the plan's line and the stage.
    void CutBeyondLightRims(const Image &color, const Image &variance, Inputs &inputs,
                            const RunOptions &run, Result *result) const {
        if (!Splits(color, variance)) return;
        std::string rimsOff;
        LightRims rims = FindLightRims(color, variance, RimSamples(inputs, color, &rimsOff),
                                       options.highlights, MeanOf(color));
        size_t moved = ClampBeyondLightRims(color, variance, rims, kLightRimReach,
                                            options.clamp, &result->image);
        result->plan.push_back(fmt::format(
            "crests and troughs beyond light rims held: {} values within {} of {} light "
            "pixels (over {} x the frame's mean, {} standard deviations above 0; none where "
            "the color has NaN/Inf, in tiles each tile's own) and {} rim pixels (a light's "
            "neighbours with a sample at least {} x its value{}), not beside a full light (one "
            "{} standard deviations below its value at least {} x the brightest light beside "
            "it: its neighbours are its rim), above the input's maximum over their {}x{} "
            "window (lights and rims left out) lowered to it; within {} of a full light held "
            "between their own input and their {}x{} window's mean minus and plus {} of its "
            "standard deviations",
            moved, kLightRimReach, rims.lights, options.highlights, kLightRimSigmas, rims.rims,
            kLightRimSampleShare, rimsOff.empty() ? "" : "; none: " + rimsOff, kFullLightSigmas,
            kFullLightShare, 2 * options.clamp + 1, 2 * options.clamp + 1, kFullLightReach,
            2 * kRimMeanRadius + 1, 2 * kRimMeanRadius + 1, kRimCutSigmas));
        if (run.keepStages && !result->stages.empty())
            result->stages.push_back({"window bounds beyond light rims", result->image});
    }

    // Why the frame's max layer (its per-pixel largest sample) cannot serve the sparse
    // lights ("" when it can, or the frame has none).
    static std::string SparseLightsOff(Inputs &inputs, const Image &color) {
        if (!inputs.Has("max")) return "";
        const Image &maxSample = inputs.Get("max");
        if (!maxSample.SameShape(color)) return "the max layer is not the color's shape";
        for (float v : maxSample.data)
            if (!std::isfinite(v)) return "the max layer has NaN/Inf values";
        return "";
    }

    static constexpr int kTileLevels = 5;
    int TileLevels(int width, int height) const {
        int levels =
            options.method.levels < 0 ? MaxWaveletLevels(width, height) : options.method.levels;
        return std::min(levels, kTileLevels);
    }

    // The per-pixel variance of the mean from the layers the frame has.
    Image Variance(Inputs &inputs, std::string *why) const {
        const std::string &source = options.variance;
        bool range = inputs.Has("min") && inputs.Has("max") && inputs.Has("spp");
        bool layer = inputs.Has("variance");
        if (source == "layer" || (source == "auto" && layer)) {
            if (!layer)
                throw Error(
                    fmt::format("{}: --variance layer needs a variance layer", inputs.Path()),
                    ErrorKind::MissingLayer);
            *why = "variance of the mean from the frame's variance layer";
            return inputs.Get("variance");
        }
        if (!range)
            throw Error(
                fmt::format("{}: awr needs a variance layer or min, max and spp layers; "
                            "the frame has neither",
                            inputs.Path()),
                ErrorKind::MissingLayer);
        *why = "variance of the mean from the sample range, (max - min)^2 / spp (AWR 4.2)";
        return AwrVarianceFromRange(inputs.Get("min"), inputs.Get("max"), inputs.Get("spp"));
    }
};

}  // namespace

std::unique_ptr<FrontEnd> AwrFrontEnd() {
    return std::make_unique<Awr>();
}

}  // namespace mcd::api
