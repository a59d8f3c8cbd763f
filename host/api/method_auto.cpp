// Method `auto` (issue #17): run the candidates the frame allows (host/api/registry.h),
// estimate each one's per-pixel error without the reference and combine them per pixel
// (the pipeline host/methods/auto.h; CPU reference cpu_reference/auto_combine.cpp).
#include "host/api/method_auto.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <map>
#include <numeric>
#include <optional>
#include <random>
#include <stdexcept>
#include <variant>

#include "host/api/registry.h"
#include "host/api/tiled_run.h"
#include "host/common/local_mean.h"
#include "host/common/parallel.h"
#include "host/io/hints.h"
#include "host/io/layer_names.h"
#include "host/methods/auto.h"
#include "host/methods/auto_flat.h"
#include "host/methods/auto_object_floor.h"
#include "host/methods/nfor.h"
#include "host/methods/nfor_band.h"
#include "host/methods/nfor_lights.h"
#include "host/methods/nfor_line.h"
#include "host/methods/run_memo.h"

namespace mcd::api {
namespace {

using Clock = std::chrono::steady_clock;

std::vector<ParamDef<AutoFrontEnd::Options>> OwnDefs() {
    using O = AutoFrontEnd::Options;
    return {
        FloatParam("budget",
                   "seconds auto may spend: a candidate that would start after this is left "
                   "out (--explain names it); the first always runs",
                   &O::budget, 0, 1e9),
        ChoiceParam("auto-combine",
                    "relative (per pixel, each candidate weighed by 1 / its smoothed error "
                    "estimate standing for the reference, and the value of least expected "
                    "relative squared error under those weights; equal weights where the "
                    "pixel's noise outweighs the estimates; on a frame without statistics, "
                    "weights), weights (the weighted mean), "
                    "select (the candidate with the smallest estimate) or mean (equal "
                    "weights, no estimate)",
                    &O::combine, {"relative", "weights", "select", "mean"}),
        ChoiceParam("auto-noise",
                    "the error estimate: auto (halves when the frame has half-buffers, "
                    "else variance when it has a variance layer, else frame), halves (each "
                    "candidate also runs on "
                    "half0 and is compared with half1; Rousselle et al. 2013), variance (SURE "
                    "from the variance layer, with a second run on a perturbed color) or "
                    "frame (SURE from a variance estimated from the frame itself, which the "
                    "candidates then read as the variance layer)",
                    &O::noise, {"auto", "variance", "halves", "frame"}),
        IntParam("auto-noise-radius",
                 "with --auto-noise frame: half-size of the window over which the smallest "
                 "squared second differences are averaged into the noise estimate",
                 &O::noiseRadius, 1, kAutoNoiseMaxRadius),
        ChoiceParam("auto-guide",
                    "what stands in for the reference in relMSE's denominator of the "
                    "estimates: combined (a first combination weighed by the plain squared "
                    "error estimates) or mean (the candidates' mean, which an overshooting "
                    "candidate inflates, hiding its own error: README)",
                    &O::guide, {"combined", "mean"}),
        IntParam("auto-radius", "half-size of the window the error estimates are averaged over",
                 &O::radius, 0, 64),
        ChoiceParam("auto-window",
                    "the final estimates' windows: tent (the tents of --auto-radius) or colour "
                    "(each tent weight also times exp(-d / --auto-window-bandwidth^2), d the "
                    "relative squared colour distance of the guide combination, so that the "
                    "windows keep to pixels of its colour; its gain on accumulated frames was "
                    "measured with --auto-radius 20: docs/methods/auto.md)",
                    &O::window, {"tent", "colour"}),
        FloatParam("auto-window-bandwidth",
                   "with --auto-window colour: the colour distance's bandwidth",
                   &O::windowBandwidth, 1e-3, 100),
        IntParam("auto-frame-radius",
                 "--auto-radius where the noise is the frame's own estimate (--auto-noise "
                 "frame, or auto on a frame without variance nor half-buffers)",
                 &O::frameRadius, 0, 64),
        FloatParam("auto-frame-power",
                   "--auto-power where the noise is the frame's own estimate", &O::framePower,
                   1e-3, 64),
        FloatParam("auto-power", "weights are 1 / error^power", &O::power, 1e-3, 64),
        FloatParam("auto-halves-power",
                   "--auto-power where the half-buffers estimate the errors (an accumulated "
                   "frame): lower weighs the candidates more evenly, where a bias both halves "
                   "share misleads the estimates",
                   &O::halvesPower, 1e-3, 64),
        FloatParam("auto-epsilon",
                   "size of the perturbation that measures each candidate's divergence, in "
                   "standard deviations of the pixel mean",
                   &O::epsilon, 1e-3, 10),
        FloatParam("auto-bayes-epsilon",
                   "--auto-epsilon for the bayes candidates: their log-domain shrinkage "
                   "bends within a fraction of a standard deviation",
                   &O::bayesEpsilon, 1e-3, 10),
        FloatParam("auto-noise-limit",
                   "with --auto-combine relative: a pixel whose variance of the mean is over "
                   "this times relMSE's denominator (of the candidates' equal-weight value) "
                   "weighs every candidate the same",
                   &O::noiseLimit, 1e-6, 1e9),
        FloatParam("auto-dark-limit",
                   "with --auto-combine relative: a candidate darker than the weighted mean "
                   "over sqrt(this) counts in the relative value as if it were there, so "
                   "that a small weight on it cannot pull a bright edge down (not at the "
                   "noisy pixels of --auto-noise-limit)",
                   &O::darkLimit, 1, 1e9),
        FloatParam("auto-noise-cap",
                   "largest variance of the mean over relMSE's denominator in the final "
                   "estimates: a pixel whose mean is mostly noise (a light seen by one "
                   "sample) weighs at most this over its variance in the window (0: no bound)",
                   &O::noiseCap, 0, 1e9),
        FloatParam("auto-halves-floor",
                   "beside half-buffers: raise each candidate's error estimate to at least "
                   "half1's variance over its window, at most this times the candidates' "
                   "median there, so that an estimate near zero by chance does not take all "
                   "the weight (0: off)",
                   &O::halvesFloor, 0, 1e6),
        FloatParam("auto-halves-rank",
                   "beside half-buffers: that floor times (the candidate's error estimate over "
                   "the frame / the smallest of those not left out, each first raised to 1% of "
                   "half1's variance over the frame) ^ this, so that where half1's noise hides "
                   "the differences the weights follow the frame's ranking instead of going "
                   "equal (0: the same floor for all; no effect with --auto-halves-floor 0)",
                   &O::halvesRank, 0, 4),
        ChoiceParam("auto-halves-variants",
                    "beside half-buffers: a method's variants (nfor and nfor layer, rhf and "
                    "rhf 2 scales, pivot and pivot no ids), whose errors go together, share "
                    "one candidate's weight, each estimate times (its method's candidates "
                    "left in) ^ (1 / --auto-halves-power) (share), or each weighs as one "
                    "(each); not under --auto-combine select, which weighs none",
                    &O::halvesVariants, {"share", "each"}),
        FloatParam("auto-halves-drop",
                   "beside half-buffers: leave out a candidate whose error estimate over the "
                   "frame is above this times the candidates' median (0: off; at least 1, so "
                   "the median's own is kept; none where that median is under 1e-4 or under "
                   "0.01 x half1's variance over the frame, within the halves' noise)",
                   &O::halvesDrop, 0, 1e6),
        FloatParam("auto-floor", "smallest relative error estimate a weight takes",
                   &O::floorError, 1e-12, 1),
        IntParam("auto-mean-radius",
                 "restore the input's local means over tents of 8x, then 2x this radius "
                 "after the combination, which leans dark where the candidates disagree (0: "
                 "off)",
                 &O::meanRadius, 0, 256),
        ChoiceParam("auto-mean-check",
                    "beside half-buffers: keep the restore of local means per window as far "
                    "as half1 says it lowers the error, the output's mean kept to 0.99 of "
                    "the input's (halves), or keep it whole (off)",
                    &O::meanCheck, {"halves", "off"}),
        IntParam("auto-mean-check-radius",
                 "with --auto-mean-check halves: the check's tents have radius twice this "
                 "(0: a 1x1 check, per pixel); values above --auto-radius / 2 act as that "
                 "(the estimates' windows): narrow, so that the share of the restore follows "
                 "half1 around a light's reflections",
                 &O::meanCheckRadius, 0, 32),
        FloatParam("auto-mean-gain",
                   "with --auto-mean-check halves, where the checked restore leaves the "
                   "output below 0.99 of the input's mean: first one gain over the whole "
                   "output, at most this, which moves no light between pixels, then the rest "
                   "by more of the restore, the same share everywhere (1: the restore "
                   "alone); half1 does not check the gain nor that lift: a brightness floor",
                   &O::meanGain, 1, 2),
        FloatParam("auto-mean-guard",
                   "beside half-buffers: a candidate whose mean over tents of "
                   "--auto-mean-guard-radius departs from the input's by t standard errors "
                   "of it (the variance of the pixel mean), t above this, has its error "
                   "estimate there multiplied by exp((t^2 - this^2) / 2), how much less "
                   "likely such a departure is under the input's noise, so that a candidate "
                   "that fades or ghosts an object weighs less on it (0: off); on, it runs "
                   "the half-buffers' second estimate pass also where the floor, the drop "
                   "and the variants are off",
                   &O::meanGuard, 0, 100),
        IntParam("auto-mean-guard-radius",
                 "with --auto-mean-guard: the radius of its tents (at most --auto-radius)",
                 &O::meanGuardRadius, 1, 16),
        ChoiceParam("auto-plain",
                    "on a frame without statistics (no variance layer, half-buffers, "
                    "histograms nor min/max/spp, as most renderers write), with or without "
                    "albedo and normals: nfor (run nfor alone, which beat the combination on "
                    "such frames; where it moves the mean luminance by over 1%, see "
                    "--auto-plain-mean) or combine (combine the candidates by SURE on the "
                    "frame's own noise estimate); --auto-noise other than auto or "
                    "--auto-combine mean combine too",
                    &O::plain, {"nfor", "combine"}),
        ChoiceParam("auto-plain-mean",
                    "with --auto-plain nfor, where nfor's output moved the frame's mean "
                    "luminance by over 1% (its firefly clamp took the light of rare bright "
                    "samples): gain (scale its output by one factor to the input's mean) or "
                    "combine (combine the candidates instead, a second run)",
                    &O::plainMean, {"gain", "combine"}),
        ChoiceParam("auto-object-floor",
                    "with the relative combination on a frame with an objectId layer: an "
                    "object whose luminance summed over it fell below "
                    "--auto-object-floor-level times the darkest candidate's moves toward the "
                    "candidates' weighted mean (the same weights) by the one fraction that "
                    "brings the sum to that level: after the "
                    "local-mean restore (after; the move is the weighted mean's over the "
                    "combination, the restore's change kept, taken --auto-object-floor-input "
                    "of the way on to the input), before it (before), or never "
                    "(off); "
                    "--explain names each object moved",
                    &O::objectFloor, {"after", "before", "off"}),
        FloatParam("auto-object-floor-level",
                   "with --auto-object-floor after or before: the share of the darkest "
                   "candidate's luminance sum an object is held to (1: all of it)",
                   &O::objectFloorLevel, 0.5, 1),
        FloatParam("auto-object-floor-input",
                   "with --auto-object-floor after: the share of the way from the "
                   "candidates' weighted mean (the restore's change kept) to the input that "
                   "the floor moves an object toward, so that its light goes back where the "
                   "samples found it rather than where the candidates spread it (0: the "
                   "weighted mean alone)",
                   &O::objectFloorInput, 0, 1),
        FloatParam("auto-object-lift",
                   "on a frame with an objectId layer and a variance layer or half-buffers, "
                   "last: an object whose luminance summed over it is below the input's by "
                   "more than this many standard errors of the input's sum (from the "
                   "variance layer, its channels taken as fully correlated, else from the "
                   "halves' difference per pixel; where the halves' difference summed over "
                   "the object says more, from that) is scaled up to that bound (at most twice "
                   "its light), as the input is the unbiased estimate of its light (0: off); "
                   "--explain names each object lifted",
                   &O::objectLift, 0, 100),
        FloatParam("auto-object-guard",
                   "on a frame with an objectId layer and half-buffers (with "
                   "--auto-object-guard-frames all, or a variance layer), before the "
                   "combination: per object of at least 64 px and per "
                   "candidate, t is the candidate's luminance summed over the object less "
                   "the input's, in standard errors of the input's sum (as "
                   "--auto-object-lift's, at least 1% of the sum); where t is below minus "
                   "this (with --auto-object-guard-sign both, |t| above it) the candidate's "
                   "error estimate on the object is multiplied by exp((t^2 - this^2) / 2), "
                   "as --auto-mean-guard's, so that the weights there move to the "
                   "candidates that keep the object's light (0: off); --explain names each "
                   "object and candidate it weighed down",
                   &O::objectGuard, 0, 100),
        ChoiceParam("auto-object-guard-sign",
                    "with --auto-object-guard: the departures it counts, darkening alone "
                    "(dark) or brightening too (both)",
                    &O::objectGuardSign, {"dark", "both"}),
        ChoiceParam("auto-object-guard-frames",
                    "with --auto-object-guard: the frames it runs on, those with half-buffers "
                    "(halves) or also those with a variance layer alone (all)",
                    &O::objectGuardFrames, {"halves", "all"}),
        FloatParam("auto-light-share",
                   "on a frame with an albedo layer, last: each emitter pixel (largest albedo "
                   "channel above 1.5) gives this share of nfor's lights' spread "
                   "(--weak-light-share 0.08, --light-share 0.004 of its output, nfor's "
                   "defaults) to each of its 4 neighbours that is no emitter, and keeps the "
                   "rest: a light's rim, which few samples hit and the combination leaves "
                   "dark (0: off)",
                   &O::lightShare, 0, 1),
        FloatParam("auto-flat-nfor",
                   "beside half-buffers, on a frame with albedo and normals, after the "
                   "object floor: where no albedo, normal or shading edge lies within a pixel "
                   "and the nfor candidate's output is within this share of the "
                   "combination's, nfor's output, if its light over those pixels is at least "
                   "0.995 of the combination's (0: off)",
                   &O::flatNfor, 0, 1),
        IntParam("auto-glint-band-radius",
                 "beside half-buffers, on a frame with an albedo channel above 8 (a glint), "
                 "last: nfor's glint bands' pass (as its --glint-band-radius) on the output: "
                 "within 16 px of a glint each pixel that is no emitter moves towards the "
                 "output's mean along its line (its structure tensor's direction of least "
                 "change) by the line's coherence, this many samples each side (0: off)",
                 &O::glintBandRadius, 0, kNforGlintBandReach - 1),
        IntParam(
            "auto-rim-hits",
            "on a frame with an albedo layer and a known spp, last: nfor's rim hits (as "
            "its --rim-hits) on the output: an emitter pixel that at most this many "
            "samples hit (its albedo at most this / spp of an emitter's within 2 pixels) "
            "is brought down to the geometric mean of its input and of its neighbours "
            "that are no emitter, its light moved to that light's brighter pixels (0: off)",
            &O::rimHits, 0, 1000),
        ChoiceParam("auto-candidates",
                    "the candidates auto may run, by their --explain labels, comma-separated "
                    "(\"nfor,rhf,pivot k0\"), or all (every one but awr and nfor layer, "
                    "which run where named); the others are left out",
                    &O::candidates, {})};
}

// The labels of --auto-candidates; empty for all.
std::vector<std::string> CandidateLabels(const std::string &list) {
    std::vector<std::string> labels;
    if (list == "all") return labels;
    size_t begin = 0;
    while (begin <= list.size()) {
        size_t end = std::min(list.find(',', begin), list.size());
        std::string label = list.substr(begin, end - begin);
        label.erase(0, label.find_first_not_of(' '));
        label.erase(label.find_last_not_of(' ') + 1);
        bool known = false;
        for (const RegisteredVariant &v : AutoVariants()) known |= v.variant->label == label;
        if (!known) {
            std::string all;
            for (const RegisteredVariant &v : AutoVariants())
                all += (all.empty() ? "" : ", ") + v.variant->label;
            throw Error(fmt::format("--auto-candidates: no candidate '{}' (all, or of: {})",
                                    label, all),
                        ErrorKind::InvalidArgument);
        }
        labels.push_back(label);
        begin = end + 1;
    }
    return labels;
}

const ParamDef<AutoFrontEnd::Options> *OwnDef(const std::string &param) {
    static const std::vector<ParamDef<AutoFrontEnd::Options>> defs = OwnDefs();
    for (const auto &def : defs)
        if (def.info.name == param) return &def;
    return nullptr;
}

// SURE's Monte Carlo divergence: the probe b, +-1 per value of the color (seeded: runs
// repeat).
Image MakeProbe(const Image &color) {
    Image probe(color.width, color.height, color.channels);
    std::mt19937 rng(0x17a0u);
    for (float &b : probe.data) b = (rng() & 1u) ? 1.f : -1.f;
    return probe;
}

// The color perturbed by epsilon sqrt(v) b, each value on its own: split among the cores.
Image Perturb(const Image &color, const Image &variance, const Image &probe, float epsilon) {
    Image perturbed(color.width, color.height, color.channels);
    ParallelValues(perturbed.data.size(), 8, [&](size_t begin, size_t end) {
        for (size_t i = begin; i < end; ++i)
            perturbed.data[i] = color.data[i] + epsilon *
                                                    std::sqrt(std::max(variance.data[i], 0.f)) *
                                                    probe.data[i];
    });
    return perturbed;
}

// What scoring bayes's split output takes: the offset 2 (v - c) of its estimate, and the
// indirect layer as read and perturbed by eps (c / sqrt(v)) b. Empty when the frame cannot
// score it.
struct SplitScore {
    Image offset, perturbedIndirect;
};

SplitScore ScoreSplit(Inputs &inputs, const Image &color, const Image &variance,
                      const Image &probe, float epsilon, std::vector<std::string> *plan) {
    SplitScore score;
    if (!inputs.Has("direct") || !inputs.Has("indirect")) return score;
    const char *lacks = !inputs.Has("direct.variance")     ? "direct.variance"
                        : !inputs.Has("indirect.variance") ? "indirect.variance"
                                                           : nullptr;
    if (lacks) {
        plan->push_back(fmt::format(
            "auto: bayes runs on the whole colour: its split output is scored with the "
            "variances of the direct and indirect means, and the frame has no {} layer",
            lacks));
        return score;
    }
    const Image direct = inputs.Get("direct"), indirect = inputs.Get("indirect");
    const Image vD = inputs.Get("direct.variance"), vI = inputs.Get("indirect.variance");
    for (const Image *image : {&direct, &indirect, &vD, &vI})
        if (!image->SameShape(color)) {
            plan->push_back(
                "auto: bayes runs on the whole colour: the split layers are not of the "
                "colour's shape");
            return score;
        }
    // The estimate holds for y = D + I: a frame whose split does not sum to its colour
    // (beyond float rounding) is not scored.
    size_t apart = 0;
    for (size_t i = 0; i < color.data.size(); ++i) {
        float d = direct.data[i], ind = indirect.data[i], y = color.data[i];
        if (std::isfinite(d) && std::isfinite(ind) && std::isfinite(y) &&
            std::fabs(d + ind - y) > 1e-4f * (std::fabs(d) + std::fabs(ind)) + 1e-6f)
            ++apart;
    }
    if (apart > 0) {
        plan->push_back(fmt::format(
            "auto: bayes runs on the whole colour: direct + indirect differs from color at "
            "{} values, and its split output is scored only where they sum to it",
            apart));
        return score;
    }
    score.offset = Image(color.width, color.height, color.channels);
    score.perturbedIndirect = indirect;
    for (size_t i = 0; i < color.data.size(); ++i) {
        double v = std::max(variance.data[i], 0.f), vi = std::max(vI.data[i], 0.f);
        double c = (v + vi - std::max(vD.data[i], 0.f)) / 2;
        // |Cov(I, y)| <= sqrt(v_I v): the layers' rounding (or a renderer's) cannot push it
        // past what a covariance can be.
        double bound = std::sqrt(v * vi);
        c = std::clamp(c, -bound, bound);
        if (!std::isfinite(c)) c = 0;
        score.offset.data[i] = float(2 * (v - c));
        double size = v > 0 ? c / std::sqrt(v) : 0;
        score.perturbedIndirect.data[i] += float(epsilon * size) * probe.data[i];
    }
    plan->push_back(
        "auto: bayes runs split (the indirect part denoised, direct added back), scored by "
        "SURE with c = Cov(indirect, color) from the direct, indirect and color variances");
    return score;
}

// Where the error estimate comes from, and what it reads.
struct Noise {
    bool scored = false;  // an estimate at all (not with --auto-combine mean)
    bool halves = false;  // the half-buffers' (else SURE)
    bool own = false;     // SURE on the frame's own estimate of the variance
    Image variance, probe, perturbed, bayesPerturbed, half0, half1;
    Image frameVariance;  // with the halves: the frame's variance layer, if any
    SplitScore split;     // with a variance layer: bayes's split output's score
    std::string from;     // for the plan
    // With the frame's own estimate: why nfor does not run alone (for nfor's plan line).
    std::string notAlone;
    std::vector<Timing> timings;
    // With the halves: the layers half0 has its own of (half0.<layer>), which its runs read.
    std::vector<std::string> half0Layers;
};

// The half-buffers (Rousselle, Manzi and Zwicker 2013): each candidate also runs on half0
// and is compared with the independent half1, E[(F(h0) - h1)^2] = E[(F(h0) - r)^2] +
// Var(h1), whatever the noise's distribution.
void HalvesNoise(Inputs &inputs, const Image &color, Noise &noise) {
    noise.half0 = inputs.Get("half0.color");
    noise.half1 = inputs.Get("half1.color");
    if (!noise.half0.SameShape(color) || !noise.half1.SameShape(color))
        throw Error(fmt::format("{}: half0.color and half1.color must have color's shape",
                                inputs.Path()),
                    ErrorKind::InvalidArgument);
    // Var(h1) = 2 Var(mean), and E[(h0 - h1)^2] = 4 Var(mean).
    noise.variance = Image(color.width, color.height, color.channels);
    for (size_t i = 0; i < noise.variance.data.size(); ++i) {
        double d = double(noise.half0.data[i]) - noise.half1.data[i];
        noise.variance.data[i] = float(d * d / 2);
    }
    // No divergence term: h1 is independent of F(h0).
    noise.probe = Image(color.width, color.height, color.channels);
    if (inputs.Has("variance")) noise.frameVariance = inputs.Get("variance");
    // half0's own layers (accumulate's): the frame's carry half1's samples too, and a run
    // that follows them would follow half1's noise and be estimated low.
    for (const std::string &name : io::Half0Layers())
        if (inputs.Has(name) && inputs.Has("half0." + name)) {
            const Image &own = inputs.Get("half0." + name);
            if (!own.SameShape(inputs.Get(name)))
                throw Error(
                    fmt::format("{}: half0.{} must have {}'s shape", inputs.Path(), name, name),
                    ErrorKind::InvalidArgument);
            noise.half0Layers.push_back(name);
        }
    noise.from = fmt::format(
        "the half-buffers (each candidate run on half0, {}, compared with half1{})",
        noise.half0Layers.empty()
            ? "with the frame's other layers"
            : fmt::format("with half0's own {}", fmt::join(noise.half0Layers, ", ")),
        noise.half0Layers.empty() ? ""
                                  : "; there each decides for itself what the run on the "
                                    "frame decides, such as rhf's cuts");
}

// No statistics (a plain Cycles frame): the variance of the mean from the frame itself, the
// local mean of the albedo-demodulated colour's smallest squared second difference over 4
// directions (README gives its ratio to real variance layers). The candidates read it as
// the frame's variance too: bayes's noise per band from it beat its own (MAD of the finest
// band) by 2-5x on the Cycles frames.
void OwnNoise(vk::Context &context, Inputs &inputs, const Image &color,
              const AutoFrontEnd::Options &o, Noise &noise) {
    const Image *albedo = nullptr;
    if (inputs.Has("albedo")) {
        const Image &a = inputs.Get("albedo");
        if (a.width == color.width && a.height == color.height &&
            (a.channels == 1 || a.channels >= color.channels))
            albedo = &a;
    }
    MethodResult estimate = AutoNoise(context, color, albedo, o.noiseRadius);
    for (const auto &t : estimate.timings) noise.timings.push_back({t.label, t.gpuMs});
    noise.variance = std::move(estimate.image);
    noise.probe = MakeProbe(color);
    noise.from = fmt::format(
        "SURE on the frame's own noise estimate (no variance layer nor half-buffers: the "
        "{}colour's smallest squared second difference over 4 directions, averaged over "
        "{}x{} windows), Monte Carlo divergence with epsilon {} (bayes {})",
        albedo ? "albedo-demodulated " : "", 2 * o.noiseRadius + 1, 2 * o.noiseRadius + 1,
        o.epsilon, o.bayesEpsilon);
    inputs.Override("variance", noise.variance);
}

// The estimate by --auto-noise and the frame's layers: SURE on the variance layer (a second
// run on a perturbed color gives the divergence), else the half-buffers, else SURE on the
// frame's own noise estimate.
Noise ChooseNoise(vk::Context &context, Inputs &inputs, const Image &color,
                  const AutoFrontEnd::Options &o, std::vector<std::string> *plan) {
    Noise noise;
    if (o.combine == "mean") {
        plan->push_back(
            "auto: no error estimate (--auto-combine mean): the candidates are averaged, each "
            "method with the same weight (shared by its variants)");
        return noise;
    }
    noise.scored = true;
    // The halves first where the frame has them (an accumulated frame: docs/methods/
    // auto.md): its variance layer, of few samples, is itself noisy and heavy-tailed.
    bool halves = (o.noise == "auto" || o.noise == "halves") && inputs.Has("half0.color") &&
                  inputs.Has("half1.color");
    bool variance =
        !halves && (o.noise == "auto" || o.noise == "variance") && inputs.Has("variance");
    if (halves) {
        noise.halves = true;
        HalvesNoise(inputs, color, noise);
        return noise;
    }
    if (variance) {
        noise.variance = inputs.Get("variance");
        if (!noise.variance.SameShape(color))
            throw Error(
                fmt::format("{}: the variance layer must have color's shape", inputs.Path()),
                ErrorKind::InvalidArgument);
        noise.probe = MakeProbe(color);
        noise.from = fmt::format(
            "SURE on the variance layer, Monte Carlo divergence with epsilon {} (bayes {})",
            o.epsilon, o.bayesEpsilon);
        // bayes's split output D + G(I) is no function of the colour alone, but SURE
        // extends to it given c = Cov(I, y) (cpu_reference/auto_combine.h): the frame's
        // variances of the direct and indirect means beside the colour's give it,
        // c = (v + v_I - v_D) / 2, where y = D + I. Else bayes runs on the whole colour.
        noise.split =
            ScoreSplit(inputs, color, noise.variance, noise.probe, o.bayesEpsilon, plan);
    } else if (o.noise == "frame" || (o.noise == "auto" && !halves)) {
        noise.own = true;
        OwnNoise(context, inputs, color, o, noise);
    } else {
        throw Error(
            fmt::format("{}: --auto-noise {}: the frame has no {}", inputs.Path(), o.noise,
                        o.noise == "halves" ? "half0.color and half1.color" : "variance layer"),
            ErrorKind::MissingLayer);
    }
    noise.perturbed = Perturb(color, noise.variance, noise.probe, o.epsilon);
    // bayes's own perturbation: its log-domain shrinkage bends within a fraction of a
    // standard deviation, so its divergence takes a smaller step (--auto-bayes-epsilon).
    noise.bayesPerturbed = Perturb(color, noise.variance, noise.probe, o.bayesEpsilon);
    return noise;
}

// A candidate that ran, and what the plan says of it.
struct Ran {
    AutoCandidate candidate;
    std::string colourName;
    double seconds = 0;
};

// The candidates that ran, what their own runs planned and their timings.
struct Candidates {
    std::vector<Ran> ran;
    std::vector<std::string> plans;
    std::vector<Timing> timings;
    // Each variant considered so far: its method and its parameter values.
    std::vector<std::pair<std::string, std::vector<ParamValue>>> seen;
};

std::vector<ParamValue> Values(const FrontEnd &method) {
    std::vector<ParamValue> values;
    for (const ParamInfo &info : method.Params()) values.push_back(method.Get(info.name));
    return values;
}

// Whether auto's setting of `param` (MethodEntry::autoSettings) applies: where an error
// estimate weighs the candidates (its reason is their weights; under --auto-combine mean the
// methods' own defaults run) and the user did not set the parameter.
bool AutoSettingApplies(const std::string &param, const AutoFrontEnd::Options &o) {
    return o.combine != "mean" &&
           std::find(o.given.begin(), o.given.end(), param) == o.given.end();
}

// The variant's method with the user's parameters, auto's settings where they apply and the
// variant's overrides on top.
std::unique_ptr<FrontEnd> WithSettings(const FrontEnd &base, const RegisteredVariant &v,
                                       const AutoFrontEnd::Options &o) {
    std::unique_ptr<FrontEnd> method = base.Clone();
    for (const auto &[param, value] : v.method->autoSettings)
        if (AutoSettingApplies(param, o)) method->Set(param, value);
    for (const auto &[param, value] : v.variant->overrides) method->Set(param, value);
    return method;
}

// The plan lines on auto's settings for the methods whose candidates ran: each applied, or
// why not.
void PlanAutoSettings(const std::vector<Ran> &ran, const AutoFrontEnd::Options &o,
                      std::vector<std::string> *plan) {
    for (const MethodEntry &entry : Registry()) {
        if (std::none_of(ran.begin(), ran.end(),
                         [&](const Ran &r) { return r.candidate.method == entry.name; }))
            continue;
        for (const auto &[param, value] : entry.autoSettings) {
            const bool given =
                std::find(o.given.begin(), o.given.end(), param) != o.given.end();
            if (AutoSettingApplies(param, o))
                plan->push_back(fmt::format(
                    "auto: {} candidates: --{} {}, auto's setting ({}; given, the option's "
                    "value holds)",
                    entry.name, param, ParamValueText(value), entry.autoSettingsWhy));
            else
                plan->push_back(fmt::format(
                    "auto: {} candidates: --{} {}, not auto's setting {}{}", entry.name, param,
                    given ? "as given" : "at the method's own default", ParamValueText(value),
                    given ? "" : " (no error estimate weighs them)"));
        }
    }
}

// The variant's front end: its method's with the user's parameters, auto's settings and its
// overrides on top. With an estimate bayes runs split only where the split can be scored
// (runsSplit).
std::unique_ptr<FrontEnd> Configure(const FrontEnd &base, const RegisteredVariant &v,
                                    const Noise &noise, const AutoFrontEnd::Options &o,
                                    bool *runsSplit) {
    std::unique_ptr<FrontEnd> method = WithSettings(base, v, o);
    *runsSplit = false;
    if (noise.scored && v.method->name == "bayes") {
        *runsSplit = !noise.split.offset.Empty() && !std::get<bool>(method->Get("no-split"));
        if (!*runsSplit) method->Set("no-split", true);
    }
    return method;
}

// Whether the variant filters as one considered before it does (the user's parameters or
// the frame make its overrides idle): left out without a word.
bool Repeats(const FrontEnd &method, const RegisteredVariant &v, Inputs &inputs,
             Candidates &done) {
    const std::vector<std::string> &layers = v.variant->differsWith;
    if (!layers.empty() && std::none_of(layers.begin(), layers.end(),
                                        [&](const auto &layer) { return inputs.Has(layer); }))
        return true;
    std::pair<std::string, std::vector<ParamValue>> key{v.method->name, Values(method)};
    if (std::find(done.seen.begin(), done.seen.end(), key) != done.seen.end()) return true;
    done.seen.push_back(std::move(key));
    return false;
}

// Why the variant stays out with this error estimate (AutoVariant::estimates), or "".
// Without an estimate (--auto-combine mean) only nfor stays out here; the variants stay out
// as variants (RunCandidates).
std::string OutByEstimate(const RegisteredVariant &v, const Noise &noise) {
    unsigned current = noise.halves ? AutoVariant::kHalves
                       : noise.own  ? AutoVariant::kOwn
                                    : AutoVariant::kVariance;
    if (v.variant->estimates & current) return "";
    if (v.variant->estimates == AutoVariant::kHalves)
        return fmt::format(
            "weighed by the half-buffers' estimate only, and the error "
            "estimate is {}",
            !noise.scored ? "none"
            : noise.own   ? fmt::format("the frame's own (on a frame without statistics "
                                          "nfor runs alone, not here: {})",
                                        noise.notAlone)
                          : "SURE on the variance layer");
    if (!noise.scored) return "";
    return fmt::format(
        "the error estimate is {}, and beside the candidates that run there it did not earn "
        "its time",
        noise.halves ? "the half-buffers'"
        : noise.own  ? "the frame's own"
                     : "SURE on the variance layer");
}

// The variant's probe: its own front end, or a cheaper one where the registry has one
// (AutoVariant::cheaperProbe), with a plan line naming what the probe changed.
std::unique_ptr<FrontEnd> CheaperProbe(const FrontEnd &method, const RegisteredVariant &v,
                                       Candidates &out) {
    if (!v.variant->cheaperProbe) return nullptr;
    std::unique_ptr<FrontEnd> probe = method.Clone();
    v.variant->cheaperProbe(*probe);
    std::string changed;
    for (const ParamInfo &info : method.Params()) {
        ParamValue before = method.Get(info.name), after = probe->Get(info.name);
        if (before == after) continue;
        changed += fmt::format("{}--{} {}", changed.empty() ? "" : ", ", info.name,
                               ParamValueText(after));
    }
    if (changed.empty()) return nullptr;
    out.plans.push_back(fmt::format(
        "{}: its probe with {} (a cheaper probe that weighed the candidates as well)",
        v.variant->label, changed));
    return probe;
}

// Run one candidate on the frame and, with an estimate, its probe: on the perturbed color
// (SURE), on half0 (the half-buffers), or for bayes's split output on the perturbed
// indirect part. The layers replaced for the probe are put back however it ends.
Ran RunCandidate(vk::Context &context, Inputs &inputs, const FrontEnd &method,
                 const RegisteredVariant &v, bool runsSplit, const Noise &noise,
                 const AutoFrontEnd::Options &o, const TileNeeds *shared, Candidates &out) {
    const std::string &label = v.variant->label;
    auto begin = Clock::now();
    // Each candidate in its own tiles where the frame does not fit it whole (host/api/
    // tiled_run.h), with its method's variants' halo (SharedTiling): auto's windows are then
    // the combination's alone.
    Result one = RunTiled(context, method, inputs, RunOptions(), shared);
    for (const std::string &line : one.plan) out.plans.push_back(label + ": " + line);
    for (const Timing &t : one.timings)
        out.timings.push_back({label + ": " + t.label, t.gpuMs});
    bool isBayes = v.method->name == "bayes";
    Ran r;
    r.candidate.label = label;
    r.candidate.method = v.method->name;
    r.candidate.output = std::move(one.image);
    r.candidate.split = runsSplit;
    r.candidate.epsilon = noise.halves ? 1.f : isBayes ? o.bayesEpsilon : o.epsilon;
    std::copy_n(v.variant->colour, 3, r.candidate.colour);
    r.colourName = v.variant->colourName;
    if (noise.scored) {
        // The probe keeps the run's decisions (FrontEnd::ForProbe, on the frame as given):
        // bayes's --zeros restore (the probe's noise can turn a lone zero's neighbours
        // black), rhf's cuts (a pixel cut in one run and filtered in the other moves by far
        // more than its colour did).
        // On half0 with half0's own layers the probe is the method's run on a frame of its
        // own, and decides for itself: the run's decisions read the frame's colour and
        // layers, which carry half1's samples, and a half0 run that follows half1 is
        // estimated low against it.
        const bool ownFrame = noise.halves && !noise.half0Layers.empty();
        std::unique_ptr<FrontEnd> decided =
            ownFrame ? nullptr : method.ForProbe(context, inputs, noise.halves);
        const FrontEnd &probed = decided ? *decided : method;
        ScopedOverrides probe(inputs);
        if (runsSplit) {
            // The probe perturbs I, the part bayes filters, by eps (c / sqrt(v)) b.
            probe.Override("indirect", noise.split.perturbedIndirect);
        } else {
            // The half run sees half the samples: the variance of its mean doubles (half0's
            // own variance, where the frame has it, is that already).
            const std::vector<std::string> &own = noise.half0Layers;
            if (!noise.frameVariance.Empty() &&
                std::find(own.begin(), own.end(), "variance") == own.end()) {
                Image doubled = noise.frameVariance;
                for (float &x : doubled.data) x *= 2;
                probe.Override("variance", std::move(doubled));
            }
            for (const std::string &name : own) probe.Alias(name, "half0." + name);
            probe.Override("color", noise.halves ? noise.half0
                                    : isBayes    ? noise.bayesPerturbed
                                                 : noise.perturbed);
        }
        std::unique_ptr<FrontEnd> cheaper = CheaperProbe(probed, v, out);
        Result probeRun =
            RunTiled(context, cheaper ? *cheaper : probed, inputs, RunOptions(), shared);
        for (const Timing &t : probeRun.timings)
            out.timings.push_back({label + " (probe): " + t.label, t.gpuMs});
        // What a probe that kept the run's decisions did (rhf's cuts: the run's counts).
        if (decided)
            for (const std::string &line : probeRun.plan)
                out.plans.push_back(label + " (probe): " + line);
        r.candidate.probe = std::move(probeRun.image);
    }
    const Image &output = r.candidate.output;
    if (!output.SameShape(inputs.Get("color")))
        throw Error(
            fmt::format("its output is {}x{}x{}", output.width, output.height, output.channels),
            ErrorKind::Internal);
    r.seconds = std::chrono::duration<double>(Clock::now() - begin).count();
    return r;
}

// The tile needs of the variants of `v`'s method that may run on these inputs, widened
// together (WidestNeeds), or none where the method does not share work window by window
// (TileNeeds::sharesByWindow: a wider halo would buy it nothing) or a variant's tiles change
// its output. Where they run in tiles they then cut the frame alike, and rhf at two scales
// takes rhf's selections and finest aggregations from the run memo window by window, as it
// does whole; the plan moves no pixel of a method whose tiles give the untiled bits. A
// variant whose needs cannot be told is left out of the plan (its own run tells why; RunTiled
// widens each run's own needs by the plan).
std::optional<TileNeeds> SharedTiling(vk::Context &context, Inputs &inputs,
                                      const FrontEnd &base, const RegisteredVariant &v,
                                      const Noise &noise, const AutoFrontEnd::Options &o,
                                      const std::vector<std::string> &allowed) {
    std::optional<TileNeeds> shared;
    for (const RegisteredVariant &other : AutoVariants()) {
        if (other.method->name != v.method->name) continue;
        const std::string &label = other.variant->label;
        const bool runs =
            allowed.empty() ? other.variant->byDefault
                            : std::find(allowed.begin(), allowed.end(), label) != allowed.end();
        if (!runs || !OutByEstimate(other, noise).empty() ||
            (!noise.scored && !other.variant->overrides.empty()))
            continue;
        TileNeeds needs;
        try {
            bool runsSplit = false;
            std::unique_ptr<FrontEnd> method = Configure(base, other, noise, o, &runsSplit);
            if (!method->Missing(inputs.Source()).empty()) continue;
            needs = method->Tiling(context, inputs);
        } catch (const Error &e) {
            if (e.Kind() == ErrorKind::Cancelled) throw;
            continue;
        }
        if (!needs.notLocal.empty() || !needs.sharesByWindow) return std::nullopt;
        shared = shared ? WidestNeeds(*shared, needs) : needs;
    }
    return shared;
}

// A variant auto runs, with its front end (Configure).
struct Chosen {
    RegisteredVariant v;
    std::unique_ptr<FrontEnd> method;
    bool runsSplit = false;
};

// The variants that run while the budget lasts, in run order: each left out (`leaveOut`, or
// a plan line for --auto-candidates) where it repeats another, needs an estimate to be
// weighed or lacks its layers.
std::vector<Chosen> ChooseCandidates(
    Inputs &inputs, const std::vector<std::unique_ptr<FrontEnd>> &methods, const Noise &noise,
    const AutoFrontEnd::Options &o, const std::vector<std::string> &allowed, Candidates &out,
    std::vector<std::string> *plan,
    const std::function<void(const std::string &, const std::string &)> &leaveOut) {
    std::vector<Chosen> chosen;
    for (const RegisteredVariant &v : AutoVariants()) {
        const std::string &label = v.variant->label;
        const FrontEnd *base = nullptr;
        for (const auto &m : methods)
            if (m->Name() == v.method->name) base = m.get();
        bool runsSplit = false;
        std::unique_ptr<FrontEnd> method = Configure(*base, v, noise, o, &runsSplit);
        if (!allowed.empty() &&
            std::find(allowed.begin(), allowed.end(), label) == allowed.end()) {
            plan->push_back(fmt::format("auto: left out {}: not in --auto-candidates", label));
            continue;
        }
        if (Repeats(*method, v, inputs, out)) continue;
        if (std::string why = OutByEstimate(v, noise); !why.empty()) {
            leaveOut(label, why);
            continue;
        }
        // With the frame's own estimate the variants run: without pivot k0, auto was x1.29
        // the best method on interior 16 spp with the ordinary passes only (pivot k0 is that
        // best method, 7x better than pivot); with it, at worst x1.06 over 10 such frames
        // (README). Without an estimate a variant cannot show where it is better: the
        // methods' own defaults only (on Cycles frames pivot k0 kept fireflies that k 0.3
        // removes).
        if (!noise.scored && !v.variant->overrides.empty()) {
            leaveOut(label, "a variant, and no error estimate to weigh it by");
            continue;
        }
        if (std::string lacks = method->Missing(inputs.Source()); !lacks.empty()) {
            leaveOut(label, lacks);
            continue;
        }
        if (allowed.empty() && !v.variant->byDefault) {
            leaveOut(label,
                     "it runs where --auto-candidates names it (beside the others it held "
                     "small shares for much time)");
            continue;
        }
        chosen.push_back({v, std::move(method), runsSplit});
    }
    return chosen;
}

// The candidates, in the registry's run order while the budget lasts, each variant left
// out where it repeats another, needs an estimate to be weighed or lacks its layers.
Candidates RunCandidates(vk::Context &context, Inputs &inputs,
                         const std::vector<std::unique_ptr<FrontEnd>> &methods,
                         const Noise &noise, const AutoFrontEnd::Options &o,
                         Clock::time_point start, std::vector<std::string> *plan) {
    Candidates out;
    // Why none ran, if none does: the first failure's kind, else the layers each lacked;
    // and the first failure's reason, else the first other left out's (not --auto-candidates').
    std::optional<ErrorKind> failure;
    std::string failed, firstOut;
    auto leaveOut = [&](const std::string &label, const std::string &why) {
        plan->push_back(fmt::format("auto: left out {}: {}", label, why));
        if (firstOut.empty()) firstOut = label + ": " + why;
    };
    std::vector<RegisteredVariant> variants = AutoVariants();
    const std::vector<std::string> allowed = CandidateLabels(o.candidates);
    // Each variant has a slot in the kernels.
    if (variants.size() > size_t(kAutoMaxCandidates))
        throw std::logic_error("auto: more variants in the registry than kernel slots");
    std::vector<Chosen> chosen =
        ChooseCandidates(inputs, methods, noise, o, allowed, out, plan, leaveOut);
    // Each method's shared tile plan (SharedTiling), made at its first candidate.
    std::map<std::string, std::optional<TileNeeds>> sharedPlans;
    auto sharedPlan = [&](const Chosen &c) -> const std::optional<TileNeeds> & {
        auto kept = sharedPlans.find(c.v.method->name);
        if (kept == sharedPlans.end()) {
            const FrontEnd *base = nullptr;
            for (const auto &m : methods)
                if (m->Name() == c.v.method->name) base = m.get();
            kept = sharedPlans
                       .emplace(c.v.method->name,
                                SharedTiling(context, inputs, *base, c.v, noise, o, allowed))
                       .first;
        }
        return kept->second;
    };
    // Every candidate's kernels start building now, behind those the runs ask for, so that
    // they build beside the first candidates' runs rather than on the way of their own.
    // Under a budget of the user's a candidate may be left out after the runs before it:
    // none is made ahead.
    if (std::find(o.given.begin(), o.given.end(), "budget") == o.given.end())
        for (const Chosen &c : chosen) {
            try {
                const std::optional<TileNeeds> &shared = sharedPlan(c);
                PrepareKernels(context, *c.method, inputs, shared ? &*shared : nullptr);
            } catch (const Error &e) {
                // The candidate's run meets it again and says so.
                if (e.Kind() == ErrorKind::Cancelled) throw;
            }
        }
    for (const Chosen &c : chosen) {
        const std::string &label = c.v.variant->label;
        double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
        if (!out.ran.empty() && elapsed > o.budget) {
            leaveOut(label, fmt::format("the budget ({} s) was spent after {:.2f} s", o.budget,
                                        elapsed));
            continue;
        }
        try {
            const std::optional<TileNeeds> &shared = sharedPlan(c);
            out.ran.push_back(RunCandidate(context, inputs, *c.method, c.v, c.runsSplit, noise,
                                           o, shared ? &*shared : nullptr, out));
            // The buffers a candidate kept for reuse (its run, probe and tiles share sizes)
            // go back: the host holds every output so far, and the next candidate's own
            // peak is what it needs.
            context.Pool().Trim();
        } catch (const Error &e) {
            if (e.Kind() == ErrorKind::Cancelled) throw;
            if (!failure) failure = e.Kind(), failed = label + ": " + e.what();
            leaveOut(label, e.what());
        }
    }
    if (out.ran.empty())
        throw Error(
            fmt::format(
                "{}: --method auto found no method for this frame{}", inputs.Path(),
                failed.empty() && firstOut.empty()
                    ? ""
                    : " (first left out: " + (failed.empty() ? firstOut : failed) + ")"),
            failure.value_or(ErrorKind::MissingLayer));
    PlanAutoSettings(out.ran, o, plan);
    return out;
}

// The candidates, sharing the work that depends on layers their runs and probes have in
// common (host/methods/run_memo.h: rhf's selections, from the histograms alone, and its
// finest scale's aggregation of a colour, at one scale and at two): the output is the same
// bit for bit, and the memo goes with the candidates' runs.
Candidates RunCandidatesSharing(vk::Context &context, Inputs &inputs,
                                const std::vector<std::unique_ptr<FrontEnd>> &methods,
                                const Noise &noise, const AutoFrontEnd::Options &o,
                                Clock::time_point start, std::vector<std::string> *plan) {
    RunMemo memo;
    struct Detach {
        Inputs &inputs;
        ~Detach() { inputs.SetMemo(nullptr); }
    } detach{inputs};
    inputs.SetMemo(&memo);
    return RunCandidates(context, inputs, methods, noise, o, start, plan);
}

// The combination's options. The frame's own estimate is rougher than a variance layer:
// milder weights over smaller windows (measured on frames without statistics,
// docs/methods/auto.md). And there the relative value leaned to the dark candidates over
// whole areas, so that path keeps the weighted mean.
AutoOptions CombineOptions(const AutoFrontEnd::Options &o, const Noise &noise,
                           const RunOptions &run) {
    AutoOptions c;
    c.combination = !noise.scored                           ? AutoCombination::Mean
                    : o.combine == "select"                 ? AutoCombination::Select
                    : o.combine == "relative" && !noise.own ? AutoCombination::Relative
                                                            : AutoCombination::Weights;
    c.meanGuide = o.guide == "mean";
    c.radius = noise.own ? o.frameRadius : o.radius;
    c.windowBandwidth = o.window == "colour" ? o.windowBandwidth : 0.f;
    c.power = noise.own ? o.framePower : noise.halves ? o.halvesPower : o.power;
    c.floorError = o.floorError;
    c.noiseLimit = o.noiseLimit;
    c.darkLimit = o.darkLimit;
    c.noiseCap = o.noiseCap;
    c.halvesFloor = o.halvesFloor;
    c.halvesRank = o.halvesRank;
    c.halvesVariants = o.halvesVariants == "share";
    if (o.halvesDrop > 0 && o.halvesDrop < 1)
        throw Error(fmt::format("--auto-halves-drop {}: 0 (off) or at least 1 (below, every "
                                "candidate could be left out)",
                                o.halvesDrop),
                    ErrorKind::InvalidArgument);
    c.halvesDrop = o.halvesDrop;
    // Within the strips' halo of twice the estimates' radius.
    c.meanGuard = o.meanGuard;
    c.meanGuardRadius = std::min(o.meanGuardRadius, c.radius);
    c.keepStages = run.keepStages;
    c.map = std::find(run.stages.begin(), run.stages.end(), "auto.map") != run.stages.end();
    return c;
}

// What the estimates read, taken from `noise` (the candidates have run).
AutoEstimateInputs EstimateInputs(Noise &noise, const AutoOptions &c) {
    AutoEstimateInputs in;
    if (!noise.scored) return in;
    if (c.combination == AutoCombination::Relative) {
        // The variance of the pixel mean: the halves' estimate of it is (h0 - h1)^2 / 4.
        in.meanVariance = noise.variance;
        if (noise.halves) {
            if (!noise.frameVariance.Empty())
                in.meanVariance = noise.frameVariance;
            else
                for (float &x : in.meanVariance.data) x /= 2;
        }
    }
    in.variance = std::move(noise.variance);
    in.probe = std::move(noise.probe);
    if (noise.halves) in.half1 = std::move(noise.half1);
    in.offset = std::move(noise.split.offset);
    return in;
}

// The plan's first lines: how the candidates were combined, then each one's share.
void PlanCombination(const AutoFrontEnd::Options &o, const AutoOptions &c, const Noise &noise,
                     const std::vector<AutoCandidate> &list, const std::vector<Ran> &ran,
                     const AutoResult &combined, std::vector<std::string> *plan) {
    int count = int(list.size());
    std::string how = fmt::format("weighted per pixel by 1 / error^{}", c.power);
    if (o.combine == "select")
        how = "selected per pixel by";
    else if (!noise.scored)
        how = "averaged";
    else if (c.combination == AutoCombination::Relative)
        how += fmt::format(
            ", the value of least expected relative squared error under those weights "
            "(equal where the pixel's variance is over {} x relMSE's denominator)",
            o.noiseLimit);
    std::string estimates;
    if (noise.scored)
        estimates = fmt::format(
            " (error estimates from {}, averaged over {}x{} windows{}; relMSE's denominator "
            "from {})",
            noise.from, 2 * c.radius + 1, 2 * c.radius + 1,
            c.windowBandwidth > 0 ? fmt::format(" weighed by the guide's colour (bandwidth {})",
                                                c.windowBandwidth)
                                  : "",
            c.meanGuide ? "the candidates' mean"
                        : "a first combination by their plain squared error");
    std::vector<std::string> lines = {
        fmt::format("auto: {} candidate{} {}{}", count, count == 1 ? "" : "s", how, estimates)};
    for (int k = 0; k < count; ++k)
        lines.push_back(fmt::format(
            "auto: ran {} ({}{:.2f} s): share {:.1f}%, largest weight in {:.1f}% of the "
            "pixels (map: {})",
            list[k].label,
            noise.halves   ? "twice, on the frame and on half0, "
            : noise.scored ? "twice, with the probe, "
                           : "",
            ran[k].seconds, combined.sharePercent[k], combined.wonPercent[k],
            ran[k].colourName));
    plan->insert(plan->begin(), lines.begin(), lines.end());
}

// An option given without the one it needs is refused before anything runs, on every path
// (nfor alone or a picked method would skip the combination that reads it).
void CheckNeededOptions(const AutoFrontEnd::Options &o) {
    bool bandwidthGiven =
        std::find(o.given.begin(), o.given.end(), "auto-window-bandwidth") != o.given.end();
    if (bandwidthGiven && o.window != "colour")
        throw Error(fmt::format("--auto-window-bandwidth {} needs --auto-window colour (the "
                                "tents have no bandwidth)",
                                o.windowBandwidth),
                    ErrorKind::InvalidArgument);
    for (const char *name : {"auto-object-guard-sign", "auto-object-guard-frames"})
        if (o.objectGuard == 0 &&
            std::find(o.given.begin(), o.given.end(), name) != o.given.end())
            throw Error(
                fmt::format("--{} needs --auto-object-guard above 0 (the guard is off)", name),
                ErrorKind::InvalidArgument);
}

// Whether the object floor runs, else (with `why`) the plan's line on why not.
bool FloorsObjects(const AutoFrontEnd::Options &o, const AutoOptions &c, Inputs &inputs,
                   std::string *why) {
    if (o.objectFloor == "off") return false;
    if (c.combination != AutoCombination::Relative)
        *why = "auto: object floor: left out (the combination is not the relative one)";
    else if (!inputs.Has("objectId"))
        *why = "auto: object floor: left out (the frame has no objectId layer)";
    return why->empty();
}

// The object floor on `image` (host/methods/auto_object_floor.h), one plan line per object.
void FloorObjects(Inputs &inputs, const std::vector<AutoCandidate> &list,
                  const std::vector<const Image *> &outputs, const Image &weighted,
                  const std::string &when, const std::string &toward, double level,
                  Image *image, std::vector<std::string> *plan) {
    size_t small = 0;
    std::vector<AutoObjectMove> moved =
        AutoObjectFloor(inputs.Get("objectId"), outputs, weighted, level, image,
                        kAutoObjectFloorMinPixels, &small);
    if (small > 0)
        plan->push_back(
            fmt::format("auto: object floor ({} the local-mean restore): left out {} "
                        "object{} of fewer than {} px",
                        when, small, small > 1 ? "s" : "", kAutoObjectFloorMinPixels));
    if (moved.empty())
        plan->push_back(
            fmt::format("auto: object floor ({} the local-mean restore): no object below {:g} "
                        "of its darkest "
                        "candidate's luminance",
                        when, level));
    for (const AutoObjectMove &m : moved)
        plan->push_back(fmt::format(
            "auto: object floor ({} the local-mean restore): object {:g} ({} px) at {:.3f} of "
            "its darkest candidate's luminance ({}) moved {:.3f} of the way to {} ({:.3f} of "
            "it)",
            when, m.id, m.pixels, m.before / m.target, list[m.darkest].label, m.alpha, toward,
            m.weighted / m.target));
}

// The object floor after the local-mean restore on `image`: its target the weighted mean's
// value with the restore's change kept, taken --auto-object-floor-input of the way to the
// input `color`. Frees `weighted` and `unrestored` (the unrestored combination) as it goes.
void FloorAfterRestore(const AutoFrontEnd::Options &o, Inputs &inputs,
                       const std::vector<AutoCandidate> &list,
                       const std::vector<const Image *> &outputs, const Image &color,
                       Image *weighted, Image *unrestored, Image *image,
                       std::vector<std::string> *plan) {
    Image target = AutoFloorTarget(*weighted, *unrestored, *image, &color, o.objectFloorInput);
    *weighted = Image();
    *unrestored = Image();
    std::string toward = "the candidates' weighted mean";
    if (o.objectFloorInput > 0)
        toward += fmt::format(" taken {:g} of the way to the input", o.objectFloorInput);
    FloorObjects(inputs, list, outputs, target, "after", toward, o.objectFloorLevel, image,
                 plan);
}

// A copy of the nfor candidate's output on the frame where --auto-flat-nfor will read it
// (beside the half-buffers, with albedo and normals), else empty.
Image FlatNforOutput(const AutoFrontEnd::Options &o, Inputs &inputs, const Noise &noise,
                     const std::vector<AutoCandidate> &list) {
    if (o.flatNfor == 0 || !noise.halves || !inputs.Has("albedo") || !inputs.Has("normal"))
        return Image();
    // The step reads three channels of each: a grey frame or a grey albedo is left as it is.
    for (const char *layer : {"color", "albedo", "normal"})
        if (inputs.Get(layer).channels < 3) return Image();
    for (const AutoCandidate &c : list)
        if (c.label == "nfor") return c.output;
    return Image();
}

// nfor's output at the flat pixels where it agrees (host/methods/auto_flat.h), one plan line.
void TakeNforWhereFlat(const AutoFrontEnd::Options &o, Inputs &inputs, const Image &nfor,
                       Image *image, std::vector<std::string> *plan) {
    if (nfor.Empty()) return;
    AutoFlatSettings s;
    s.agreement = o.flatNfor;
    AutoFlatResult r =
        AutoTakeNforWhereFlat(inputs.Get("albedo"), inputs.Get("normal"), nfor, s, image);
    plan->push_back(fmt::format(
        "auto: flat: {} pixels without an albedo, normal or shading edge within a pixel where "
        "nfor is within {:g} of the combination, nfor holding {:.4f} of its light there: {} "
        "(--auto-flat-nfor; at least {:g} of the light)",
        r.pixels, s.agreement, r.light, r.taken ? "nfor's output taken" : "left", s.keep));
}

// The frame's alpha layer, or null where it has none (the last passes leave alpha 0 alone).
const Image *AlphaOrNull(Inputs &inputs) {
    return inputs.Has("alpha") ? &inputs.Get("alpha") : nullptr;
}

// nfor's lights' spread at --auto-light-share of its shares on `image`, one plan line.
void SpreadLights(const AutoFrontEnd::Options &o, Inputs &inputs, Image *image,
                  std::vector<std::string> *plan) {
    if (o.lightShare == 0 || !inputs.Has("albedo")) return;
    NforLightSettings s;
    s.weakShare *= o.lightShare;
    s.strongShare *= o.lightShare;
    const size_t lights = NforSpreadLights(inputs.Get("albedo"), AlphaOrNull(inputs), s, image);
    if (lights == 0) return;
    plan->push_back(fmt::format(
        "auto: lights: {} emitter pixels (albedo above {:g}) gave {:g} (albedo below {:g}) or "
        "{:g} of their output to each of their 4 neighbours that is no emitter, {:g} of "
        "nfor's spread (--auto-light-share): a light's rim, which few samples hit and the "
        "combination left dark",
        lights, s.emitterAlbedo, s.weakShare, s.weakAlbedo, s.strongShare, o.lightShare));
}

// nfor's glint bands' pass on `image` (host/methods/nfor_band.h), one plan line where it
// moved a pixel.
void SmoothGlintBands(const AutoFrontEnd::Options &o, Inputs &inputs, Image *image,
                      std::vector<std::string> *plan) {
    if (o.glintBandRadius == 0 || !inputs.Has("albedo")) return;
    NforGlintBandSettings s;
    s.radius = o.glintBandRadius;
    s.glintAlbedo = kNforGlintAlbedo;
    s.reach = kNforGlintReach;
    const size_t moved =
        NforSmoothGlintBands(inputs.Get("albedo"), AlphaOrNull(inputs), s, image);
    if (moved == 0) return;
    plan->push_back(fmt::format(
        "auto: glint bands: {} pixels within {} of a glint (an albedo channel above {:g}) "
        "moved towards the output's mean along their line ({} samples each side), by its "
        "coherence, emitters left out (--auto-glint-band-radius)",
        moved, s.reach, s.glintAlbedo, s.radius));
}

// nfor's rim hits on `image` (host/methods/nfor_lights.h) against the frame's `color`, one
// plan line where they moved light.
void FoldRimHits(const AutoFrontEnd::Options &o, Inputs &inputs, const Image &color,
                 Image *image, std::vector<std::string> *plan) {
    if (o.rimHits == 0 || !inputs.Has("albedo")) return;
    const int spp = FrameSamplesPerPixel(inputs);
    NforRimSettings s;
    s.coreRatio = NforRimRatio(spp, o.rimHits);
    if (s.coreRatio == 0) return;
    const size_t folded =
        NforFoldRimHits(color, inputs.Get("albedo"), AlphaOrNull(inputs), s, image);
    if (folded == 0) return;
    plan->push_back(fmt::format(
        "auto: rim hits: {} emitter pixels of albedo at most 1/{:g} of an emitter's within {} "
        "(a light's rim that few samples hit) brought down to the geometric mean of their "
        "input and their ground's, the light they lost given to that light's core "
        "(--auto-rim-hits {}, spp {})",
        folded, s.coreRatio, s.radius, o.rimHits, spp));
}

// The object lift on `image` (host/methods/auto_object_floor.h), one plan line per object
// lifted, or one on why it was left out or lifted nothing.
void LiftObjects(const AutoFrontEnd::Options &o, Inputs &inputs, const Image &color,
                 Image *image, std::vector<std::string> *plan) {
    if (o.objectLift == 0) return;
    if (!inputs.Has("objectId")) {
        plan->push_back("auto: object lift: left out (the frame has no objectId layer)");
        return;
    }
    const bool variance = inputs.Has("variance");
    const bool halves = inputs.Has("half0.color") && inputs.Has("half1.color");
    if (!variance && !halves) {
        plan->push_back(
            "auto: object lift: left out (the frame has no variance layer nor half-buffers)");
        return;
    }
    // The halves' disagreement over each object beside the pixels' variance.
    const Image *half0 = halves ? &inputs.Get("half0.color") : nullptr;
    const Image *half1 = halves ? &inputs.Get("half1.color") : nullptr;
    Image lumVariance = AutoLuminanceVariance(
        color, variance ? &inputs.Get("variance") : nullptr, half0, half1);
    size_t small = 0;
    std::vector<AutoObjectLift> lifted =
        AutoObjectLiftToInput(inputs.Get("objectId"), color, lumVariance, half0, half1,
                              o.objectLift, image, kAutoObjectFloorMinPixels, &small);
    const char *source = variance ? (halves ? "the variance layer or, where larger, the "
                                              "halves' difference over the object"
                                            : "the variance layer")
                                  : "the half-buffers";
    if (lifted.empty())
        plan->push_back(fmt::format(
            "auto: object lift: no object below the input's luminance by over {:g} standard "
            "errors (from {}){}",
            o.objectLift, source,
            small > 0 ? fmt::format("; left out {} of fewer than {} px", small,
                                    kAutoObjectFloorMinPixels)
                      : ""));
    for (const AutoObjectLift &l : lifted)
        plan->push_back(fmt::format(
            "auto: object lift: object {:g} ({} px) at {:.3f} of the input's luminance, "
            "below its bound {:.3f} (the input's less {:g} standard errors of {:.4f}, from "
            "{}): scaled by {:.4f}{}",
            l.id, l.pixels, l.before / l.input, l.bound / l.input, o.objectLift,
            l.error / l.input,
            l.halves ? "the halves' difference over it"
                     : (variance ? "the variance layer" : "the half-buffers"),
            l.scale,
            l.scale < l.bound / l.before ? " (the largest scale, short of it)" : " to it"));
}

// The object guard's factors on the candidates' estimates (host/methods/auto_object_floor.h),
// one plan line per object and candidate weighed down, or one on why it did not run; empty
// factors where it did not.
Image GuardObjects(const AutoFrontEnd::Options &o, Inputs &inputs, const Image &color,
                   const Noise &noise, const std::vector<AutoCandidate> &list,
                   std::vector<std::string> *plan) {
    if (o.objectGuard == 0) return Image();
    const bool variance = inputs.Has("variance");
    const bool layers = inputs.Has("half0.color") && inputs.Has("half1.color");
    const bool halves = noise.halves && layers;
    const char *why = !noise.scored             ? "no estimates: the mean combination"
                      : !inputs.Has("objectId") ? "the frame has no objectId layer"
                      : !variance && !halves
                          ? "the frame has no variance layer nor half-buffers"
                      : !halves && o.objectGuardFrames == "halves"
                          ? (layers ? "the estimates are not the half-buffers'; "
                                      "--auto-object-guard-frames all"
                                    : "the frame has no half-buffers; "
                                      "--auto-object-guard-frames all")
                          : nullptr;
    if (why) {
        plan->push_back(fmt::format("auto: object guard: left out ({})", why));
        return Image();
    }
    const Image *half0 = halves ? &inputs.Get("half0.color") : nullptr;
    const Image *half1 = halves ? &inputs.Get("half1.color") : nullptr;
    const Image lumVariance = AutoLuminanceVariance(
        color, variance ? &inputs.Get("variance") : nullptr, half0, half1);
    std::vector<const Image *> outputs;
    for (const AutoCandidate &c : list) outputs.push_back(&c.output);
    AutoObjectGuard guard;
    guard.z = o.objectGuard, guard.both = o.objectGuardSign == "both";
    AutoObjectGuardResult guarded = AutoObjectGuardFactors(
        inputs.Get("objectId"), color, lumVariance, half0, half1, outputs, guard);
    const std::string small =
        guarded.small > 0
            ? fmt::format("; left out {} object{} of fewer than {} px", guarded.small,
                          guarded.small > 1 ? "s" : "", guard.minPixels)
            : "";
    if (guarded.hits.empty()) {
        plan->push_back(fmt::format(
            "auto: object guard: no candidate's object sum {} the input's by over {:g} "
            "standard errors{}",
            guard.both ? "departs from" : "below", o.objectGuard, small));
        return Image();
    }
    for (const AutoObjectGuardHit &hit : guarded.hits)
        plan->push_back(fmt::format(
            "auto: object guard: object {:g} ({} px): {} at t = {:.2f} standard errors of the "
            "input's sum, its estimate there times {:.3g} (--auto-object-guard {:g})",
            hit.id, hit.pixels, list[hit.candidate].label, hit.t, hit.factor, o.objectGuard));
    if (!small.empty()) plan->push_back("auto: object guard:" + small.substr(1));
    return std::move(guarded.factors);
}

// The floor's weighted mean from the combination's own weights (no second combination),
// which are dropped. Before the restore the floor moves the combination now; after it, the
// target is the restored value plus the weighted mean's excess over the unrestored
// combination kept here (AutoFloorTarget).
void StartFloor(const AutoFrontEnd::Options &options, Inputs &inputs,
                const std::vector<AutoCandidate> &list,
                const std::vector<const Image *> &outputs, AutoResult *combined,
                Image *weighted, Image *unrestored, std::vector<std::string> *plan) {
    *weighted = AutoWeightedMean(outputs, combined->weights, combined->image);
    combined->weights = Image();
    if (options.objectFloor == "after")
        *unrestored = combined->image;
    else
        FloorObjects(inputs, list, outputs, *weighted, "before",
                     "the candidates' weighted mean", options.objectFloorLevel,
                     &combined->image, plan);
}

}  // namespace

AutoFrontEnd::AutoFrontEnd() {
    for (const MethodEntry &entry : Registry()) {
        methods.push_back(entry.make());
        for (ParamInfo info : methods.back()->Params()) {
            for (const auto &[param, value] : entry.autoSettings)
                if (param == info.name)
                    info.help += fmt::format(
                        "; auto's {} candidates run with {} where it is not given (auto's "
                        "setting; not under --auto-combine mean)",
                        entry.name, ParamValueText(value));
            infos.push_back(info);
        }
    }
    for (ParamDef<Options> def : OwnDefs()) {
        def.info.defaultValue = def.get(Options());
        def.info.method = name;
        infos.push_back(def.info);
    }
}

AutoFrontEnd::AutoFrontEnd(const AutoFrontEnd &other)
    : infos(other.infos), options(other.options) {
    for (const auto &m : other.methods) methods.push_back(m->Clone());
}

std::unique_ptr<FrontEnd> AutoFrontEnd::Clone() const {
    return std::make_unique<AutoFrontEnd>(*this);
}

std::string AutoFrontEnd::Summary() const {
    return "its candidates that the frame's layers allow (awr only where --auto-candidates "
           "names it), combined per pixel by error estimates that need no reference (the "
           "half-buffers, else SURE from the variance layer); nfor alone on a frame without "
           "statistics";
}

void AutoFrontEnd::Set(const std::string &param, const ParamValue &value) {
    auto Given = [&] {
        if (std::find(options.given.begin(), options.given.end(), param) == options.given.end())
            options.given.push_back(param);
    };
    if (const auto *def = OwnDef(param)) {
        // A label that names no candidate is refused here, not at the run.
        if (param == "auto-candidates") CandidateLabels(std::get<std::string>(value));
        def->set(options, value);
        return Given();
    }
    for (auto &m : methods)
        for (const ParamInfo &info : m->Params())
            if (info.name == param) {
                m->Set(param, value);
                return Given();
            }
    throw Error("auto has no parameter '" + param + "'", ErrorKind::InvalidArgument);
}

ParamValue AutoFrontEnd::Get(const std::string &param) const {
    if (const auto *def = OwnDef(param)) return def->get(options);
    for (const auto &m : methods)
        for (const ParamInfo &info : m->Params())
            if (info.name == param) return m->Get(param);
    throw Error("auto has no parameter '" + param + "'", ErrorKind::InvalidArgument);
}

const FrontEnd &AutoFrontEnd::Base(const std::string &method) const {
    for (const auto &m : methods)
        if (m->Name() == method) return *m;
    throw std::logic_error("auto: no front end for " + method);
}

namespace {

// The error estimate ChooseNoise takes on these layers, as OutByEstimate reads it
// (AutoVariant::estimates' bits).
unsigned EstimateOnLayers(Inputs &inputs, const AutoFrontEnd::Options &o) {
    if (o.combine == "mean") return AutoVariant::kVariance;
    if ((o.noise == "auto" || o.noise == "halves") && inputs.Has("half0.color") &&
        inputs.Has("half1.color"))
        return AutoVariant::kHalves;
    if ((o.noise == "auto" || o.noise == "variance") && inputs.Has("variance"))
        return AutoVariant::kVariance;
    return AutoVariant::kOwn;
}

}  // namespace

TileNeeds AutoFrontEnd::Tiling(vk::Context &context, Inputs &inputs) const {
    TileNeeds needs;
    // A variant this estimate leaves out runs on no tile: its reach (and what measuring
    // it costs, nfor's coarse gate) is not the tiles'.
    const unsigned estimate = EstimateOnLayers(inputs, options);
    needs.notLocal =
        "auto: each tile fixes its candidates' frame-wide quantities, its own estimates, "
        "the restore's gain and lift and the object floor's, lift's and guard's sums";
    for (const RegisteredVariant &v : AutoVariants()) {
        const FrontEnd &base = Base(v.method->name);
        if (!base.Missing(inputs.Source()).empty() || !(v.variant->estimates & estimate))
            continue;
        std::unique_ptr<FrontEnd> method = WithSettings(base, v, options);
        TileNeeds one = method->Tiling(context, inputs);
        needs.reach = std::max(needs.reach, one.reach);
        needs.align = std::lcm(needs.align, std::max(one.align, 1));
    }
    // Tiles only where asked for (RunOptions::tileSize): each candidate runs in tiles of its
    // own where the frame does not fit it, and the combination in strips (host/methods/
    // auto.h), so what auto holds whole on the device is the frame's own noise estimate.
    // A forced tile's halo: the widest candidate's reach, twice the estimates' box radius
    // and the noise estimate's reach.
    const int box = std::max(options.radius, options.frameRadius);
    const int noise = options.noiseRadius + 1;
    // With the restore's check, its tent's radius too (about the estimates' box's).
    const int mean = options.meanRadius > 0 ? LocalMeanReach(options.meanRadius, true) +
                                                  (options.meanCheck == "halves" ? box : 0)
                                            : 0;
    // The guard's tents (at most the estimates' radius, hence the box's) feed the final
    // window only, so they lie within twice the box: box + guard <= 2 * box.
    const int guard = options.meanGuard > 0 ? std::min(options.meanGuardRadius, box) : 0;
    needs.reach += std::max(2 * box, box + guard) + noise + mean;
    needs.reachText = fmt::format(
        "the widest candidate's reach + twice the estimates' box radius {} (the guard's "
        "tents {} within it) + the noise estimate's {} + the local mean's coarse and fine "
        "tents {}",
        box, guard, noise, mean);
    // The glint bands' pass runs last beside the half-buffers, near glints alone.
    if (options.glintBandRadius > 0 && inputs.Has("half0.color") && inputs.Has("half1.color") &&
        inputs.Has("albedo") && NforLineSpreads(inputs.Get("albedo"), kNforGlintAlbedo)) {
        needs.reach += kNforGlintBandReach;
        needs.reachText += fmt::format("; {} for the glint bands", kNforGlintBandReach);
    }
    // The rim hits run last, beside emitters alone.
    if (options.rimHits > 0 && inputs.Has("albedo") &&
        NforLineSpreads(inputs.Get("albedo"), NforRimSettings{}.emitterAlbedo) &&
        NforRimRatio(FrameSamplesPerPixel(inputs), options.rimHits) > 0) {
        needs.reach += 2 * NforRimSettings{}.radius;
        needs.reachText += fmt::format("; {} for the rim hits", 2 * NforRimSettings{}.radius);
    }
    // The noise estimate: the colour, the albedo, their second differences and the result.
    needs.bytesPerPixel = 4 * 4 * 4;
    needs.bindingBytesPerPixel = 4 * 4;
    return needs;
}

// Every candidate's layers, and the half-buffers for the error estimate.
std::vector<std::string> AutoFrontEnd::Uses() const {
    std::vector<std::string> layers = {"half0.color", "half1.color", "direct.variance",
                                       "indirect.variance"};
    for (const std::string &name : io::Half0Layers()) layers.push_back("half0." + name);
    for (const auto &m : methods) {
        std::vector<std::string> uses = m->Uses();
        if (uses.empty()) return {};
        layers.insert(layers.end(), uses.begin(), uses.end());
    }
    return layers;
}

std::string AutoFrontEnd::Missing(const Frame &frame) const {
    for (const RegisteredVariant &v : AutoVariants())
        if (Base(v.method->name).Missing(frame).empty()) return "";
    return "no method has the layers it needs";
}

const FrontEnd &AutoFrontEnd::Pick(const Frame &frame, const std::string &demodulate,
                                   std::vector<std::string> *plan) const {
    CheckNeededOptions(options);
    std::string order;
    for (const MethodEntry *m : PickOrder()) order += (order.empty() ? "" : " > ") + m->name;
    for (const MethodEntry *m : PickOrder()) {
        const FrontEnd &c = Base(m->name);
        std::string lacks = c.Missing(frame);
        if (lacks.empty() && !demodulate.empty() && !c.Undemodulable(frame, demodulate).empty())
            lacks = "it cannot run on a demodulated frame";
        if (lacks.empty()) {
            plan->insert(
                plan->begin(),
                fmt::format("auto: {} (one method{}: the first of {} the frame "
                            "allows)",
                            c.Name(), demodulate.empty() ? "" : " with --demodulate", order));
            return c;
        }
        plan->push_back(fmt::format("auto: left out {}: {}", c.Name(), lacks));
    }
    throw Error(fmt::format("{}: --method auto found no method for this frame", frame.path),
                ErrorKind::MissingLayer);
}

std::vector<Stage> AutoFrontEnd::Reference(vk::Context &, Inputs &) const {
    throw Error("auto: pick a method first", ErrorKind::Internal);
}

std::string SampleStatistics(const Frame &frame, const FrontEnd &awr, const FrontEnd &rhf) {
    for (const char *layer : {"variance", "half0.color", "half1.color"})
        if (frame.Has(layer)) return fmt::format("the frame has {}", layer);
    for (const FrontEnd *method : {&awr, &rhf})
        if (method->Missing(frame).empty())
            return fmt::format("the frame has {}'s statistics", method->Name());
    return "";
}

std::string AutoFrontEnd::WhyNotNforAlone(const Frame &frame) const {
    if (options.plain != "nfor") return "--auto-plain combine";
    if (options.noise != "auto") return fmt::format("--auto-noise {}", options.noise);
    if (options.combine == "mean") return "--auto-combine mean";
    if (std::string has = SampleStatistics(frame, Base("awr"), Base("rhf")); !has.empty())
        return has;
    if (std::string lacks = Base("nfor").Missing(frame); !lacks.empty()) return lacks;
    return "";
}

const FrontEnd *AutoFrontEnd::PickWithoutStatistics(const Frame &frame,
                                                    std::vector<std::string> *plan) const {
    CheckNeededOptions(options);
    if (!WhyNotNforAlone(frame).empty()) return nullptr;
    plan->push_back(
        "auto: nfor alone (the frame has no statistics: no variance layer, half-buffers, "
        "histograms nor min/max/spp; --auto-plain combine combines the candidates instead)");
    // Without albedo and normals (Blender's default passes) nfor still runs alone: its fit
    // then follows the depth and the screen position, and the plan says how to get them.
    std::vector<std::string> features;
    for (const char *layer : {"albedo", "normal"})
        if (!frame.Has(layer)) features.push_back(layer);
    if (!features.empty()) {
        std::string follows =
            frame.Has("depth") ? "the depth and the screen position" : "the screen position";
        std::string what =
            fmt::format("nfor's fit follows {} only: no {} layer{}", follows,
                        fmt::join(features, " nor "), features.size() > 1 ? "s" : "");
        plan->push_back("auto: " + io::Lacks(frame, what, features));
    }
    for (const char *statistics : {"awr", "rhf"})
        plan->push_back(
            fmt::format("auto: left out {}: {}", statistics, Base(statistics).Missing(frame)));
    return &Base("nfor");
}

// The noise source, the candidates, their combination (host/methods/auto.h), the plan.
Result AutoFrontEnd::Run(vk::Context &context, Inputs &inputs, const RunOptions &run) const {
    auto start = Clock::now();
    CheckNeededOptions(options);
    const Image color = inputs.Get("color");
    if (color.channels < 1 || color.channels > 4)
        throw Error(fmt::format("{}: auto combines 1 to 4 colour channels, the color has {}",
                                inputs.Path(), color.channels),
                    ErrorKind::InvalidArgument);
    std::vector<std::string> plan;
    Noise noise = ChooseNoise(context, inputs, color, options, &plan);
    if (noise.own) {
        // Where nfor alone could run, it ran and moved the mean (KeepTheMeanOfNforAlone).
        noise.notAlone = WhyNotNforAlone(inputs.Source());
        if (noise.notAlone.empty())
            noise.notAlone = "nfor alone moved the frame's mean luminance by over 1%, above";
    }
    Candidates candidates =
        RunCandidatesSharing(context, inputs, methods, noise, options, start, &plan);
    std::vector<AutoCandidate> list;
    for (Ran &r : candidates.ran) list.push_back(std::move(r.candidate));
    AutoOptions combine = CombineOptions(options, noise, run);
    // The half0 runs' combination, for the restore's check against half1.
    const bool check = noise.halves && options.meanRadius > 0 && options.meanCheck == "halves";
    Image half0 = check ? noise.half0 : Image();
    AutoEstimateInputs estimate = EstimateInputs(noise, combine);
    // The half0 runs' combination (the restore's check) reads the same factors: the same
    // combination, the objects judged on the whole frame's samples.
    estimate.objectFactors = GuardObjects(options, inputs, color, noise, list, &plan);
    std::string noFloor;
    const bool floor = FloorsObjects(options, combine, inputs, &noFloor);
    combine.keepWeights = floor;
    AutoResult combined = AutoCombine(context, color, list, estimate, combine);
    PlanCombination(options, combine, noise, list, candidates.ran, combined, &plan);
    if (!noFloor.empty()) plan.push_back(noFloor);
    // The floor's weighted mean reuses the combination's weights: no second combination.
    std::vector<Image> outputs;
    std::vector<const Image *> outputPointers;
    for (AutoCandidate &c : list) outputPointers.push_back(&c.output);
    Image weighted, unrestored;
    if (floor)
        StartFloor(options, inputs, list, outputPointers, &combined, &weighted, &unrestored,
                   &plan);
    Result result = ResultOf(std::move(combined));
    const Image *variance = inputs.Has("variance") ? &inputs.Get("variance") : nullptr;
    // nfor's output on the frame for the flat pixels: the check puts the probes in its place.
    const Image flatNfor = FlatNforOutput(options, inputs, noise, list);
    if (check) {
        // The candidates' outputs are combined: their half0 runs take their place (the
        // floor after the restore keeps the outputs).
        const bool keep = floor && options.objectFloor == "after";
        outputPointers.clear();
        for (AutoCandidate &c : list) {
            if (keep) outputs.push_back(std::move(c.output));
            c.output = c.probe;
        }
        for (const Image &output : outputs) outputPointers.push_back(&output);
        AutoOptions quiet = combine;
        quiet.keepStages = quiet.map = quiet.keepWeights = false;
        quiet.meanGuardVarianceScale = 2;  // half0 holds half the samples
        Image combinedHalf = AutoCombine(context, half0, list, estimate, quiet).image;
        Image combinedFull = std::move(result.image);
        // The check's tents, within the estimates' windows (the tiles' reach holds those).
        const int check = std::min(options.meanCheckRadius, options.radius / 2);
        RestoreCheck kept = RestoreLocalMeansChecked(
            color, half0, estimate.half1, combinedFull, combinedHalf, options.meanRadius,
            variance, kLocalMeanRebalanceAuto, check, kRestoreCheckFloor, &result.image,
            options.meanGain);
        std::string lift = fmt::format("{:.2f} of the rest", kept.lift);
        if (kept.gain != 1) lift = fmt::format("times {:.4f} and ", kept.gain) + lift;
        plan.push_back(fmt::format(
            "auto: local mean: {}; kept per {}x{} tent as far as half1 says it lowers the "
            "error of the same combination of the half0 runs (mean share {:.2f}), then "
            "{} for {} of the input's mean (--auto-mean-check off: whole)",
            kept.restore, 4 * check + 1, 4 * check + 1, kept.meanShare, lift,
            kRestoreCheckFloor));
    } else if (options.meanRadius > 0) {
        plan.push_back("auto: local mean: " +
                       RestoreLocalMeansRebalanced(color, options.meanRadius, &result.image,
                                                   variance, kLocalMeanRebalanceAuto));
    }
    if (floor && options.objectFloor == "after")
        FloorAfterRestore(options, inputs, list, outputPointers, color, &weighted, &unrestored,
                          &result.image, &plan);
    TakeNforWhereFlat(options, inputs, flatNfor, &result.image, &plan);
    LiftObjects(options, inputs, color, &result.image, &plan);
    SpreadLights(options, inputs, &result.image, &plan);
    if (noise.halves) SmoothGlintBands(options, inputs, &result.image, &plan);
    FoldRimHits(options, inputs, color, &result.image, &plan);
    for (const AutoCandidate &c : list) result.candidates.push_back(c.label);
    list.clear();
    result.method = "auto";
    plan.insert(plan.end(), result.plan.begin(), result.plan.end());
    plan.insert(plan.end(), candidates.plans.begin(), candidates.plans.end());
    result.plan = std::move(plan);
    std::vector<Timing> timings = std::move(noise.timings);
    timings.insert(timings.end(), candidates.timings.begin(), candidates.timings.end());
    timings.insert(timings.end(), result.timings.begin(), result.timings.end());
    result.timings = std::move(timings);
    return result;
}

}  // namespace mcd::api
