// Method `nfor`: feature regression (host/methods/nfor.h), NFOR's first-order fits on the
// frame's albedo, normal, depth (and pivot), with the colour's and the features' noise
// estimated from the frame when it has no variance layer.
#include <fmt/format.h>

#include <algorithm>
#include <sstream>

#include "cpu_reference/nfor.h"
#include "host/api/front_end.h"
#include "host/api/nfor_reference.h"
#include "host/api/tiled_run.h"
#include "host/common/local_mean.h"
#include "host/kernels/nfor_kernels.h"
#include "host/methods/nfor.h"
#include "host/methods/nfor_band.h"
#include "host/methods/nfor_line.h"
#include "host/methods/nfor_rare.h"
#include "host/methods/nfor_specks.h"

namespace mcd::api {
namespace {

struct NforParamsApi {
    NforOptions options;
    std::string bandwidths = "0.5,1";
    std::string pilotBandwidths = "1";
    std::string noise = "auto", pivot = "auto";
    std::string pilotLayer;  // empty: the first pass's output is the pilot
    // On a frame without a variance layer, where --pilot-wide-radius is 0: the second
    // pass's wide windows and the agreement that takes their fit (0: off).
    int plainWideRadius = 8;
    float plainWideAgreement = 0.003f;
};

std::vector<float> ParseBandwidths(const std::string &text, const char *option) {
    std::vector<float> values;
    std::stringstream stream(text);
    std::string item;
    while (std::getline(stream, item, ',')) {
        size_t used = 0;
        float v = 0;
        try {
            v = std::stof(item, &used);
        } catch (const std::logic_error &) {
            used = 0;
        }
        if (used == 0 || used != item.size() || !(v > 0) || !std::isfinite(v))
            throw Error(fmt::format("nfor: --{} takes numbers > 0 separated by commas, "
                                    "not '{}'",
                                    option, text),
                        ErrorKind::InvalidArgument);
        values.push_back(v);
    }
    if (values.empty() || values.size() > 4)
        throw Error(fmt::format("nfor: --{} takes 1 to 4 bandwidths, not '{}'", option, text),
                    ErrorKind::InvalidArgument);
    return values;
}

using O = NforOptions;

std::vector<ParamDef<NforParamsApi>> Defs() {
    auto nested = [](auto def) { return Nested(&NforParamsApi::options, def); };
    return {
        ChoiceParam("bandwidths",
                    "colour bandwidths k, comma-separated (1 to 4 candidates; with several, "
                    "each pixel takes the one of smallest SURE)",
                    &NforParamsApi::bandwidths, {}),
        nested(IntParam("radius", "regression window half-size", &O::radius, 1, 10)),
        nested(IntParam("gather-radius",
                        "a pixel averages the fits of the windows centred at most this far "
                        "(-1: all that hold it)",
                        &O::gatherRadius, -1, 10)),
        nested(IntParam("patch-radius", "colour patch half-size of the NL-means distance",
                        &O::patchRadius, 0, 3)),
        nested(BoolParam("no-demodulated-distance",
                         "compare the colour itself in the NL-means distance (by default "
                         "colour / albedo: texture and edge coverage divide out)",
                         &O::noDemodulatedDistance)),
        nested(FloatParam("albedo-noise",
                          "the demodulated distance compares the colours themselves, not "
                          "colour / albedo, in a pair with an end whose albedo is noise: its "
                          "relative variance over 3x3 above this, and dividing by it roughens "
                          "the colour (glossy metal, whose albedo follows the sampled bounce); "
                          "0: every pair compares colour / albedo",
                          &O::albedoNoise, 0, 100)),
        nested(FloatParam("glint-noise",
                          "on a frame without a variance layer, where the albedo is noise "
                          "(--albedo-noise) within 16 pixels of a glint (an albedo channel "
                          "above 8), the weights' noise (also SURE's and the pilot's) at "
                          "least this times the clamped colour's variance over 3x3: the fits "
                          "average a reflected light's "
                          "hits and misses instead of keeping them (the output within 3 "
                          "pixels of such a pixel then at least the clamped colour's 3x3 "
                          "minimum); 0: off",
                          &O::glintNoise, 0, 100)),
        nested(FloatParam("alpha", "variance cancellation in the colour distance", &O::alpha, 0,
                          10)),
        nested(EnumParam("distance-variance",
                         "the colour distance's variances: min (2 min(v_p, v_q) cancelled and "
                         "normalised: a dark pixel "
                         "does not borrow from a brighter, noisier one) or sum (v_p + v_q)",
                         &O::minVariance, {{"min", true}, {"sum", false}})),
        nested(EnumParam("pilot-distance-variance",
                         "the second pass's colour distance's variances: same (as "
                         "--distance-variance), min or sum",
                         &O::pilotMinVariance, {{"same", -1}, {"min", 1}, {"sum", 0}})),
        nested(FloatParam("ridge", "ridge lambda x sum(w) on the non-constant columns",
                          &O::ridge, 1e-4, 1e3)),
        nested(FloatParam("feature-bandwidth",
                          "feature weights exp(-|dF|^2 / (this x sigma)^2); 0: colour only",
                          &O::featureBandwidth, 0, 1e3)),
        nested(FloatParam("albedo-sigma", "albedo scale of the feature weight", &O::albedoSigma,
                          1e-4, 1e3)),
        nested(FloatParam("normal-sigma", "normal scale of the feature weight", &O::normalSigma,
                          1e-4, 1e3)),
        nested(FloatParam("depth-sigma", "depth / its mean: scale of the feature weight",
                          &O::depthSigma, 1e-4, 1e3)),
        nested(FloatParam("pivot-sigma", "pivot / its mean: scale of the feature weight",
                          &O::pivotSigma, 1e-4, 1e3)),
        nested(IntParam("noise-radius", "window half-size of the noise estimates",
                        &O::noiseRadius, 1, 3)),
        nested(BoolParam("no-edge-noise",
                         "on a frame without variance, weigh by the same noise estimate the "
                         "firefly clamp reads (by default the weights' is estimated again on "
                         "the clamped colour, and an edge pixel with too few neighbours of "
                         "its albedo takes its neighbours' noise, so that it is smoothed)",
                         &O::noEdgeNoise)),
        nested(BoolParam("no-sparse-noise",
                         "estimate the colour's noise by the median of the neighbours' "
                         "differences alone (by default a direction where at least half of "
                         "them are 0, as where most of a frame's few samples are exactly 0, "
                         "takes their mean: there the median reads no noise and the fits "
                         "left black holes)",
                         &O::noSparseNoise)),
        nested(BoolParam("clamp-layer",
                         "with a variance layer, the firefly clamp reads the layer instead of "
                         "the frame's own noise estimate (a firefly's few samples report its "
                         "own variance there)",
                         &O::clampLayer)),
        nested(FloatParam("clamp-loss",
                          "with a variance layer, where the clamp against the frame's own "
                          "estimate takes off more than this fraction of the colour's sum (the "
                          "light is in rare bright samples, not fireflies) it reads the layer",
                          &O::clampLoss, 0, 1)),
        nested(BoolParam("no-lone-sample-cap",
                         "where the firefly clamp reads the variance layer, read it as it is "
                         "(by default an isolated lone sample, a pixel whose layer says one "
                         "sample holds its mean, far above its neighbours and with no other "
                         "such pixel within 15, reads its neighbours' median there, so a "
                         "firefly on a quiet ground is clamped)",
                         &O::noLoneSampleCap)),
        nested(FloatParam("noise-calibration", "factor on the estimated variance",
                          &O::noiseCalibration, 1e-3, 1e3)),
        nested(FloatParam("firefly-threshold",
                          "clamp a value above its 8 neighbours' median + this x sigma; 0: off",
                          &O::fireflyThreshold, 0, 1e6)),
        nested(FloatParam("firefly-relative",
                          "and above the median + this x |median| (noise-free peaks stay)",
                          &O::fireflyRelative, 0, 1e6)),
        nested(IntParam("firefly-rank",
                        "compare with the 8 neighbours' median (0) or their k-th largest (k: a "
                        "pixel with k - 1 bright neighbours is a highlight, kept)",
                        &O::fireflyRank, 0, 8)),
        nested(FloatParam("firefly-light-edge",
                          "a pixel unlike all its neighbours next to an emitter (a light's "
                          "edge): kept (negative) or clamped as a firefly with this in place "
                          "of --firefly-relative",
                          &O::fireflyLightEdge, -1, 1e6)),
        nested(BoolParam("firefly-each-channel",
                         "clamp each channel on its own (by default a pixel with two channels "
                         "or more above their limits is scaled as a whole by the sum of its "
                         "values clamped one by one over the sum of its values: the hue "
                         "stays)",
                         &O::fireflyEachChannel)),
        nested(
            FloatParam("firefly-line",
                       "keep a pixel on a bright line (along an axis or a diagonal, within 2 "
                       "pixels on both sides, one brighter than this x it: a highlight's "
                       "streak); 0: off",
                       &O::fireflyLine, 0, 1e6)),
        nested(FloatParam(
            "firefly-line-floor",
            "a pixel the clamp takes down keeps at least this x its line's "
            "brightness (the dimmer side's brightest within 2 pixels, along the "
            "axis or diagonal where that is largest): a highlight line's peaks, "
            "which --firefly-line does not keep; only within 4 pixels of an albedo above 8, a "
            "light a highlight reflects; 0: off",
            &O::fireflyLineFloor, 0, 1e6)),
        nested(FloatParam("firefly-lone-light",
                          "keep an emitter with no emitter among its 8 neighbours, its albedo "
                          "at least this and its colour within 1.25x of its albedo in every "
                          "channel (a light smaller than a pixel, seen directly: its value is "
                          "its emission, no firefly; one sample's hit of a light under a pixel "
                          "reads many times its share); 0: off (clamped like a firefly)",
                          &O::fireflyLoneLight, 0, 1e6)),
        nested(FloatParam("wide-agreement",
                          "with --pilot-wide-radius and one pilot bandwidth: take the wide "
                          "window's fit where its squared difference from the narrow one's, "
                          "relative to that one's magnitude and averaged over the SURE window, "
                          "is below this, elsewhere the narrow one's; 0: SURE picks",
                          &O::wideAgreement, 0, 1e6)),
        nested(
            IntParam("kept-radius",
                     "on a frame without a variance layer (or beside one where the clamp reads "
                     "the frame's own estimate, unless --no-layer-passes), a pixel the fits "
                     "left as it came in (no neighbour weighed: a partly covered edge unlike "
                     "all around it) takes the output's mean over this radius weighted by the "
                     "features; 0: kept",
                     &O::keptRadius, 0, 8)),
        nested(
            FloatParam("weak-emitter-albedo",
                       "on a frame without a variance layer (or beside one where the clamp "
                       "reads the frame's own estimate, unless --no-layer-passes), emitters "
                       "whose albedo is below this (a light's partly covered edge, a moving "
                       "light's streak) take the output's mean weighted by the features, their "
                       "albedo not compared, over --kept-radius (2 where that is 0); 0: "
                       "emitters kept",
                       &O::weakEmitterAlbedo, 0, 1e30)),
        nested(FloatParam("weak-emitter-line",
                          "a weak emitter (--weak-emitter-albedo) on a bright line, with a "
                          "pixel at least this x as bright on both sides along an axis or a "
                          "diagonal within 2 steps (a glossy highlight's streak), weighs the "
                          "pixels of its mean also by their brightness against its own "
                          "(--weak-emitter-range): it averages along the streak, not with the "
                          "darker ground beside it; 0: off",
                          &O::weakEmitterLine, 0, 1e30)),
        nested(FloatParam("weak-emitter-range",
                          "--weak-emitter-line's brightness weight: a Gaussian of this in the "
                          "log of the channels' mean (+ 0.01)",
                          &O::weakEmitterRange, 1e-3, 1e30)),
        nested(
            FloatParam("weak-light-share",
                       "on a frame without a variance layer (or beside one where the clamp "
                       "reads the frame's own estimate, unless --no-layer-passes), last: each "
                       "emitter of albedo below --weak-emitter-albedo gives this share of its "
                       "output to each of its 4 neighbours that is no emitter (a light's rim, "
                       "which few samples hit), keeping the rest; 0: off",
                       &O::weakLightShare, 0, 0.25)),
        nested(FloatParam("light-share",
                          "the same for the other emitters (a light hundreds of times as "
                          "bright as its rim); 0: off",
                          &O::lightShare, 0, 0.25)),
        nested(FloatParam("line-spread",
                          "the light the firefly clamp took from a line's pixels (a glossy "
                          "object's highlight line, drawn by few samples as hits with gaps) "
                          "within 4 pixels of a light whose albedo exceeds this, shared along "
                          "the line, a pixel given at most up to the input's light along it; "
                          "0: off",
                          &O::lineSpread, 0, 1e30)),
        nested(FloatParam("emitter-albedo",
                          "pixels whose albedo exceeds this are emitters: left out of every "
                          "window and kept as they are (weak ones smoothed: "
                          "--weak-emitter-albedo; on a plain frame each gives its rim a "
                          "share: --light-share)",
                          &O::emitterAlbedo, 1, 1e30)),
        nested(IntParam("prefilter-radius",
                        "window half-size of the features' prefilter; 0: off",
                        &O::prefilterRadius, 0, 5)),
        nested(IntParam("prefilter-patch", "patch half-size of the features' prefilter",
                        &O::prefilterPatch, 0, 2)),
        nested(FloatParam("prefilter-bandwidth",
                          "NL-means bandwidth of the features' prefilter",
                          &O::prefilterBandwidth, 1e-3, 1e3)),
        nested(IntParam("sure-radius", "window half-size of the SURE average", &O::sureRadius,
                        0, 8)),
        ChoiceParam("pilot-bandwidths",
                    "a second pass weighted by the colour distance of the first pass's output "
                    "(the pilot): its bandwidths k, comma-separated (1 to 4, chosen per pixel "
                    "by SURE); none: one pass",
                    &NforParamsApi::pilotBandwidths, {}),
        nested(FloatParam("pilot-alpha",
                          "variance cancellation of the second pass's distance (the pilot's "
                          "own noise is far below the colour's)",
                          &O::pilotAlpha, 0, 10)),
        nested(IntParam("pilot-wide-radius",
                        "the second pass also fits over windows of this half-size (above "
                        "--radius) and SURE picks per pixel among both sizes; 0: off",
                        &O::pilotWideRadius, 0, 10)),
        IntParam("plain-wide-radius",
                 "on a frame without a variance layer (a plain render), where "
                 "--pilot-wide-radius is 0 and the second pass has one bandwidth: it also "
                 "fits over windows of this half-size and takes their fit where it agrees "
                 "with the narrow one's (--plain-wide-agreement): an interior's walls; 0, or "
                 "not above --radius: off",
                 &NforParamsApi::plainWideRadius, 0, 10),
        FloatParam("plain-wide-agreement",
                   "with --plain-wide-radius: the --wide-agreement it runs with (0: SURE "
                   "picks between the two sizes)",
                   &NforParamsApi::plainWideAgreement, 0, 1e6),
        nested(IntParam("nfor-mean-radius",
                        "restore the clamped colour's local means over tents of 8x, then 2x "
                        "this radius after the fits; 0: off",
                        &O::meanRadius, 0, 64)),
        nested(IntParam(
            "clamp-light-radius",
            "on a frame without a variance layer (or beside one where the clamp reads the "
            "frame's own estimate, unless --no-layer-passes) where the coarse pass does not "
            "run, after the local means: the colour's own means (the light the firefly clamp "
            "took) restored over tents of 2x this radius, each value's difference its own "
            "noise (a lone firefly's light stays out); 0: off",
            &O::clampLightRadius, 0, 64)),
        nested(IntParam("clamp-light-fine", "then over tents of 2x this radius; 0: none",
                        &O::clampLightFine, 0, 64)),
        nested(BoolParam("no-layer-passes",
                         "beside a variance layer, leave out the passes of a frame without "
                         "one: the specks' clamp, the clamp's light restored, the weak "
                         "emitters' mean and the lights' spread",
                         &O::noLayerPasses)),
        nested(FloatParam("layer-noise-cap",
                          "beside a variance layer the weights read min(layer, this x the "
                          "frame's own estimate of the clamped colour's noise); 0: the layer",
                          &O::layerNoiseCap, 0, 1e6)),
        nested(FloatParam("pilot-noise-cap",
                          "beside a variance layer the second pass's distance reads min(the "
                          "weights' noise, this x the frame's own estimate of the clamped "
                          "colour's noise); 0: the weights' noise",
                          &O::pilotNoiseCap, 0, 1e6)),
        nested(IntParam("clamp-light-reach",
                        "the clamp's light is not given back within this many pixels of an "
                        "emitter or a partly covered pixel",
                        &O::clampLightReach, 0, 16)),
        nested(FloatParam(
            "rare-light-share",
            "on a frame without a variance layer, where the clamp's light is restored, after "
            "it: a pixel the firefly clamp cut to under 1 / --rare-light-ratio of its colour, "
            "with others such near it (--rare-light-pair; rare bright samples: a glossy "
            "floor's reflection of a light that few samples hit; a lone one is a firefly), "
            "gives this share of the "
            "light the clamp took to the pixels around it, a Gaussian of 2 pixels, none "
            "within --clamp-light-reach of an emitter or a partly covered pixel; 0: off",
            &O::rareLightShare, 0, 1)),
        nested(FloatParam("rare-light-ratio",
                          "--rare-light-share's cut: a pixel's colour over its clamped colour "
                          "(the channels' sums) above this",
                          &O::rareLightRatio, 1, 1e6)),
        nested(IntParam("rare-light-pair",
                        "--rare-light-share's source has --rare-light-others more cut pixels "
                        "within this many pixels (a reflection's footprint holds its hits "
                        "close together; hits scattered thinly, as a caustic's over a floor, "
                        "would each become a blob)",
                        &O::rareLightPair, 1, kNforRarePair)),
        nested(IntParam("rare-light-others",
                        "the cut pixels within --rare-light-pair a source needs besides "
                        "itself (more than that square holds: no source)",
                        &O::rareLightOthers, 1,
                        (2 * kNforRarePair + 1) * (2 * kNforRarePair + 1) - 1)),
        nested(IntParam(
            "glint-band-radius",
            "on a frame without a variance layer, last: within 16 pixels of a glint (an albedo "
            "channel above 8: a renderer that writes a reflected light into the albedo, as "
            "Cycles does, where the features cannot explain a glossy highlight's band) each "
            "pixel that is no emitter moves towards the output's mean along its line (the "
            "structure tensor's direction of least change, a Gaussian of 1.5 pixels over this "
            "many samples each side, each sample's luminance held within 1/2 to 2x the "
            "pixel's + 0.01, a sample of no light black, emitters', empty pixels' and "
            "non-finite samples left out) by the tensor's coherence; 0: off",
            &O::glintBandRadius, 0, kNforGlintBandReach - 1)),
        nested(IntParam(
            "rim-hits",
            "on a frame without a variance layer, last: an emitter pixel that at most this "
            "many of the frame's samples hit (its largest albedo channel at most this / spp of "
            "an emitter's within 2 pixels: a light's rim, reading the light times the hits' "
            "share) is brought down to the geometric mean of its input and of its neighbours "
            "that are no emitter (their median), and the light it loses goes to that light's "
            "brighter pixels: the frame's light stays. spp from the frame's spp layer, else "
            "its metadata (Cycles' cycles.<view layer>.samples); a frame that states none, or "
            "fewer than 4 x this, is left as it is; 0: off",
            &O::rimHits, 0, 1000)),
        nested(FloatParam(
            "speck-relative",
            "where no variance layer is read (the frame's own noise estimate; or beside one "
            "where the clamp reads that estimate, unless --no-layer-passes), with the local "
            "means restored: a pixel of the fits' output above (1 + this) x its "
            "--speck-rank-th brightest neighbour + --speck-floor (a speck the fits left) is "
            "scaled down to that before the restore, which gives the pixels around it what of "
            "its light it holds for certain; negative: off",
            &O::speckRelative, -1, 1e3)),
        nested(BoolParam("no-exact-ground",
                         "with the local means restored, where the specks' clamp runs: fit a "
                         "pixel whose 8 neighbours' input colours are the same bit for bit and "
                         "lit (a ground every sample of which saw the same: a mirror's or a "
                         "sky's constant) like any other; by default it keeps its input where "
                         "the firefly clamp left it and it differs from them (a light under a "
                         "pixel seen in a mirror), and its light stays out of the local means",
                         &O::noExactGround)),
        nested(FloatParam("speck-floor", "the absolute part of --speck-relative's bound",
                          &O::speckFloor, 0, 1e6)),
        nested(
            IntParam("speck-rank",
                     "--speck-relative's bound is over the pixel's this-th brightest "
                     "neighbour: a pixel with this many bright neighbours (a line's) is kept",
                     &O::speckRank, 1, 8)),
        nested(FloatParam(
            "speck-flat-share",
            "a pixel whose 8 neighbours' median luminance (the 5th brightest) is at least "
            "this x its --speck-rank-th brightest neighbour's (a speck on a flat "
            "ground, not on a highlight's slope) is held to "
            "--speck-flat-relative in place of --speck-relative; 0: off",
            &O::speckFlatShare, 0, 1)),
        nested(FloatParam("speck-flat-relative",
                          "--speck-relative's bound on a flat ground (--speck-flat-share)",
                          &O::speckFlatRelative, 0, 1e3)),
        nested(
            BoolParam("nfor-coarse",
                      "on every frame, denoise the frame again at half the resolution and "
                      "take its low frequencies where they differ from the output's by under "
                      "--coarse-relative x its magnitude and --coarse-noise x its residual "
                      "(by default only on frames --coarse-gate lets through)",
                      &O::coarse)),
        nested(FloatParam("coarse-gate",
                          "the coarse pass runs on a frame whose noise as relMSE weighs it "
                          "(the median over the pixels of its own estimate / (colour^2 + "
                          "0.01), partly covered pixels divided by their alpha) is at least "
                          "this; 0: never (without --nfor-coarse)",
                          &O::coarseGate, 0, 1e3)),
        nested(IntParam("noisy-radius",
                        "where the coarse pass runs (a noisy frame), the fits' window "
                        "half-size (the second pass's wide windows no wider left out); at "
                        "most --radius: --radius on every frame",
                        &O::noisyRadius, 0, 10)),
        nested(FloatParam("coarse-relative",
                          "the coarse pass's difference allowed, relative to the output",
                          &O::coarseRelative, 0, 1e3)),
        nested(FloatParam("coarse-noise",
                          "the coarse pass's difference allowed, relative to the output's "
                          "residual (input - output)",
                          &O::coarseNoise, 0, 1e3)),
        nested(BoolParam("premultiplied",
                         "denoise partly covered pixels (alpha between 0 and 1: an edge over a "
                         "transparent background) as the frame holds them, premultiplied; by "
                         "default their colour and features are divided by their alpha (the "
                         "surface they show) and the output multiplied back",
                         &O::premultiplied)),
        ChoiceParam("nfor-noise",
                    "auto (the variance layer when present) or estimate (from the frame)",
                    &NforParamsApi::noise, {"auto", "estimate"}),
        ChoiceParam("pivot-feature", "auto (the pivot layer as features when present) or off",
                    &NforParamsApi::pivot, {"auto", "off"}),
        ChoiceParam("nfor-pilot-layer",
                    "a layer of the frame (RGB) read as the second pass's pilot in place of "
                    "the first pass's output (empty: the first pass's)",
                    &NforParamsApi::pilotLayer, {})};
}

class Nfor : public FrontEndOf<NforParamsApi> {
  public:
    Nfor() : FrontEndOf("nfor", Defs()) {}

    std::unique_ptr<FrontEnd> Clone() const override { return std::make_unique<Nfor>(*this); }
    std::string Summary() const override {
        return "feature regression (NFOR): first-order fits of the colour on albedo, normal, "
               "depth (and pivot), bandwidth per pixel by SURE, a second pass over the first's "
               "output; runs on plain frames";
    }
    std::vector<std::string> Uses() const override {
        std::vector<std::string> layers = {"color", "albedo",   "normal", "depth",
                                           "pivot", "variance", "alpha"};
        if (!options.pilotLayer.empty()) layers.push_back(options.pilotLayer);
        return layers;
    }
    std::string Undemodulable(const Frame &, const std::string &) const override {
        // The pilot layer stays in radiance while the colour is divided.
        return options.pilotLayer.empty()
                   ? ""
                   : "--nfor-pilot-layer: the pilot layer is not demodulated";
    }

    Result Run(vk::Context &context, Inputs &inputs, const RunOptions &run) const override {
        NforOptions o = Options(inputs);
        o.keepStages = run.keepStages;
        return ResultOf(NforDenoise(context, InputsOf(inputs), o, inputs.Memo()));
    }

    // Whether the frame holds a glint for the floor (NforOptions::glintNoise): an albedo
    // channel above kNforGlintAlbedo, or a partly covered pixel's that its alpha's division
    // would lift above it.
    static bool GlintMayRun(Inputs &inputs) {
        const Image &albedo = inputs.Get("albedo");
        if (NforLineSpreads(albedo, kNforGlintAlbedo)) return true;
        if (!inputs.Has("alpha")) return false;
        const Image &alpha = inputs.Get("alpha");
        for (size_t i = 0; i < alpha.PixelCount(); ++i) {
            const float a = alpha.data[i];
            if (!(a > 0.f && a < 1.f)) continue;
            for (int c = 0; c < albedo.channels; ++c)
                if (albedo.Plane(c)[i] > kNforGlintAlbedo * a) return true;
        }
        return false;
    }

    TileNeeds Tiling(vk::Context &context, Inputs &inputs) const override {
        const NforOptions o = Options(inputs);
        int channels = inputs.Get("color").channels;
        // The kept pixels' pass runs where the noise is the frame's own (InputsOf), and
        // beside a layer unless --no-layer-passes (where the clamp reads the frame's own
        // estimate, which a run decides: the reach allows for it).
        const bool passesOff =
            options.noise == "auto" && inputs.Has("variance") && o.noLayerPasses;
        const int keptReach = NforKeptPassRadius(o, !passesOff, inputs.Has("albedo"));
        // The lights' spread reads the output of the 4 neighbours.
        const int lightReach = NforSpreadsLights(o, !passesOff, inputs.Has("albedo")) ? 1 : 0;
        // The clamp reads its 8 neighbours, its line test 2 pixels away, the line's floor
        // the emitters kNforLineFloorReach away.
        const int lineReach = o.fireflyLineFloor > 0 && inputs.Has("albedo")
                                  ? std::max(2, kNforLineFloorReach)
                              : o.fireflyLine > 0 ? 2
                                                  : 1;
        // Where it may read the layer, the lone samples' cap reads their flags
        // kNforLoneReach away, each of its 8 neighbours.
        const bool loneCap =
            options.noise == "auto" && inputs.Has("variance") && !o.noLoneSampleCap;
        const int clampReach = std::max(lineReach, loneCap ? kNforLoneReach + 1 : 0);
        // The distance's trust reads the clamped colour of the 8 neighbours, which reads
        // max(clamp, noise) further: 1 + max(clamp, noise), which the noise and clamp's
        // reach below already holds (both at least 1); the max keeps the trust named.
        const bool trusts =
            o.albedoNoise > 0 && !o.noDemodulatedDistance && inputs.Has("albedo");
        const int trustReach = trusts ? 1 : 0;
        // The glint floor (where the noise is the frame's own, on a frame with a glint) reads
        // the albedo kNforGlintReach away, the trust and the clamped colour of the 8
        // neighbours; its guard on the output reads the floor kNforGlintGuardReach away,
        // within the passes' reach.
        const bool glints = trusts && o.glintNoise > 0 && !o.noEdgeNoise &&
                            !(options.noise == "auto" && inputs.Has("variance")) &&
                            GlintMayRun(inputs);
        const int glintReach = glints ? kNforGlintReach : 0;
        int colourReach =
            o.patchRadius +
            std::max(std::max(o.noiseRadius, trustReach) + clampReach, glintReach);
        int featureReach = o.prefilterRadius > 0
                               ? o.prefilterRadius + o.prefilterPatch + o.noiseRadius + 1
                               : 0;
        TileNeeds needs;
        // A second pass reads the first's output as far as one pass reaches, and its own
        // patches around it.
        const int passReach = 3 * o.radius, pilotReach = PassReach(o) - passReach;
        // The specks' bound reads the fits' output of the 8 neighbours.
        const int speckReach = o.meanRadius > 0 && o.speckRelative >= 0 ? 1 : 0;
        needs.reach = passReach + pilotReach + std::max(colourReach, featureReach) +
                      o.sureRadius + speckReach +
                      (o.meanRadius > 0 ? LocalMeanReach(o.meanRadius) : 0) + keptReach +
                      lightReach;
        needs.reachText = fmt::format(
            "a pixel averages the fits of windows up to {} away, each fit reads {} further "
            "and the distances there {} more; {} for the second pass over the pilot; {} for "
            "the noise, clamp, patches, the distance's trust and the glint floor (or the "
            "features' "
            "prefilter); {} for the SURE "
            "average; {} for the specks' neighbours; {} for the local means; {} for the "
            "kept pixels' mean; {} for the lights' spread",
            o.radius, o.radius, o.radius, pilotReach, std::max(colourReach, featureReach),
            o.sureRadius, speckReach, o.meanRadius > 0 ? LocalMeanReach(o.meanRadius) : 0,
            keptReach, lightReach);
        // The distances at the largest windows a run may take (a noisy frame's).
        const NforOptions noisy = NforNoisyOptions(o);
        int offsets =
                ref::NforOffsetCount(std::max({o.radius, o.pilotWideRadius, noisy.radius})),
            features = 10, candidates = 4;
        // The largest one-binding buffer: the distances, or at small radii the coefficients,
        // the candidates, the packed inputs or the illumination.
        needs.bindingBytesPerPixel =
            4.0 * std::max({offsets, NforBetaStride(features, channels), candidates * channels,
                            NforPackedFloats(features), kNforIlluminationFloats});
        // The second pass's capped copy of the variance layer.
        const bool cappedPilot = o.pilotNoiseCap > 0 && options.noise == "auto" &&
                                 inputs.Has("variance") && !o.pilotBandwidths.empty();
        needs.bytesPerPixel =
            4.0 * (2 * offsets + 2 * NforBetaStride(features, channels) +
                   NforPackedFloats(features) + kNforIlluminationFloats +
                   candidates * (channels + 1) + 6 * channels + 3 * features + 3 +
                   (trusts ? 1 : 0) + (glints ? 2 : 0) + (cappedPilot ? channels : 0));
        // Whether the gate lets the coarse pass run is measured only for a frame too large
        // to run whole (a whole frame's run does not read the reach): a noise pass saved.
        bool whole =
            PlanTiles(context, needs, inputs.Width(), inputs.Height(), 0).tileWidth == 0;
        // The clamp's light (none in the coarse pass's run) reads, at each scale s, tents of
        // reach 2s for the means and 2s more for the gain's average, and the reach of its
        // guard, where it runs: where the passes of a frame without a variance layer do (not
        // under --no-layer-passes beside one), the coarse pass shut.
        // The rare light's spread runs after it: a receiver reads sources within its
        // Gaussian's reach, each its pair's distance further, and that one the clamp's
        // light's reach of an emitter.
        const int clampLightReach =
            o.meanRadius > 0 && o.clampLightRadius > 0 && !passesOff
                ? std::max(4 * o.clampLightRadius + 4 * o.clampLightFine + o.clampLightReach,
                           o.rareLightShare > 0
                               ? kNforRareRadius + o.rareLightPair + o.clampLightReach
                               : 0)
                : 0;
        const int fineReach = needs.reach + clampLightReach;
        // A frame that fits whole takes its gate's verdict unmeasured: the larger reach.
        const bool measured = o.coarse || !whole;
        if ((o.coarse || o.coarseGate > 0) &&
            (whole || NforCoarseRuns(context, InputsOf(inputs), o))) {
            // A frame the coarse pass runs on takes the noisy radius's windows.
            if (noisy.radius != o.radius) {
                needs.reach += PassReach(noisy) - PassReach(o);
                needs.reachText += fmt::format("; {} more for a noisy frame's {}x{} windows",
                                               PassReach(noisy) - PassReach(o),
                                               2 * noisy.radius + 1, 2 * noisy.radius + 1);
            }
            // The half-resolution pass reaches twice as far in this frame's pixels, its
            // 2x2 blocks on the frame's grid; the correction's windows 6 pixels more.
            needs.reach = 2 * needs.reach + 2 + 6;
            needs.align = 2;
            needs.reachText += "; doubled and 8 more for the coarse pass";
            if (!measured && fineReach > needs.reach) {
                needs.reach = fineReach;
                needs.reachText += fmt::format(
                    " (or {}, the clamp's light's without it, if larger)", fineReach);
            }
        } else {
            needs.reach = fineReach;
            needs.reachText += fmt::format("; {} for the clamp's light", clampLightReach);
        }
        // The line spread runs last on the frame's resolution, near lights alone: a frame
        // without one needs no reach for it.
        if (inputs.Has("albedo") && NforLineSpreads(inputs.Get("albedo"), o.lineSpread)) {
            needs.reach += kNforLineReach;
            needs.reachText += fmt::format("; {} for the line spread", kNforLineReach);
        }
        // The glint bands' pass runs after it, near glints alone: their reach holds the
        // structure tensor's and the samples'.
        if (o.glintBandRadius > 0 && inputs.Has("albedo") &&
            NforLineSpreads(inputs.Get("albedo"), kNforGlintAlbedo)) {
            needs.reach += kNforGlintBandReach;
            needs.reachText += fmt::format("; {} for the glint bands", kNforGlintBandReach);
        }
        // The rim hits run last, beside emitters alone: a pixel's light comes from rim
        // pixels within their radius, each decided by its core and ground within as much.
        if (o.rimRatio > 0 && NforLineSpreads(inputs.Get("albedo"), o.emitterAlbedo)) {
            needs.reach += 2 * NforRimSettings{}.radius;
            needs.reachText +=
                fmt::format("; {} for the rim hits", 2 * NforRimSettings{}.radius);
        }
        return needs;
    }

    std::unique_ptr<FrontEnd> ForTiles(vk::Context &context, Inputs &whole) const override {
        auto copy = std::make_unique<Nfor>(*this);
        NforInputs in = InputsOf(whole);
        copy->depthScale = NforDepthScale(in.depth);
        copy->pivotScale = NforPivotScale(in.pivot);
        // Whether the coarse pass runs and whether the clamp reads the variance layer:
        // decided once for the frame.
        const NforOptions o = Options(whole);
        if (!o.coarse && o.coarseGate > 0) in.coarseLevel = NforCoarseLevel(context, in, o);
        copy->coarseLevel = in.coarseLevel;
        NforFrameClampLoss(context, &in, o);
        copy->clampLoss = in.clampLoss;
        copy->coarseClampLoss = in.coarseClampLoss;
        return copy;
    }

    std::vector<Stage> Reference(vk::Context &, Inputs &inputs) const override {
        NforOptions o = Options(inputs);
        NforInputs in = InputsOf(inputs);
        std::vector<float> weights;
        std::vector<std::string> names;
        Image features = NforFeatures(in, o, &weights, &names);
        const ref::NforParams p = NforReferenceParams(o, weights);
        ref::NforInputs cpuIn{in.color, in.albedo, &features, in.variance, in.alpha, in.pilot};
        std::vector<std::pair<std::string, Image>> cpu;
        ref::Nfor(cpuIn, p, &cpu);
        std::vector<Stage> stages;
        for (auto &[name, image] : cpu) stages.push_back({name, std::move(image)});
        return stages;
    }

  private:
    // How far the passes read: a pixel averages the fits of windows up to the radius away,
    // each fit reads as far and the distances there as far again; a second pass reads the
    // first's output as far as its windows and its patches around it.
    static int PassReach(const NforOptions &o) {
        return 3 * o.radius + (!o.pilotBandwidths.empty()
                                   ? 3 * std::max(o.radius, o.pilotWideRadius) + o.patchRadius
                                   : 0);
    }

    // The options for this frame: the given ones, with the plain frame's wide windows
    // where the frame has no variance layer and the second pass has one bandwidth and no
    // wide windows of its own (a frame with statistics gains little from them for their
    // time).
    NforOptions Options(Inputs &inputs) const {
        NforOptions o = options.options;
        o.bandwidths = ParseBandwidths(options.bandwidths, "bandwidths");
        o.pilotBandwidths.clear();
        if (options.pilotBandwidths != "none")
            o.pilotBandwidths = ParseBandwidths(options.pilotBandwidths, "pilot-bandwidths");
        if (options.plainWideRadius > o.radius && o.pilotWideRadius == 0 &&
            o.pilotBandwidths.size() == 1 && !inputs.Has("variance")) {
            o.pilotWideRadius = options.plainWideRadius;
            o.wideAgreement = options.plainWideAgreement;
        }
        // The rare light's share was measured on frames without statistics only.
        if (inputs.Has("variance")) o.rareLightShare = 0;
        // So were the glint bands'.
        if (inputs.Has("variance")) o.glintBandRadius = 0;
        // The frame's spp (a pass over its spp layer) only where the rim hits could run.
        o.rimRatio = o.rimHits > 0 && inputs.Has("albedo")
                         ? NforRimRatio(FrameSamplesPerPixel(inputs), o.rimHits)
                         : 0.f;
        return o;
    }

    NforInputs InputsOf(Inputs &inputs) const {
        NforInputs in;
        in.color = &inputs.Get("color");
        for (auto [layer, field] :
             {std::pair{"albedo", &in.albedo}, {"normal", &in.normal}, {"depth", &in.depth}})
            if (inputs.Has(layer)) *field = &inputs.Get(layer);
        if (options.pivot == "auto" && inputs.Has("pivot")) in.pivot = &inputs.Get("pivot");
        if (inputs.Has("alpha")) in.alpha = &inputs.Get("alpha");
        if (!options.pilotLayer.empty()) in.pilot = &inputs.Get(options.pilotLayer);
        if (options.noise == "auto" && inputs.Has("variance"))
            in.variance = &inputs.Get("variance");
        in.depthScale = depthScale;
        in.pivotScale = pivotScale;
        in.clampLoss = clampLoss;
        in.coarseClampLoss = coarseClampLoss;
        in.coarseLevel = coarseLevel;
        return in;
    }

    // Set by ForTiles: the whole frame's divisors of depth and pivot, the fractions of its
    // light the clamp against its own estimate takes off and its relative noise (< 0: each
    // run's own).
    float depthScale = 0, pivotScale = 0;
    double clampLoss = -1, coarseClampLoss = -1;
    double coarseLevel = -1;  // the coarse pass's gate (NforCoarseLevel)
};

}  // namespace

std::unique_ptr<FrontEnd> NforFrontEnd() {
    return std::make_unique<Nfor>();
}

}  // namespace mcd::api
