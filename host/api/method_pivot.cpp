// Method `pivot`: Ershov et al.'s pivot-image filter (host/methods/pivot.h), planefit or the
// bilateral baseline, with the frame's guides and section 8's partial images when present.
#include <fmt/format.h>

#include <algorithm>

#include "cpu_reference/auto_combine.h"
#include "cpu_reference/kept_edges.h"
#include "cpu_reference/local_mean.h"
#include "cpu_reference/pivot_chroma.h"
#include "cpu_reference/pivot_filter.h"
#include "cpu_reference/pivot_spikes.h"
#include "host/api/front_end.h"
#include "host/common/kept_edges.h"
#include "host/common/local_mean.h"
#include "host/common/pivot_chroma.h"
#include "host/common/pivot_spikes.h"
#include "host/io/hints.h"
#include "host/methods/auto.h"
#include "host/methods/pivot.h"
#include "pivot/gather.h"
#include "pivot/pivot.h"

namespace mcd::api {
namespace {

// The input-range bound's widening, in standard deviations of the input's noise: none.
// Widened, it left the overshoots of plain frames, whose noise estimated from the frame is
// large at highlights; pixels of variance 0 are left instead (a dim frame's windows of few
// samples that all missed the light its fits see).
constexpr double kPivotRangeSpread = 0;

// The method's parameters, and which layers feed it.
struct PivotSettings {
    PivotParams method;
    std::string guides = "auto", noise = "auto", layer = "auto";
    bool noPartials = false;
    // Keep the values beside other ids as the filter left them (ClampEdgeFitsToSides and
    // ClampKeptEdgeValues off).
    bool keepEdges = false;
    // Scale the output of pixels whose pivot is a lone spike (ScalePivotSpikes).
    bool spikes = false;
    // Fit the pixels whose pivot is a cluster of spikes as the others (KeepPivotSpikeClusters
    // off).
    bool fitClusters = false;
    // The output held to the range of its input's (2 r + 1)^2 window (BoundToInputRange);
    // 0: off.
    int range = 1;
    // The output bound to k standard deviations of the input's noise (BoundToNoise); 0: off.
    float bound = 3;
    // Set by ForTiles: the whole frame's thresholds (of the pivot, of each partial's).
    std::vector<float> thresholds;
    std::vector<std::vector<float>> partialThresholds;
};

// Lone pivot spikes that few samples saw scaled in the result's image (--pivot-spikes), with
// the plan's line and the stage. Only the sample variance tells how few samples saw a pixel:
// the frame's estimate is large at every highlight. Returns the colour the local means are
// restored from, the scaled pixels at their output (a firefly is noise, not energy to give
// back over the tents around it); empty where it is the input.
Image ScaleSpikes(const PivotInputs &in, const RunOptions &run, Result *result) {
    if (!in.variance) {
        result->plan.push_back("pivot spikes: not looked for (no variance layer)");
        return {};
    }
    const std::vector<size_t> spikes =
        ScalePivotSpikes(*in.color, *in.pivot, *in.variance, &result->image);
    Image restoreFrom;
    if (!spikes.empty()) {
        restoreFrom = *in.color;
        for (size_t p : spikes)
            for (int c = 0; c < restoreFrom.channels; ++c)
                restoreFrom.Plane(c)[p] = result->image.Plane(c)[p];
    }
    result->plan.push_back(fmt::format(
        "pivot spikes: {} pixels whose pivot is a lone spike (over {} times its neighbours' "
        "median) and whose colour's standard deviation is at least {} of it (the variance "
        "layer) take their filtered z times their neighbours' pivot, their firefly not "
        "restored",
        spikes.size(), kPivotSpike, kPivotSpikeNoise));
    if (run.keepStages) result->stages.push_back({"pivot spikes", result->image});
    return restoreFrom;
}

// Filtered values beside other ids held between their two sides (ClampEdgeFitsToSides), with
// the plan's line and the stage.
void HoldEdgeSides(const PivotInputs &in, const RunOptions &run, Result *result) {
    if (!in.objectId && !in.partId) {
        result->plan.push_back("edge sides: not looked at (no ids)");
        if (run.keepStages) result->stages.push_back({"edge sides", result->image});
        return;
    }
    const size_t sides =
        ClampEdgeFitsToSides(*in.color, *in.pivot, in.objectId, in.partId, &result->image);
    result->plan.push_back(fmt::format(
        "edge sides: {} filtered values beside other ids whose color / pivot lay beyond both "
        "sides' (the pixels off the edge in their 5x5 window, of their own ids and of others) "
        "and their outline's (the median of their own ids' inputs beside other ids there) "
        "clamped to that range (a pixel that mixes two sides lies between them; planes "
        "extrapolated to an edge do not always; an outline of its own, a glass's, shows in the "
        "inputs along it)",
        sides));
    if (run.keepStages) result->stages.push_back({"edge sides", result->image});
}

// Pixels whose pivot is a cluster of spikes keep their input (KeepPivotSpikeClusters), with
// the plan's line and the stage.
void KeepSpikeClusters(const PivotInputs &in, const RunOptions &run, Result *result) {
    const size_t clusters =
        KeepPivotSpikeClusters(*in.color, *in.pivot, in.objectId, in.partId, &result->image)
            .size();
    result->plan.push_back(fmt::format(
        "spike clusters: {} pixels whose pivot is over {} times its neighbours' median with 2 "
        "or more of them so (a light seen in a mirror: the albedo followed it; no fit of the "
        "surface around holds it) {}keep their input, which the restore leaves (it spread "
        "their cut light as a halo)",
        clusters, kPivotSpike,
        in.objectId || in.partId
            ? "and whose other neighbours have their ids (a mirror's; a thin bright part of "
              "its own ids, a wire, is fitted) "
            : "(no ids: a thin bright part, a wire, is not told from a reflection) "));
    if (run.keepStages) result->stages.push_back({"spike clusters", result->image});
}

// Pixels whose fits tint them given their window's chroma (KeepWindowChroma), with the plan's
// line and the stage: the output's last step, held as the bound holds the fits (its k; before
// the local means, it moved lights the restore then gave back less of). Only against a
// variance layer and with object ids: the frame's own estimate, or a window across objects,
// recoloured pixels.
void KeepChroma(const PivotInputs &in, float bound, const RunOptions &run, Result *result) {
    if (!in.variance || !in.objectId) {
        result->plan.push_back(
            fmt::format("chroma: not looked at ({})",
                        !in.variance ? "no variance layer read: the fits' noise is estimated"
                                     : "no object ids: windows would cross objects"));
        return;
    }
    const size_t moved = KeepWindowChroma(*in.color, *in.pivot, *in.variance, in.objectId,
                                          in.partId, bound, &result->image);
    const int side = 2 * kPivotChromaRadius + 1;
    const std::string held =
        bound > 0 ? fmt::format(
                        "each channel's target within {} standard deviations of its "
                        "input, as the bound holds",
                        bound)
                  : std::string("unbounded: --pivot-bound 0");
    result->plan.push_back(fmt::format(
        "chroma: {} pixels whose chroma is off their input's in their {}x{} window (of their "
        "ids; z's ratio of sums times their pivot) by {} to {} of that chroma's noise (the "
        "variance layer; weight 0 to 1), where the window's chroma and sum agree with their "
        "input's within {} to {} of its noise (weight 1 to 0), move by their weight toward "
        "their sum at the window's chroma ({})",
        moved, side, side, kPivotChromaFit, kPivotChromaFitFull, kPivotChromaAgree,
        kPivotChromaAgreeNone, held));
    if (run.keepStages) result->stages.push_back({"chroma", result->image});
}

class Pivot : public FrontEndOf<PivotSettings> {
  public:
    Pivot()
        : FrontEndOf(
              "pivot",
              {ChoiceParam("pivot-layer",
                           "the layer filtered against: auto (pivot when the frame has one, "
                           "else albedo), pivot, or albedo (a cheap deterministic image of "
                           "the same structure that every renderer writes)",
                           &PivotSettings::layer, {"auto", "pivot", "albedo"}),
               Nested(&PivotSettings::method,
                      EnumParam("filter",
                                "planefit (the paper's plane fits, eqs. 10-13) or bilateral "
                                "(cross-bilateral baseline of z = color / pivot)",
                                &PivotParams::filter,
                                {{"planefit", PivotFilter::PlaneFit},
                                 {"bilateral", PivotFilter::Bilateral}})),
               Nested(&PivotSettings::method,
                      IntParam("max-radius",
                               "largest half-size of a planefit square (paper: 30-40)",
                               &PivotParams::maxRadius, 2, 64)),
               Nested(&PivotSettings::method,
                      FloatParam("target-noise",
                                 "relative std of a centre's fit that stops the growth",
                                 &PivotParams::targetNoise, 0, 1e6)),
               Nested(&PivotSettings::method,
                      FloatParam("good-noise",
                                 "pixels whose relative std exceeds this are left out of fits",
                                 &PivotParams::goodNoise, 1e-6, 1e6)),
               Nested(&PivotSettings::method,
                      FloatParam("disagreement",
                                 "relative square-vs-quadrant difference that stops the growth",
                                 &PivotParams::disagreement, 0, 1e6)),
               Nested(&PivotSettings::method,
                      FloatParam("robust-k",
                                 "k of eq. 10; above 0 the fits down-weight outliers, "
                                 "which lowers the error but darkens heavy-tailed frames "
                                 "(relief-abc 16 spp: mean 0.65 of the reference with "
                                 "0.3, 1.04 with 0)",
                                 &PivotParams::k, 0, 1e6)),
               Nested(&PivotSettings::method,
                      FloatParam("sigma-weight",
                                 "weight of the noise term sigma in eq. 10 (1: the paper; "
                                 "0 keeps fireflies' energy in heavy-tailed noise)",
                                 &PivotParams::sigmaWeight, 0, 1e6)),
               Nested(&PivotSettings::method,
                      FloatParam("pivot-edge",
                                 "shading edges the pivot does not show (a sun patch on a "
                                 "floor): a fit leaves out, and a pixel does not gather the "
                                 "fit of, what lies across one, where the two 3x3 medians "
                                 "of color / pivot differ by over the smaller and by over "
                                 "this many standard deviations of their noise (0: off)",
                                 &PivotParams::edge, 0, 1e6)),
               Nested(&PivotSettings::method,
                      IntParam("bilateral-radius", "window half-size of the bilateral filter",
                               &PivotParams::bilateralRadius, 0, 64)),
               Nested(&PivotSettings::method,
                      FloatParam("sigma-range",
                                 "bilateral range sigma on the pivot's relative difference",
                                 &PivotParams::sigmaRange, 1e-6, 1e6)),
               Nested(
                   &PivotSettings::method,
                   FloatParam("pivot-floor",
                              "pixels with pivot <= this x the channel mean keep their input",
                              &PivotParams::floor, 1e-12, 1e6)),
               Nested(&PivotSettings::method,
                      IntParam("pivot-mean-radius",
                               "restore the input's local means over tents of 8x, then 2x "
                               "this radius (the fits leave out the bright tail of heavy-"
                               "tailed noise and small highlights; 0: off)",
                               &PivotParams::meanRadius, 0, 256)),
               ChoiceParam("guides", "auto (normals and ids when the frame has them) or none",
                           &PivotSettings::guides, {"auto", "none"}),
               ChoiceParam("pivot-noise",
                           "auto (the variance layer when present, else estimated from the "
                           "frame: the median over 5x5 of squared second differences of z) or "
                           "estimate (the sample variance of z's 3x3 neighbours)",
                           &PivotSettings::noise, {"auto", "estimate"}),
               BoolParam(
                   "no-partials",
                   "filter color as one image even when the frame has section 8's "
                   "partial<k>.color/.pivot and remainder layers (by default each partial "
                   "is filtered against its own pivot and the remainder added)",
                   &PivotSettings::noPartials),
               BoolParam(
                   "pivot-keep-edges",
                   "leave the values beside other ids as the filter left them; by default "
                   "two steps hold them: first each filtered value beside other ids whose "
                   "filtered value / pivot lies beyond the range of both sides' in its 5x5 "
                   "window (the pixels off the edge, of its own ids and of others), widened "
                   "to its outline's level (the median input / pivot of its own ids' pixels "
                   "beside other ids there), is clamped to that range times its pivot (dark "
                   "dots along an outline); then each value the filter kept at its input "
                   "(mixing in a side far from its own) is clamped to the range of the "
                   "filtered values of both sides in its 3x3 window (dots along id edges); "
                   "where it lacks filtered values of both sides (a part at most two pixels "
                   "wide, or beside a side kept whole) the range also spans its own ids' "
                   "level within 2, the lower of their median and its pivot times their "
                   "median over the pivot (dots along a wire)",
                   &PivotSettings::keepEdges),
               BoolParam("pivot-spikes",
                         "scale lone pivot spikes: a pixel whose pivot is a lone spike (over "
                         "16 times its neighbours' median, channels summed, that median above "
                         "0) and whose colour's standard deviation (the variance layer; "
                         "frames without one are left) is at least a quarter of it takes its "
                         "filtered z times its neighbours' median pivot (an albedo that "
                         "followed a mirror to a light in one of a few samples carries the "
                         "firefly, and z times the pivot gives it back); it also removes real "
                         "highlights that a single sample saw (beyond the paper; off by "
                         "default)",
                         &PivotSettings::spikes),
               BoolParam("pivot-fit-clusters",
                         "fit the pixels whose pivot is a cluster of spikes (over 16 times its "
                         "neighbours' median, channels summed, with 2 or more of them so: a "
                         "light seen in a mirror, whose albedo followed the mirror to it) as "
                         "the others; by default they keep their input, which the restore of "
                         "local means leaves (their fits cut the light and the restore spread "
                         "it as a halo round the reflection; beyond the paper)",
                         &PivotSettings::fitClusters),
               IntParam("pivot-range",
                        "each pixel's channels end within the range of their input's values "
                        "in the window of this half-size (widened by 1e-5 of its largest "
                        "magnitude, so that a rounding does not count), moved toward their "
                        "input by one "
                        "share (plane fits that extrapolate a highlight's slope or its "
                        "fireflies beyond every input around them; beyond the paper; 0: off); "
                        "a channel whose variance is 0, or whose 3x3 window holds a variance "
                        "that is NaN, infinite or negative, is left as it is (its noise says "
                        "nothing), as are values that are not finite",
                        &PivotSettings::range, 0, 16),
               FloatParam("pivot-bound",
                          "each value ends at most this many standard deviations of its "
                          "noise (the variance layer, else estimated from the frame; the "
                          "larger of the pixel's and its 3x3 window's mean without the "
                          "largest) from its input, before the local means are restored: fits "
                          "that overshoot an edge or go negative cannot move a pixel farther "
                          "than its noise allows; a pixel's channels move by one share, so a "
                          "bound does not tint it, and not below 0; a value of variance 0 is "
                          "only kept from going below 0; it holds the last step's chroma "
                          "mends to the same k (beyond the paper; 0: off, unbounded)",
                          &PivotSettings::bound, 0, 1e6)}) {}

    std::unique_ptr<FrontEnd> Clone() const override { return std::make_unique<Pivot>(*this); }
    std::string Summary() const override {
        return "Ershov et al.'s pivot-image filter (needs a pivot or an albedo layer; "
               "normals, objectId, partId, variance refine it)";
    }
    std::vector<std::string> Uses() const override {
        return {"color",    "pivot",  "albedo",    "variance", "normal",
                "objectId", "partId", "remainder", "partial*"};
    }
    std::string Missing(const Frame &frame) const override {
        std::string layer = PivotLayer([&](const std::string &l) { return frame.Has(l); });
        if (frame.Has(layer)) return "";
        return options.layer == "auto"
                   ? io::Lacks(frame, "no pivot or albedo layer", {"pivot", "albedo"})
                   : io::Lacks(frame, fmt::format("no {} layer", layer), {layer});
    }
    std::string Undemodulable(const Frame &, const std::string &) const override {
        return "the pivot method divides by itself";
    }

    void PrepareKernels(vk::Context &context, Inputs &inputs) const override {
        const PivotInputs in = InputsOf(inputs);
        // As Run: the fits read the frame's noise estimate where there is no variance layer
        // (the kernel's variant depends on there being one, not on its values).
        PivotInputs fitIn = in;
        const Image estimate;
        if (UsesFrameNoise(in)) fitIn.variance = &estimate;
        PreparePivotKernels(context, fitIn, options.method);
        if (!in.variance && (options.range > 0 || options.bound > 0))
            PrepareAutoNoiseKernels(context);
    }

    Result Run(vk::Context &context, Inputs &inputs, const RunOptions &run) const override {
        PivotInputs in = InputsOf(inputs);
        // Without a variance layer the fits read the frame's own noise estimate, robust to
        // the lines and edges the pivot does not show (a 3x3 sample variance takes them for
        // noise). The bound and the restore keep theirs: a median misses fireflies.
        PivotInputs fitIn = in;
        Image frameNoise;
        if (UsesFrameNoise(in)) {
            frameNoise = FrameNoise(*in.color, in.pivot);
            fitIn.variance = &frameNoise;
        }
        Result result =
            ResultOf(PivotDenoise(context, fitIn, options.method, SetupFor(inputs, run)));
        if (UsesFrameNoise(in))
            result.plan.insert(result.plan.begin(),
                               "variance for the fits: estimated from the frame (no variance "
                               "layer): the median over 5x5 of the smallest squared second "
                               "difference of color / pivot over 4 directions, times the "
                               "pivot squared");
        // Without a variance layer, the range and the bound read the frame's own noise
        // estimate (auto's).
        Image estimated;
        if (!in.variance && (options.range > 0 || options.bound > 0))
            estimated = AutoNoise(context, *in.color, in.pivot, 1).image;
        const Image &variance = in.variance ? *in.variance : estimated;
        const char *noiseSource = in.variance ? "the variance layer"
                                              : "estimated from the frame divided by the pivot";
        Image restoreFrom;
        if (options.spikes) restoreFrom = ScaleSpikes(in, run, &result);
        if (!options.keepEdges) {
            HoldEdgeSides(in, run, &result);
            KeptEdges kept = ClampKeptEdgeValues(*in.color, *in.pivot, in.objectId, in.partId,
                                                 &result.image);
            result.plan.push_back(fmt::format(
                "kept edges: {} values kept at their input beside other ids clamped to the "
                "range of both sides' filtered values in their 3x3 window, {} of them "
                "without a filtered value of both sides around them (in a part at most two "
                "pixels wide, or beside a side kept whole: a light, alpha 0) to the range "
                "that also spans their own ids' level within 2 (the lower of the median "
                "value and the pivot times the median value / pivot); {} keep their input "
                "and its noise (no pixel of their ids around them)",
                kept.clamped, kept.thin, kept.alone));
            if (run.keepStages) result.stages.push_back({"kept edges", result.image});
        }
        if (options.range > 0) {
            size_t moved = BoundToInputRange(*in.color, variance, options.range,
                                             kPivotRangeSpread, &result.image);
            result.plan.push_back(fmt::format(
                "range: {} values moved to within their input's range in its {}x{} window "
                "(those of variance 0, or of a window with a variance not finite or negative, "
                "left; {})",
                moved, 2 * options.range + 1, 2 * options.range + 1, noiseSource));
            if (run.keepStages) result.stages.push_back({"range", result.image});
        }
        if (options.bound > 0) {
            size_t moved = BoundToNoise(*in.color, variance, options.bound, &result.image);
            result.plan.push_back(fmt::format(
                "bound: {} values moved to within {} standard deviations of their input's "
                "noise ({}: the pixel's, or its 3x3 window's mean without the largest, the "
                "larger; those of variance 0 only kept from going below 0)",
                moved, options.bound, noiseSource));
            if (run.keepStages) result.stages.push_back({"bound", result.image});
        }
        if (!options.fitClusters) KeepSpikeClusters(in, run, &result);
        // A tile's last steps wait for the assembled frame (Finish).
        if (!finishWhole) RestoreAndKeepChroma(in, restoreFrom, run, &result);
        if (UsesAlbedo(inputs))
            result.plan.insert(result.plan.begin(),
                               options.layer == "auto"
                                   ? "pivot: the albedo layer stands in for the pivot (the "
                                     "frame has no pivot layer)"
                                   : "pivot: the albedo layer stands in for the pivot "
                                     "(--pivot-layer albedo)");
        return result;
    }

    void Finish(vk::Context &, Inputs &whole, Result *result) const override {
        Result finished;
        finished.image = std::move(result->image);
        RestoreAndKeepChroma(InputsOf(whole), Image(), RunOptions(), &finished);
        result->image = std::move(finished.image);
        for (std::string &line : finished.plan)
            result->plan.push_back("on the whole frame, after the tiles: " + line);
    }

    TileNeeds Tiling(vk::Context &, Inputs &inputs) const override {
        int channels = inputs.Get("color").channels;
        TileNeeds needs;
        // z's noise over 3x3 and the id boundary (4-neighbours) read 1 pixel further, the
        // side medians of a pixel beside other ids PIVOT_SIDE_RADIUS.
        const int ratioReach = std::max(2, PIVOT_SIDE_RADIUS);
        if (options.method.filter == PivotFilter::Bilateral) {
            needs.reach = options.method.bilateralRadius + ratioReach;
            needs.reachText = fmt::format(
                "the bilateral radius {}; {} for the noise estimated from 3x3 neighbours, the "
                "id boundary and the side medians of pixels beside other ids",
                options.method.bilateralRadius, ratioReach);
        } else {
            needs.reach = 2 * options.method.maxRadius + ratioReach;
            needs.reachText = fmt::format(
                "a pixel gathers the fits of centres up to the largest square half-size {} "
                "away, each fit reads up to {} further; {} for the noise estimated from 3x3 "
                "neighbours, the id boundary and the side medians of pixels beside other ids",
                options.method.maxRadius, options.method.maxRadius, ratioReach);
        }
        const int mean =
            options.method.meanRadius > 0 ? LocalMeanReach(options.method.meanRadius, true) : 0;
        // The bound's 3x3 window, and the noise estimate's 3x3 residuals over a 3x3 mean;
        // the edge sides' 5x5 window of outputs (the ids and inputs they test lie in the
        // tile), then the kept edges' 5x5 window (a thin part's own median); the range's
        // window; the spikes' 3x3 window and the noise estimate's. The spike clusters read
        // their own output and the pivot: no reach.
        const int bound = (options.bound > 0 ? 3 : 0) + (options.keepEdges ? 0 : 2 + 2) +
                          options.range + (options.spikes ? 1 : 0);
        // The frame's noise for the fits: a 5x5 median of second differences.
        const int frameNoise = !inputs.Has("variance") && options.noise == "auto" ? 3 : 0;
        needs.reach += bound + frameNoise;
        const int beforeRestore = needs.reach;
        needs.reach += mean;
        // The chroma's window reads inputs only, beside the output at its own pixel: the
        // larger of the two reaches, not their sum.
        const PivotInputs in = InputsOf(inputs);
        const int chroma = in.variance && in.objectId ? kPivotChromaRadius : 0;
        needs.reach = std::max(needs.reach, chroma);
        // The restore and the chroma, the last steps, read the spikes' scaled pixels where
        // they restore from: with --pivot-spikes they stay in the tiles.
        if (!options.spikes) needs.finishReach = needs.reach - beforeRestore;
        needs.reachText += fmt::format(
            "; the local mean's coarse and fine tents {}; {} for the bound's noise, the "
            "edge sides', the kept edges', the range's and the spikes' windows (the spike "
            "clusters read their own pixel); {} for the frame's noise "
            "estimate; the chroma's window {} (the larger of it and the rest)",
            mean, bound, frameNoise, chroma);
        // The gather sums the centres tile by tile of its own grid: windows on that grid
        // keep the order of the sums.
        needs.align = PIVOT_GATHER_TILE;
        // Two fit buffers of PIVOT_PLANES / 2 planes per channel (one binding per channel
        // and buffer), six images of the colour's channels, the variance, the fit's packed
        // z, s, nu, level and noise (eight per channel, four without the edge test; one
        // binding per channel) and the guides (4 floats a pixel).
        const int zsnPlanes =
            options.method.edge > 0 ? PIVOT_ZSN_EDGE_PLANES : PIVOT_ZSN_PLANES;
        needs.bindingBytesPerPixel = std::max(PIVOT_PLANES_PER_BUFFER, zsnPlanes) * 4.0;
        needs.bytesPerPixel = (16.0 + 7 + zsnPlanes) * channels * 4 + 4 * 4;
        return needs;
    }

    std::unique_ptr<FrontEnd> ForTiles(vk::Context &, Inputs &whole) const override {
        auto copy = std::make_unique<Pivot>(*this);
        PivotInputs in = InputsOf(whole);
        const float floor = options.method.floor;
        copy->options.thresholds = PivotThresholds(*in.pivot, floor);
        for (const PivotPartial &partial : in.partials)
            copy->options.partialThresholds.push_back(PivotThresholds(*partial.pivot, floor));
        return copy;
    }

    std::vector<Stage> Reference(vk::Context &, Inputs &inputs) const override {
        PivotInputs in = InputsOf(inputs);
        Image frameNoise;
        if (UsesFrameNoise(in)) frameNoise = ref::FrameNoise(*in.color, in.pivot);
        Image ids;
        if (in.objectId || in.partId) {
            ids = Image(inputs.Width(), inputs.Height(), 2);
            for (size_t i = 0; i < ids.PixelCount(); ++i) {
                if (in.objectId) ids.data[i] = in.objectId->data[i];
                if (in.partId) ids.data[ids.PixelCount() + i] = in.partId->data[i];
            }
        }
        ref::PivotFilterInputs cpuIn;
        cpuIn.color = in.color;
        cpuIn.pivot = in.pivot;
        cpuIn.variance = UsesFrameNoise(in) ? &frameNoise : in.variance;
        cpuIn.guides = {in.normal, ids.Empty() ? nullptr : &ids};
        for (const PivotPartial &partial : in.partials)
            cpuIn.partials.push_back({partial.color, partial.pivot, partial.variance});
        cpuIn.remainder = in.remainder;
        std::vector<std::pair<std::string, Image>> cpu;
        Image out = ref::PivotFilter(cpuIn, options.method, &cpu);
        Image restoreFrom = *in.color;
        if (options.spikes && in.variance) {
            for (size_t p : ref::ScalePivotSpikes(*in.color, *in.pivot, *in.variance, &out))
                for (int c = 0; c < out.channels; ++c)
                    restoreFrom.Plane(c)[p] = out.Plane(c)[p];
            cpu.emplace_back("pivot spikes", out);
        }
        Image estimated;
        if (!in.variance && (options.range > 0 || options.bound > 0))
            estimated = ref::AutoNoise(*in.color, in.pivot, 1);
        const Image &variance = in.variance ? *in.variance : estimated;
        if (!options.keepEdges) {
            ref::ClampEdgeFitsToSides(*in.color, *in.pivot, in.objectId, in.partId, &out);
            cpu.emplace_back("edge sides", out);
            ref::ClampKeptEdgeValues(*in.color, *in.pivot, in.objectId, in.partId, &out);
            cpu.emplace_back("kept edges", out);
        }
        if (options.range > 0) {
            ref::BoundToInputRange(*in.color, variance, options.range, kPivotRangeSpread, &out);
            cpu.emplace_back("range", out);
        }
        if (options.bound > 0) {
            ref::BoundToNoise(*in.color, variance, options.bound, &out);
            cpu.emplace_back("bound", out);
        }
        if (!options.fitClusters) {
            ref::KeepPivotSpikeClusters(*in.color, *in.pivot, in.objectId, in.partId, &out);
            cpu.emplace_back("spike clusters", out);
        }
        if (int r = options.method.meanRadius; r > 0) {
            ref::RestoreLocalMeans(restoreFrom, r, &out, in.variance, kLocalMeanRebalance,
                                   true);
            cpu.emplace_back("local mean", out);
        }
        if (in.variance && in.objectId) {
            ref::KeepWindowChroma(*in.color, *in.pivot, *in.variance, in.objectId, in.partId,
                                  options.bound, &out);
            cpu.emplace_back("chroma", std::move(out));
        }
        std::vector<Stage> stages;
        for (auto &[name, image] : cpu) stages.push_back({name, std::move(image)});
        return stages;
    }

  private:
    // Whether the frame's robust noise estimate stands in for a variance layer: none, one
    // image filtered (no partials) and --pivot-noise auto.
    bool UsesFrameNoise(const PivotInputs &in) const {
        return !in.variance && in.partials.empty() && options.noise == "auto";
    }
    // The layer that serves as the pivot: auto takes the real one when there is one, as
    // the albedo lacks its shading.
    template <typename HasLayer>
    std::string PivotLayer(HasLayer has) const {
        if (options.layer == "auto") return has("pivot") ? "pivot" : "albedo";
        return options.layer;
    }
    bool UsesAlbedo(Inputs &inputs) const {
        return PivotLayer([&](const std::string &l) { return inputs.Has(l); }) == "albedo";
    }

    // The local means restored (from `restoreFrom` where given: the spikes' scaled pixels),
    // then the chroma kept: the output's last steps.
    void RestoreAndKeepChroma(const PivotInputs &in, const Image &restoreFrom,
                              const RunOptions &run, Result *result) const {
        if (int r = options.method.meanRadius; r > 0) {
            result->plan.push_back(
                "local mean: " +
                RestoreLocalMeansRebalanced(restoreFrom.Empty() ? *in.color : restoreFrom, r,
                                            &result->image, in.variance));
            if (run.keepStages) result->stages.push_back({"local mean", result->image});
        }
        KeepChroma(in, options.bound, run, result);
    }

    // The pipeline's inputs from the frame and the parameters.
    PivotInputs InputsOf(Inputs &inputs) const {
        std::string layer = PivotLayer([&](const std::string &l) { return inputs.Has(l); });
        if (!inputs.Has(layer)) {
            if (options.layer == "auto")
                throw Error(
                    fmt::format("{}: the pivot method needs a pivot layer or an albedo layer "
                                "(render them with `mcdenoise render --layers pivot,gbuffer`)",
                                inputs.Path()),
                    ErrorKind::MissingLayer);
            throw Error(fmt::format("{}: --pivot-layer {} names a layer the frame lacks",
                                    inputs.Path(), layer),
                        ErrorKind::MissingLayer);
        }
        PivotInputs in;
        in.color = &inputs.Get("color");
        in.pivot = &inputs.Get(layer);
        // The pivot divides the colour channel by channel: the colour's shape, said here with
        // the file and the layer (the frame's noise estimate reads it before the checks).
        const Image &color = *in.color, &pivot = *in.pivot;
        if (pivot.width != color.width || pivot.height != color.height ||
            pivot.channels != color.channels)
            throw Error(fmt::format("{}: layer '{}' is {}x{}x{}; the pivot method needs the "
                                    "colour's {}x{}x{}",
                                    inputs.Path(), layer, pivot.width, pivot.height,
                                    pivot.channels, color.width, color.height, color.channels),
                        ErrorKind::InvalidArgument);
        in.thresholds = options.thresholds;
        bool noise = options.noise == "auto";
        if (noise && inputs.Has("variance")) in.variance = &inputs.Get("variance");
        if (options.guides == "auto") {
            if (inputs.Has("normal")) in.normal = &inputs.Get("normal");
            if (inputs.Has("objectId")) in.objectId = &inputs.Get("objectId");
            if (inputs.Has("partId")) in.partId = &inputs.Get("partId");
        }
        if (options.noPartials) return in;
        // Section 8: partial0, partial1, ... while the frame has them, and the remainder.
        for (int k = 0; inputs.Has(fmt::format("partial{}.color", k)); ++k) {
            std::string name = fmt::format("partial{}", k);
            if (!inputs.Has(name + ".pivot"))
                throw Error(fmt::format("{}: layer {}.color has no {}.pivot (or pass "
                                        "--no-partials)",
                                        inputs.Path(), name, name),
                            ErrorKind::MissingLayer);
            PivotPartial partial{&inputs.Get(name + ".color"), &inputs.Get(name + ".pivot")};
            if (noise && inputs.Has(name + ".variance"))
                partial.variance = &inputs.Get(name + ".variance");
            if (size_t(k) < options.partialThresholds.size())
                partial.thresholds = options.partialThresholds[k];
            in.partials.push_back(partial);
        }
        if (!in.partials.empty()) {
            if (!inputs.Has("remainder"))
                throw Error(
                    fmt::format(
                        "{}: the partial images need a remainder layer (or pass --no-partials)",
                        inputs.Path()),
                    ErrorKind::MissingLayer);
            in.remainder = &inputs.Get("remainder");
        }
        return in;
    }
};

}  // namespace

std::unique_ptr<FrontEnd> PivotFrontEnd() {
    return std::make_unique<Pivot>();
}

}  // namespace mcd::api
