// Method `rhf`: Ray Histogram Fusion (host/methods/rhf.h) on the color and the histograms
// (Bin_0000..Bin_{3n}, the renderer's `--layers hist` or any renderer writing the authors'
// layout).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <vector>

#include "cpu_reference/exact_pixels.h"
#include "cpu_reference/kept_edges.h"
#include "cpu_reference/local_mean.h"
#include "cpu_reference/rhf.h"
#include "host/api/front_end.h"
#include "host/common/exact_pixels.h"
#include "host/common/kept_edges.h"
#include "host/common/local_mean.h"
#include "host/io/hints.h"
#include "host/kernels/rhf_select.h"
#include "host/methods/rhf.h"
#include "host/methods/run_memo.h"
#include "rhf/blockmax.h"
#include "rhf/terms.h"

namespace mcd::api {
namespace {

class Rhf : public FrontEndOf<RhfParams> {
  public:
    Rhf()
        : FrontEndOf(
              "rhf",
              {IntParam("patch-half", "patch half-size w (patches are (2w+1)^2)",
                        &RhfParams::patchHalf, 0, 20),
               IntParam("search-half", "search half-window b (the window is (2b+1)^2)",
                        &RhfParams::searchHalf, 0, 20),
               FloatParam("kappa", "threshold on the normalised chi-square patch distance",
                          &RhfParams::threshold, 0, 1e30),
               FloatParam("bright-veto",
                          "leave a candidate patch out when one of its pixels differs from its "
                          "counterpart in the saturated bins (samples brighter than the "
                          "histogram's range) by more than this: those bins' terms over the "
                          "harmonic mean of the two sample counts. Beyond the authors' tool, "
                          "whose distance lets a visible light into dark patches at few "
                          "samples; 0 is the authors' tool",
                          &RhfParams::brightVeto, 0, 1e30),
               FloatParam("bright-pool",
                          "finest scale: leave a candidate patch out when its bright samples "
                          "(saturated bins, colours summed) pooled over the patch, Q, and the "
                          "centre's, P, differ as rates over the boxes' pixels aQ, aP by "
                          "(P/aP - Q/aQ)^2 > this x (P/aP^2 + Q/aQ^2): a highlight's "
                          "line of bright samples is kept out of the dark patches around it. "
                          "Beyond the authors' tool; 0: off",
                          &RhfParams::brightPool, 0, 1e30),
               IntParam("knn", "nearest patches always averaged (finest scale)",
                        &RhfParams::knn, 0, 1681),
               IntParam("nscales",
                        "scales (fewer when a scale would be smaller than the search window)",
                        &RhfParams::scales, 1, 8),
               BoolParam("keep-negative",
                         "keep negative output values, as the authors' tool does (by default "
                         "the scale recombination's bicubic overshoot below 0 is clamped to 0)",
                         &RhfParams::keepNegative),
               IntParam("rhf-mean-radius",
                        "restore the input's local means over tents of 8x and 2x this radius "
                        "(beyond the paper: patch weights average fireflies into their dark "
                        "neighbours and so darken heavy-tailed frames), and cut lone spikes "
                        "before the filter, which spreads each over its search window (their "
                        "energy comes back with the means); 0: off",
                        &RhfParams::meanRadius, 0, 64)}) {}

    std::unique_ptr<FrontEnd> Clone() const override { return std::make_unique<Rhf>(*this); }
    std::string Summary() const override {
        return "Ray Histogram Fusion (needs the Bin_* histogram channels)";
    }
    std::vector<std::string> Uses() const override {
        return {"color", "hist", "zhist", "variance", "min", "max", "spp"};
    }
    std::string Missing(const Frame &frame) const override {
        return frame.Has("hist")
                   ? ""
                   : io::Lacks(frame, "no histogram channels (Bin_0000..)", {"hist"});
    }
    std::string Undemodulable(const Frame &frame, const std::string &layer) const override {
        // The histograms must be of the samples of color / guide: the renderer's zhist.
        if (layer == "pivot" && frame.Has("zhist")) return "";
        return fmt::format(
            "rhf needs histograms of the samples of color / {}, a 'zhist' layer ({}; "
            "mcdenoise render --layers zhist writes it for the pivot)",
            layer,
            layer == "pivot" ? fmt::format("{} has none", frame.path)
                             : "only the pivot has them");
    }

    Result Run(vk::Context &context, Inputs &inputs, const RunOptions &run) const override {
        RunSetup setup = SetupFor(inputs, run);
        setup.scalesUsed = whole.scalesUsed;
        setup.histScales = whole.histScales;
        const Image &color = inputs.Get("color");
        // Lone spikes, lights' rims and bright clusters cut before the filter (it spread
        // each over its search window, a square); the restore of local means gives the
        // spikes' and bridged clusters' energy back, the rims and other clusters take their
        // input back after the filter.
        Image variance = ExactVariance(ExactLayersOf(inputs));
        const std::shared_ptr<const Cuts> made = CutsFor(inputs, variance, setup);
        const Cuts &cuts = *made;
        const Image &cut = cuts.image;
        const size_t spikes = cuts.spikes.size();
        const std::vector<size_t> &rims = cuts.rims, &clusters = cuts.clusters;
        const bool anyCut =
            spikes > 0 || !rims.empty() || !clusters.empty() || !cuts.bridged.empty();
        if (setup.memo) setup.histId = inputs.LayerId(HistogramLayer(inputs));
        Result result = ResultOf(
            RhfDenoise(context, anyCut ? cut : color, Histograms(inputs), options, setup));
        // What the filter wrote counts as filtered: the restore tells the values given back
        // below (rims, clusters, exact pixels) by equality, and a mean that rounds onto its
        // input would be kept on the GPU or in the twin alone.
        MarkFiltered(color, &result.image);
        if (options.meanRadius > 0)
            result.plan.insert(
                result.plan.begin(),
                {fmt::format("spikes: {} lone pixels over {} times their neighbours' median "
                             "(channels summed) take that median before the filter (it would "
                             "spread each over its search window); the local mean gives their "
                             "energy back",
                             spikes, kSpike),
                 fmt::format("lights' rims: {} pixels over {} times their neighbours' median "
                             "beside a brighter light (its samples within {}%), of at least "
                             "{} samples, take their other neighbours' median before the "
                             "filter and their input back after it",
                             rims.size(), kSpike, kLightNoise * 100, kRimSamples),
                 fmt::format(
                     "bright clusters: {} pixels in clusters of {} or more within {}x{} over "
                     "{} times their neighbours' median, at most {} of each one's samples "
                     "above the histograms' range and too many for their share of the search "
                     "window's (binomial tail under {}) and at least the rest of it, take "
                     "their other neighbours' median before the filter and their input back "
                     "after it; {} more in clusters joined by a pixel with a bright sample "
                     "under {} times that touches {} or more groups of {} or more over pixels "
                     "each with a bright sample, spanning less than {} (a soft caustic split "
                     "at its middle), take that median before the filter too, but not their "
                     "input back: the local mean gives their energy back{}",
                     clusters.size(), kClusterLeast, kClusterSpan, kClusterSpan, kSpike,
                     kClusterShare, kClusterLevel, cuts.bridged.size(), kSpike, kBridgedGroups,
                     kBridgedSize, kClusterSpan,
                     Variance(inputs) ? "" : " (none: the frame has no variance layer)")});
        size_t exact = KeepExactPixels(color, variance, &result.image, ExactReach());
        GiveBack(color, rims, &result.image);
        GiveBack(color, clusters, &result.image);
        result.plan.push_back(
            variance.Empty()
                ? std::string("exact pixels: none known (no variance layer nor min, max and "
                              "spp)")
                : fmt::format("exact pixels: {} values with zero variance (every sample "
                              "equal, not black) keep their input; the energy moved into them "
                              "goes back to the values within {} that lost it",
                              exact, ExactReach()));
        if (run.keepStages) result.stages.push_back({"exact pixels", result.image});
        // A tile's restore waits for the assembled frame (Finish).
        if (int r = options.meanRadius; r > 0 && !finishWhole) {
            result.plan.push_back(
                "local mean: " +
                RestoreLocalMeansRebalanced(color, r, &result.image, Variance(inputs)));
            if (run.keepStages) result.stages.push_back({"local mean", result.image});
        }
        return result;
    }

    void PrepareKernels(vk::Context &context, Inputs &inputs) const override {
        RunSetup setup = SetupFor(inputs, RunOptions());
        // Looser than Run, on purpose: no kernel's key reads `histScales`, so it is left
        // unset; the selection kernels are listed even where the memo will serve the
        // selections (auto's candidates share their keys, and an unused one costs a build).
        setup.scalesUsed = whole.scalesUsed;
        PrepareRhfKernels(context, inputs.Width(), inputs.Height(), Histograms(inputs).channels,
                          options, setup);
    }

    void Finish(vk::Context &, Inputs &whole, Result *result) const override {
        result->plan.push_back("local mean (on the whole frame, after the tiles): " +
                               RestoreLocalMeansRebalanced(whole.Get("color"),
                                                           options.meanRadius, &result->image,
                                                           Variance(whole)));
    }

    // The probe cuts the run's rims and clusters, each from the probe's own colour, and gives
    // them the probe's input back: a pixel near a cut's threshold does not flip between the
    // run and the probe, which would read as a divergence (or a half0 difference) the run
    // does not have. On half0 the run's spikes too; on the perturbed colour the probe finds
    // its own (with the run's, SURE read rhf's error on caustic fireflies too low:
    // docs/methods/auto.md).
    std::unique_ptr<FrontEnd> ForProbe(vk::Context &, Inputs &run, bool onHalf) const override {
        if (options.meanRadius <= 0) return nullptr;
        auto probe = std::make_unique<Rhf>(*this);
        const ExactLayers layers = ExactLayersOf(run);
        // auto's rhf candidates cut their frame alike: the second takes the first's sets.
        std::string key;
        if (RunMemo *memo = run.Memo()) {
            key = CutSetsKey(run, layers, onHalf);
            probe->decidedKey = key;
            if (const auto *kept = memo->Find<std::shared_ptr<const CutSets>>(key)) {
                probe->decided = *kept;
                return probe;
            }
        }
        probe->decided = FindCutSets(run, ExactVariance(layers), onHalf);
        if (!key.empty())
            run.Memo()->Add(key,
                            std::make_shared<std::shared_ptr<const CutSets>>(probe->decided));
        return probe;
    }

    TileNeeds Tiling(vk::Context &context, Inputs &inputs) const override {
        const RhfParams &o = options;
        int scales = RhfScalesUsed(inputs.Width(), inputs.Height(), o);
        TileNeeds needs;
        // The exact pixels' energy returns within ExactReach, by weights read as far again.
        needs.reach = RhfReach(o, scales) + 2 * ExactReach() +
                      (o.meanRadius > 0 ? LocalMeanReach(o.meanRadius, true) + CutReach() : 0);
        needs.reachText = fmt::format(
            "the farthest over scales s < {} of (2 x patch half {} + search half {} + 2) x 2^s "
            "and the downsampler's 3-sigma taps, then bicubic U and D per recombination; "
            "twice the exact pixels' reach {}; the local mean's tents {} and {} for the cuts",
            scales, o.patchHalf, o.searchHalf, ExactReach(),
            o.meanRadius > 0 ? LocalMeanReach(o.meanRadius, true) : 0, CutReach());
        needs.finishReach = o.meanRadius > 0 ? LocalMeanReach(o.meanRadius, true) : 0;
        needs.align = 1 << (scales - 1);
        needs.sharesByWindow = true;
        // Per pixel: the histograms, the colour and its filtered image, the selection mask,
        // the bin maxima (a float per 8 pixels and bin plane) and, when on, the pooled veto's
        // counts (a float); each coarser scale s adds its histograms (1/4^s) and colour
        // images (a generous 8 per pixel in all), checked against the peak measured at 1080p.
        // The downsampler's scratch holds one buffer of histograms at a time (1/2^s of one
        // binding at most, below in fixedBytes).
        int planes = inputs.Get(HistogramLayer(inputs)).channels;
        double maskBytes = RhfMaskWords(o.searchHalf) * 4.0, histScales = 1,
               scratchBindings = 0;
        for (int s = 1; s < scales; ++s) {
            histScales += std::pow(0.25, s);
            scratchBindings += std::pow(0.5, s);
        }
        double colourImages = scales > 1 ? 8 : 2;
        needs.bytesPerPixel = planes * 4.0 * histScales + maskBytes + 3 * 4.0 * colourImages +
                              (planes - 1) * 4.0 / RHF_BLOCKMAX_WIDTH +
                              (o.brightPool > 0 ? 4.0 : 0.0);
        // One binding: the mask, a sixth of the histograms (their buffers at most), the maxima.
        // A histogram buffer holds at most 2^25 floats (RhfLayoutFor), less than a binding on
        // devices with larger ones: scaled so that PlanTiles' test against the binding is
        // that one.
        const double binding = std::min<double>(context.BindingBytes(), 4.0 * (1 << 25));
        const double histBytes = 4.0 * ((planes + RHF_HIST_SLOTS - 1) / RHF_HIST_SLOTS) *
                                 (double(context.BindingBytes()) / binding);
        needs.bindingBytesPerPixel =
            std::max({maskBytes, histBytes, (planes - 1) * 4.0 / RHF_BLOCKMAX_WIDTH});
        // The distances of a strip fill at most a binding; the two term buffers hold (b + 1)
        // of every 2b + 1 rows of offsets for as many rows and the strip's apron of 2w + b
        // rows more (rhf.cpp, RhfLayoutFor), for a window at most maxWidth wide: one row of
        // distance strip with its terms and apron must fit a binding, so wider frames run in
        // narrower tiles.
        const int side = 2 * o.searchHalf + 1, apron = 2 * o.patchHalf + o.searchHalf;
        const double maxFloats = binding / 4;
        needs.maxWidth =
            int(std::min(maxFloats / (double(o.searchHalf + 1) * side * (apron + 1)),
                         maxFloats / (double(side) * side)));
        needs.fixedBytes = binding * (1 + 2.0 * (o.searchHalf + 1) / side + scratchBindings) +
                           2 * 4.0 * apron * (o.searchHalf + 1) * side *
                               std::min(inputs.Width(), std::max(needs.maxWidth, 1));
        return needs;
    }

    std::unique_ptr<FrontEnd> ForTiles(vk::Context &, Inputs &frame) const override {
        auto copy = std::make_unique<Rhf>(*this);
        copy->whole.scalesUsed = RhfScalesUsed(frame.Width(), frame.Height(), options);
        copy->whole.histScales =
            RhfHistScales(frame.Get("color"), Histograms(frame), copy->whole.scalesUsed);
        return copy;
    }

    std::vector<Stage> Reference(vk::Context &, Inputs &inputs) const override {
        std::vector<std::pair<std::string, Image>> named;
        Image cut = inputs.Get("color");
        const Image variance = ExactVariance(ExactLayersOf(inputs));
        std::vector<size_t> rims, clusters, bridged;
        if (options.meanRadius > 0) {
            ref::CutSpikes(&cut, &variance);
            if (Variance(inputs))
                clusters = ref::CutBrightClusters(inputs.Get("color"), Histograms(inputs),
                                                  options.searchHalf, &cut, &bridged);
            Image spiked = cut;
            rims = ManySampled(spiked, Histograms(inputs), variance,
                               ref::CutLightRims(&cut, variance), &cut);
        }
        Image out = ref::Rhf(cut, Histograms(inputs), options, &named);
        // The pipeline's clamp of the recombination's overshoot (the reference's output is
        // raw).
        if (!options.keepNegative)
            for (float &v : out.data) v = v < 0 ? 0.f : v;
        const Image &given = inputs.Get("color");
        for (size_t i = 0; i < out.data.size(); ++i)
            out.data[i] = ref::FilteredValue(out.data[i], given.data[i]);
        ref::KeepExactPixels(inputs.Get("color"), variance, &out, ExactReach());
        GiveBack(inputs.Get("color"), rims, &out);
        GiveBack(inputs.Get("color"), clusters, &out);
        named.emplace_back("exact pixels", out);
        if (options.meanRadius > 0) {
            ref::RestoreLocalMeans(inputs.Get("color"), options.meanRadius, &out,
                                   Variance(inputs), kLocalMeanRebalance, true);
            named.emplace_back("local mean", std::move(out));
        }
        std::vector<Stage> stages;
        for (auto &[name, image] : named) stages.push_back({name, std::move(image)});
        return stages;
    }

  private:
    // The colour with the cuts made and the pixels cut (ascending, of the window); `lights`
    // (where asked) which pixels the rims were found beside.
    struct Cuts {
        Image image;
        std::vector<size_t> spikes, rims, clusters, bridged;
        std::vector<char> lights;
    };
    // The pixels a run cut, of its whole frame (ForProbe), and the lights beside its rims
    // (which their medians leave out); spikes on half0 only: on the perturbed colour the
    // probe finds its own.
    struct CutSets {
        int width = 0, height = 0;
        std::optional<std::vector<size_t>> spikes;
        std::vector<size_t> rims, clusters, bridged, rimLights;
    };

    // What Cut reads, for a memo key: the layers by their identities (Inputs::LayerId: each
    // hashed once a frame; the exact variance by the layers it is made from, so that a hit
    // does not make it), the options and the window.
    std::string CutInputs(Inputs &run, const ExactLayers &layers) const {
        auto id = [&](const Image *layer, const char *name) {
            return layer ? run.LayerId(name) : std::string("none");
        };
        return fmt::format(
            "colour {} exact variance of {} {} {} {} variance layer {} histograms {} search {} "
            "radius {} window {}x{} at {},{} of {}x{}",
            run.LayerId("color"), id(layers.variance, "variance"), id(layers.min, "min"),
            id(layers.max, "max"), id(layers.spp, "spp"), Variance(run) != nullptr,
            run.LayerId(HistogramLayer(run)), options.searchHalf, options.meanRadius,
            run.Width(), run.Height(), run.OriginX(), run.OriginY(), run.FrameWidth(),
            run.FrameHeight());
    }

    // The cut sets' memo key: everything Cut reads and what ForProbe keeps of it.
    std::string CutSetsKey(Inputs &run, const ExactLayers &layers, bool onHalf) const {
        return fmt::format("rhf.cuts {} spikes {}", CutInputs(run, layers), onHalf);
    }

    // This run's cuts: its own (Cut) or as its run decided (CutAsDecided). With auto's memo
    // they are made once for the same inputs: rhf and rhf at two scales cut the same colour,
    // and so do their probes (the same perturbed colour, the same decided sets). A whole
    // frame's own cuts keep their lights for ForProbe. The decided cuts' key is the sets' key
    // and the probe's inputs (its colour, variance and window, origin included).
    std::shared_ptr<const Cuts> CutsFor(Inputs &inputs, const Image &variance,
                                        const RunSetup &setup) const {
        RunMemo *memo = inputs.Memo();
        if (!memo || options.meanRadius <= 0 || (decided && decidedKey.empty()))
            return std::make_shared<const Cuts>(decided ? CutAsDecided(inputs, variance, setup)
                                                        : Cut(inputs, variance));
        if (!decided) return OwnCuts(inputs, variance);
        const std::string key = fmt::format("rhf.decided cuts by {} on {}", decidedKey,
                                            CutInputs(inputs, ExactLayersOf(inputs)));
        return Kept(*memo, key, [&] { return CutAsDecided(inputs, variance, setup); });
    }

    // The run's own cuts, from auto's memo where an earlier run made them; with their lights
    // on a whole frame only: ForProbe looks up no tile's.
    std::shared_ptr<const Cuts> OwnCuts(Inputs &inputs, const Image &variance) const {
        const bool whole =
            inputs.Width() == inputs.FrameWidth() && inputs.Height() == inputs.FrameHeight();
        return Kept(*inputs.Memo(), OwnCutsKey(inputs),
                    [&] { return Cut(inputs, variance, whole); });
    }

    // The own cuts' memo key.
    std::string OwnCutsKey(Inputs &inputs) const {
        return "rhf.own cuts " + CutInputs(inputs, ExactLayersOf(inputs));
    }

    // The cuts kept in `memo` under `key`, made there by `make` where none are.
    template <class Make>
    static std::shared_ptr<const Cuts> Kept(RunMemo &memo, const std::string &key,
                                            const Make &make) {
        if (const auto *kept = memo.Find<std::shared_ptr<const Cuts>>(key)) return *kept;
        auto cuts = std::make_shared<const Cuts>(make());
        memo.Add(key, std::make_shared<std::shared_ptr<const Cuts>>(cuts));
        return cuts;
    }

    // The run's cuts on `run` as ForProbe keeps them: the pixels of its whole frame and the
    // lights beside its rims; its spikes on half0 only. The cuts an earlier run kept in
    // auto's memo where there are (a frame run whole), else cut here and not kept: a tiled
    // run reads its tiles' cuts, never the whole frame's.
    std::shared_ptr<const CutSets> FindCutSets(Inputs &run, const Image &variance,
                                               bool onHalf) const {
        std::shared_ptr<const Cuts> found;
        if (RunMemo *memo = run.Memo(); memo && options.meanRadius > 0)
            if (const auto *kept = memo->Find<std::shared_ptr<const Cuts>>(OwnCutsKey(run)))
                found = *kept;
        if (!found || found->lights.empty())
            found = std::make_shared<const Cuts>(Cut(run, variance, true));
        const Cuts &cuts = *found;
        const std::vector<char> &lights = cuts.lights;
        auto sets = std::make_shared<CutSets>();
        sets->width = run.FrameWidth() > 0 ? run.FrameWidth() : run.Width();
        sets->height = run.FrameHeight() > 0 ? run.FrameHeight() : run.Height();
        auto toFrame = [&](const std::vector<size_t> &pixels) {
            std::vector<size_t> frame;
            for (size_t p : pixels)
                frame.push_back(size_t(int(p / run.Width()) + run.OriginY()) * sets->width +
                                size_t(int(p % run.Width()) + run.OriginX()));
            return frame;
        };
        if (onHalf) sets->spikes = toFrame(cuts.spikes);
        sets->clusters = toFrame(cuts.clusters);
        sets->bridged = toFrame(cuts.bridged);
        sets->rims = toFrame(cuts.rims);
        // The lights beside the rims, as the run told them.
        std::vector<size_t> rimLights;
        const int w = run.Width(), h = run.Height();
        for (size_t p : cuts.rims)
            for (int j = std::max(0, int(p / w) - 1); j <= std::min(h - 1, int(p / w) + 1); ++j)
                for (int i = std::max(0, int(p % w) - 1); i <= std::min(w - 1, int(p % w) + 1);
                     ++i)
                    if (lights[size_t(j) * w + i]) rimLights.push_back(size_t(j) * w + i);
        std::sort(rimLights.begin(), rimLights.end());
        rimLights.erase(std::unique(rimLights.begin(), rimLights.end()), rimLights.end());
        sets->rimLights = toFrame(rimLights);
        return sets;
    }

    // The cuts found on this colour (none with --rhf-mean-radius 0); with `withLights` their
    // lights set to which pixels the rims were found beside. Every input read here (the
    // layers, the variance's, the options) goes into CutInputs: auto's runs and probes take
    // the cuts and their sets by that key.
    Cuts Cut(Inputs &inputs, const Image &variance, bool withLights = false) const {
        Cuts cuts;
        const Image &color = inputs.Get("color");
        cuts.image = color;
        if (options.meanRadius <= 0) return cuts;
        CutSpikes(&cuts.image, &variance, &cuts.spikes);
        // Without the variance layer the restore would take a cluster back as a highlight
        // (by its neighbours) on top of the input it takes back.
        if (Variance(inputs))
            cuts.clusters = CutBrightClusters(color, Histograms(inputs), options.searchHalf,
                                              &cuts.image, &cuts.bridged);
        Image spiked = cuts.image;
        if (withLights) cuts.lights = Lights(spiked, variance);
        cuts.rims = ManySampled(spiked, Histograms(inputs), variance,
                                CutLightRims(&cuts.image, variance), &cuts.image);
        return cuts;
    }

    // Which pixels of `color` are lights by `variance` (as CutLightRims tells them); none
    // where the shapes differ.
    static std::vector<char> Lights(const Image &color, const Image &variance) {
        std::vector<char> light(color.PixelCount(), 0);
        if (variance.width != color.width || variance.height != color.height) return light;
        const Image sums = ChannelSums(color);
        for (size_t p = 0; p < light.size(); ++p) light[p] = Light(variance, sums, p);
        return light;
    }

    // The run's cuts (`decided`, of the whole frame) on this window's colour: each pixel takes
    // the median of its neighbours as the run's cut does (a cluster's outside the cluster, a
    // rim's of those the run told no lights), from this colour; the spikes its own where
    // `decided` has none. The probe's variance (auto doubles it for SURE) decides nothing.
    Cuts CutAsDecided(Inputs &inputs, const Image &variance, const RunSetup &setup) const {
        Cuts cuts;
        const Image &color = inputs.Get("color");
        cuts.image = color;
        const int w = color.width, h = color.height;
        cuts.clusters = InWindow(decided->clusters, w, h, setup);
        cuts.bridged = InWindow(decided->bridged, w, h, setup);
        cuts.rims = InWindow(decided->rims, w, h, setup);
        const size_t n = color.PixelCount();
        if (decided->spikes) {
            cuts.spikes = InWindow(*decided->spikes, w, h, setup);
            TakeNeighbourMedians(color, cuts.spikes, std::vector<char>(n, 0), &cuts.image);
        } else {
            CutSpikes(&cuts.image, &variance, &cuts.spikes);
        }
        std::vector<char> inCluster(n, 0);
        for (size_t p : cuts.clusters) inCluster[p] = 1;
        for (size_t p : cuts.bridged) inCluster[p] = 1;
        TakeNeighbourMedians(color, cuts.clusters, inCluster, &cuts.image);
        TakeNeighbourMedians(color, cuts.bridged, inCluster, &cuts.image);
        const Image spiked = cuts.image;
        std::vector<char> light(n, 0);
        for (size_t p : InWindow(decided->rimLights, w, h, setup)) light[p] = 1;
        TakeNeighbourMedians(spiked, cuts.rims, light, &cuts.image);
        return cuts;
    }

    // The pixels of `frame` (of the whole frame, as `decided`) within this w x h window.
    std::vector<size_t> InWindow(const std::vector<size_t> &frame, int w, int h,
                                 const RunSetup &setup) const {
        std::vector<size_t> window;
        for (size_t q : frame) {
            const int x = int(q % decided->width) - setup.frameX0,
                      y = int(q / decided->width) - setup.frameY0;
            if (x >= 0 && x < w && y >= 0 && y < h) window.push_back(size_t(y) * w + x);
        }
        return window;
    }

    // Set by ForProbe: the run's cuts, which its probe makes on its own colour, and their
    // key in auto's memo (empty without one).
    std::shared_ptr<const CutSets> decided;
    std::string decidedKey;

    // The frame's variance layer for the restore's highlights, or null.
    static const Image *Variance(Inputs &inputs) {
        return inputs.Has("variance") ? &inputs.Get("variance") : nullptr;
    }

    // How far rhf moves a value at the finest scale: a patch's pixels from the search
    // window's far side.
    int ExactReach() const { return 2 * options.patchHalf + options.searchHalf; }

    // How far the cuts read. A cluster's cut reads its search window (kClusterSpan - 1 and
    // searchHalf beyond a pixel) and, to tell it from a longer run, whether the pixels up to
    // kClusterSpan away are over (their neighbours, 1 more) or bridge two groups: a bridge
    // reads its neighbours (1), and whether the group a neighbour is in can be bridged, which
    // spans less than kClusterSpan: its pixels up to kClusterSpan - 1 from that neighbour tell
    // it ends, with their neighbours (1): kClusterSpan + 1 + kClusterSpan - 1 + 1 in all. A
    // spike's cut reads 2 pixels. The rims are found on the cut colour, their 9x9 window of
    // lights (kRimWindow) read after those cuts.
    int CutReach() const {
        const int clusters =
            std::max(2 * kClusterSpan + 1, kClusterSpan - 1 + options.searchHalf);
        return kRimWindow + std::max(2, clusters);
    }

    // The rims (CutLightRims) of at least kRimSamples samples (the histograms' count): with
    // fewer a rim one sample saw holds a large share of its light, and the filter's spread
    // along the light's edge is its coverage (cornell at 4 spp, 2 in auto's half-buffers);
    // those that hold no sample of their light (HoldsALightSample) and the others take their
    // value in `given` back in `cut`.
    static constexpr float kRimSamples = 16;
    static std::vector<size_t> ManySampled(const Image &given, const Image &histograms,
                                           const Image &variance,
                                           const std::vector<size_t> &rims, Image *cut) {
        std::vector<size_t> kept;
        const size_t n = given.PixelCount();
        const Image sums = rims.empty() ? Image() : ChannelSums(given);
        for (size_t p : rims) {
            const float count = histograms.data[(histograms.channels - 1) * n + p];
            if (count >= kRimSamples && HoldsALightSample(sums, variance, p, count)) {
                kept.push_back(p);
                continue;
            }
            for (int c = 0; c < given.channels; ++c)
                cut->data[c * n + p] = given.data[c * n + p];
        }
        return kept;
    }

    // Whether rim p holds at least one of its `count` samples' share of the brightest light
    // within kRimReach (`sums`: ChannelSums of the frame; a light as CutLightRims reads one):
    // a sample that saw the light; a dimmer caustic sample beside a light is no rim of it.
    static bool HoldsALightSample(const Image &sums, const Image &variance, size_t p,
                                  float count) {
        const int w = sums.width, h = sums.height, x = int(p % w), y = int(p / w);
        double brightest = 0;
        for (int j = std::max(0, y - kRimReach); j <= std::min(h - 1, y + kRimReach); ++j)
            for (int i = std::max(0, x - kRimReach); i <= std::min(w - 1, x + kRimReach); ++i) {
                const size_t q = size_t(j) * w + i;
                if (Light(variance, sums, q))
                    brightest = std::max(brightest, double(sums.data[q]));
            }
        return double(sums.data[p]) * count >= brightest;
    }

    // The pixels `rims` (CutLightRims, CutBrightClusters) take their input back.
    static void GiveBack(const Image &input, const std::vector<size_t> &rims, Image *output) {
        for (size_t p : rims)
            for (int c = 0; c < input.channels; ++c)
                output->data[c * input.PixelCount() + p] =
                    input.data[c * input.PixelCount() + p];
    }

    // The layers that tell which pixels are exact.
    static ExactLayers ExactLayersOf(Inputs &inputs) {
        ExactLayers layers;
        if (inputs.Has("variance")) layers.variance = &inputs.Get("variance");
        if (inputs.Has("min") && inputs.Has("max") && inputs.Has("spp")) {
            layers.min = &inputs.Get("min");
            layers.max = &inputs.Get("max");
            layers.spp = &inputs.Get("spp");
        }
        return layers;
    }

    // Set by ForTiles: the whole frame's scales and histogram rescales.
    struct {
        int scalesUsed = 0;
        std::vector<float> histScales;
    } whole;

    static std::string HistogramLayer(Inputs &inputs) {
        if (!inputs.Has("hist"))
            throw Error(fmt::format("{}: rhf needs the histogram channels Bin_0000..Bin_{{3n}} "
                                    "(render with --layers hist); the frame has none",
                                    inputs.Path()),
                        ErrorKind::MissingLayer);
        return "hist";
    }
    const Image &Histograms(Inputs &inputs) const {
        if (!inputs.Has("hist"))
            throw Error(fmt::format("{}: rhf needs the histogram channels Bin_0000..Bin_{{3n}} "
                                    "(render with --layers hist); the frame has none",
                                    inputs.Path()),
                        ErrorKind::MissingLayer);
        return inputs.Get("hist");
    }
};

}  // namespace

std::unique_ptr<FrontEnd> RhfFrontEnd() {
    return std::make_unique<Rhf>();
}

}  // namespace mcd::api
