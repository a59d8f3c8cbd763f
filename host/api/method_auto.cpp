// Method `auto` (issue #17): run the candidates the frame allows, estimate each one's
// per-pixel error without the reference and combine them per pixel (GPU kernels
// shaders/auto/; CPU reference cpu_reference/auto_combine.cpp).
#include "host/api/method_auto.h"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <iterator>
#include <numeric>
#include <random>
#include <stdexcept>

#include "host/api/png_sink.h"
#include "host/kernels/auto_combine.h"
#include "host/kernels/auto_estimate.h"
#include "host/kernels/auto_noise.h"
#include "host/kernels/auto_smooth.h"
#include "host/vk/gpu_image.h"
#include "shaders/auto/auto.h"
#include "shaders/auto/noise.h"

namespace mcd::api {
namespace {

// The order the single-method paths pick in (--demodulate, the reference), as before:
// the geometric mean over the built-in scenes of the error at equal time.
constexpr const char *kPickOrder[] = {"awr", "rhf", "bayes", "pivot"};

// A candidate: a method with some parameters set over the user's.
struct Variant {
    std::string label, method;
    std::vector<std::pair<std::string, ParamValue>> overrides;
};

// In the order they run while the budget lasts: the measured strongest first. The pivot
// variants without the guides ("no ids": --guides none) filter the pixels next to another
// object or part id, which pivot keeps as they are: on Blender Cycles frames, whose walls
// and objects each have an id, those pixels carried 83% of pivot's error on the 256x256
// cornell box, and with these two variants auto went from 5.16e-3 to 4.39e-3 there
// (accumulated 16 x 1 spp) and from 3.36e-3 to 1.87e-3 (plain 16 spp; README).
std::vector<Variant> Variants() {
    return {{"rhf", "rhf", {}},
            {"pivot", "pivot", {}},
            {"pivot k0", "pivot", {{"robust-k", 0.f}}},
            {"bayes", "bayes", {}},
            {"awr", "awr", {}},
            {"rhf 2 scales", "rhf", {{"nscales", 2}}},
            {"pivot no ids", "pivot", {{"guides", std::string("none")}}},
            {"pivot k0 no ids", "pivot", {{"robust-k", 0.f}, {"guides", std::string("none")}}},
            {"bayes no split", "bayes", {{"no-split", true}}}};
}

// The map's colour of variant v (linear RGB).
constexpr float kPalette[][3] = {{0.9f, 0.1f, 0.1f}, {0.1f, 0.7f, 0.1f}, {0.1f, 0.3f, 1.f},
                                 {1.f, 0.8f, 0.05f}, {0.8f, 0.1f, 0.9f}, {0.1f, 0.9f, 0.9f},
                                 {1.f, 0.5f, 0.f},   {0.5f, 0.5f, 0.5f}, {0.5f, 0.25f, 0.1f}};
constexpr const char *kPaletteName[] = {"red",  "green",  "blue", "yellow", "magenta",
                                        "cyan", "orange", "grey", "brown"};

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
                    "the error estimate: auto (variance when the frame has a variance "
                    "layer, else halves, else frame), halves (each candidate also runs on "
                    "half0 and is compared with half1; Rousselle et al. 2013), variance (SURE "
                    "from the variance layer, with a second run on a perturbed color) or "
                    "frame (SURE from a variance estimated from the frame itself, which the "
                    "candidates then read as the variance layer)",
                    &O::noise, {"auto", "variance", "halves", "frame"}),
        IntParam("auto-noise-radius",
                 "with --auto-noise frame: half-size of the window over which the smallest "
                 "squared second differences are averaged into the noise estimate",
                 &O::noiseRadius, 1, AUTO_NOISE_MAX_RADIUS),
        ChoiceParam("auto-guide",
                    "what stands in for the reference in relMSE's denominator of the "
                    "estimates: combined (a first combination weighed by the plain squared "
                    "error estimates) or mean (the candidates' mean, which an overshooting "
                    "candidate inflates, hiding its own error: README)",
                    &O::guide, {"combined", "mean"}),
        IntParam("auto-radius", "half-size of the window the error estimates are averaged over",
                 &O::radius, 0, 64),
        IntParam("auto-frame-radius",
                 "--auto-radius where the noise is the frame's own estimate (--auto-noise "
                 "frame, or auto on a frame without variance nor half-buffers)",
                 &O::frameRadius, 0, 64),
        FloatParam("auto-frame-power",
                   "--auto-power where the noise is the frame's own estimate", &O::framePower,
                   1e-3, 64),
        FloatParam("auto-power", "weights are 1 / error^power", &O::power, 1e-3, 64),
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
        FloatParam("auto-floor", "smallest relative error estimate a weight takes",
                   &O::floorError, 1e-12, 1),
        ChoiceParam("auto-map",
                    "write a PNG here: each pixel coloured by the candidate with the largest "
                    "weight (--explain gives the colours)",
                    &O::map, {})};
}

const ParamDef<AutoFrontEnd::Options> *OwnDef(const std::string &param) {
    static const std::vector<ParamDef<AutoFrontEnd::Options>> defs = OwnDefs();
    for (const auto &def : defs)
        if (def.info.name == param) return &def;
    return nullptr;
}

std::unique_ptr<FrontEnd> MethodByName(const std::string &name) {
    if (name == "awr") return AwrFrontEnd();
    if (name == "bayes") return BayesFrontEnd();
    if (name == "pivot") return PivotFrontEnd();
    return RhfFrontEnd();
}

double SecondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

AutoFrontEnd::AutoFrontEnd() {
    for (const char *m : {"awr", "bayes", "pivot", "rhf"}) {
        methods.push_back(MethodByName(m));
        for (const ParamInfo &info : methods.back()->Params()) infos.push_back(info);
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
    return "every method the frame's layers allow, combined per pixel by error estimates "
           "that need no reference (SURE from the variance layer or the half-buffers)";
}

void AutoFrontEnd::Set(const std::string &param, const ParamValue &value) {
    if (const auto *def = OwnDef(param)) return def->set(options, value);
    for (auto &m : methods)
        for (const ParamInfo &info : m->Params())
            if (info.name == param) return m->Set(param, value);
    throw Error("auto has no parameter '" + param + "'");
}

ParamValue AutoFrontEnd::Get(const std::string &param) const {
    if (const auto *def = OwnDef(param)) return def->get(options);
    for (const auto &m : methods)
        for (const ParamInfo &info : m->Params())
            if (info.name == param) return m->Get(param);
    throw Error("auto has no parameter '" + param + "'");
}

namespace {

// SURE's Monte Carlo divergence: the probe b, +-1 per value of the color (seeded: runs
// repeat).
Image MakeProbe(const Image &color) {
    Image probe(color.width, color.height, color.channels);
    std::mt19937 rng(0x17a0u);
    for (float &b : probe.data) b = (rng() & 1u) ? 1.f : -1.f;
    return probe;
}

// The color perturbed by epsilon sqrt(v) b.
Image Perturb(const Image &color, const Image &variance, const Image &probe, float epsilon) {
    Image perturbed = color;
    for (size_t i = 0; i < perturbed.data.size(); ++i)
        perturbed.data[i] +=
            epsilon * std::sqrt(std::max(variance.data[i], 0.f)) * probe.data[i];
    return perturbed;
}

// What scoring bayes's split output takes: the offset 2 (v - c) of its estimate, and the
// indirect layer as read and perturbed by eps (c / sqrt(v)) b. Empty when the frame cannot
// score it.
struct SplitScore {
    Image offset, indirect, perturbedIndirect;
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
    score.indirect = indirect;
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

}  // namespace

TileNeeds AutoFrontEnd::Tiling(vk::Context &context, Inputs &inputs) const {
    TileNeeds needs;
    needs.notLocal =
        "auto: each tile fixes its candidates' frame-wide quantities and its own estimates";
    int count = 0;
    for (const Variant &variant : Variants()) {
        const FrontEnd *base = nullptr;
        for (const auto &m : methods)
            if (m->Name() == variant.method) base = m.get();
        if (!base || !base->Missing(inputs.Source()).empty()) continue;
        std::unique_ptr<FrontEnd> method = base->Clone();
        for (const auto &[param, value] : variant.overrides) method->Set(param, value);
        TileNeeds one = method->Tiling(context, inputs);
        needs.reach = std::max(needs.reach, one.reach);
        needs.align = std::lcm(needs.align, std::max(one.align, 1));
        needs.bytesPerPixel = std::max(needs.bytesPerPixel, one.bytesPerPixel);
        needs.bindingBytesPerPixel =
            std::max(needs.bindingBytesPerPixel, one.bindingBytesPerPixel);
        needs.fixedBytes = std::max(needs.fixedBytes, one.fixedBytes);
        if (one.maxWidth > 0)
            needs.maxWidth =
                needs.maxWidth > 0 ? std::min(needs.maxWidth, one.maxWidth) : one.maxWidth;
        ++count;
    }
    // The combination holds every candidate's output (and its probe's) on the host and its
    // outputs, estimates and their means on the GPU. The estimates' box mean runs twice (the
    // guide's pass, then the final one), and on a frame without statistics the candidates
    // read a noise estimate that reaches noiseRadius + 1 further.
    double channels = 3, candidates = std::max(count, 1);
    const int box = std::max(options.radius, options.frameRadius);
    const int noise = options.noiseRadius + 1;
    needs.reach += 2 * box + noise;
    needs.reachText = fmt::format(
        "the widest candidate's reach + twice the estimates' box radius {} + the noise "
        "estimate's {}",
        box, noise);
    // Colour-sized: the colour, the output, the split's offset (and its zeros for the
    // others) and the relative combination's variance of the mean.
    needs.bytesPerPixel += 4 * (candidates * channels + 2 * candidates + 5 * channels);
    needs.bindingBytesPerPixel =
        std::max(needs.bindingBytesPerPixel, 4 * candidates * channels);
    return needs;
}

std::unique_ptr<FrontEnd> AutoFrontEnd::ForTiles(Inputs &whole) const {
    if (!options.map.empty())
        throw Error(
            fmt::format("--auto-map: {} runs auto in tiles, and the map of a tiled "
                        "run is not assembled from its tiles; leave --auto-map out",
                        whole.Path()));
    return Clone();
}

// Every candidate's layers, and the half-buffers for the error estimate.
std::vector<std::string> AutoFrontEnd::Uses() const {
    std::vector<std::string> layers = {"half0.color", "half1.color", "direct.variance",
                                       "indirect.variance"};
    for (const auto &m : methods) {
        std::vector<std::string> uses = m->Uses();
        if (uses.empty()) return {};
        layers.insert(layers.end(), uses.begin(), uses.end());
    }
    return layers;
}

std::string AutoFrontEnd::Missing(const Frame &frame) const {
    for (const auto &m : methods)
        if (m->Missing(frame).empty()) return "";
    return "no method has the layers it needs";
}

const FrontEnd &AutoFrontEnd::Pick(const Frame &frame, const std::string &demodulate,
                                   std::vector<std::string> *plan) const {
    std::string order;
    for (const char *m : kPickOrder) order += (order.empty() ? "" : " > ") + std::string(m);
    for (const char *m : kPickOrder) {
        const FrontEnd *c = nullptr;
        for (const auto &candidate : methods)
            if (candidate->Name() == m) c = candidate.get();
        std::string lacks = c->Missing(frame);
        if (lacks.empty() && !demodulate.empty() &&
            !c->Undemodulable(frame, demodulate).empty())
            lacks = "it cannot run on a demodulated frame";
        if (lacks.empty()) {
            plan->insert(
                plan->begin(),
                fmt::format("auto: {} (one method{}: the first of {} the frame "
                            "allows)",
                            c->Name(), demodulate.empty() ? "" : " with --demodulate", order));
            return *c;
        }
        plan->push_back(fmt::format("auto: left out {}: {}", c->Name(), lacks));
    }
    throw Error(fmt::format("{}: --method auto found no method for this frame", frame.path));
}

std::vector<Stage> AutoFrontEnd::Reference(vk::Context &, Inputs &) const {
    throw Error("auto: pick a method first");
}

Result AutoFrontEnd::Run(vk::Context &context, Inputs &inputs, const RunOptions &run) const {
    auto start = std::chrono::steady_clock::now();
    const Frame &frame = inputs.Source();
    const Image color = inputs.Get("color");
    int w = color.width, h = color.height, channels = color.channels;
    if (channels < 1 || channels > 4)
        throw Error(fmt::format("{}: auto combines 1 to 4 colour channels, the color has {}",
                                inputs.Path(), channels));
    std::vector<std::string> plan;

    // The estimate. Half-buffers (Rousselle, Manzi and Zwicker 2013): each candidate also
    // runs on half0 and is compared with the independent half1, E[(F(h0) - h1)^2] =
    // E[(F(h0) - r)^2] + Var(h1), whatever the noise's distribution. Else SURE from the
    // variance layer: a second run on a perturbed color gives the divergence.
    Image variance, half0, half1, probe, perturbed;
    std::string noiseFrom;
    bool ownNoise = false;  // the variance is auto's own estimate
    std::vector<Timing> noiseTimings;
    bool halves = inputs.Has("half0.color") && inputs.Has("half1.color");
    // Measured (README): SURE beat the halves on 3 of 4 frames with both (not on
    // relief-abc), so auto takes the halves only where there is no variance layer.
    bool useVariance = options.combine != "mean" && options.noise != "halves" &&
                       options.noise != "frame" && inputs.Has("variance");
    bool useHalves = options.combine != "mean" && halves && !useVariance &&
                     options.noise != "variance" && options.noise != "frame";
    if (useHalves) {
        half0 = inputs.Get("half0.color");
        half1 = inputs.Get("half1.color");
        if (!half0.SameShape(color) || !half1.SameShape(color))
            throw Error(fmt::format("{}: half0.color and half1.color must have color's shape",
                                    inputs.Path()));
        // Var(h1) = 2 Var(mean), and E[(h0 - h1)^2] = 4 Var(mean).
        variance = Image(w, h, channels);
        for (size_t i = 0; i < variance.data.size(); ++i) {
            double d = double(half0.data[i]) - half1.data[i];
            variance.data[i] = float(d * d / 2);
        }
        probe = Image(w, h, channels);  // no divergence term: h1 is independent of F(h0)
        noiseFrom = "the half-buffers (each candidate run on half0, compared with half1)";
    } else if (useVariance) {
        variance = inputs.Get("variance");
        if (!variance.SameShape(color))
            throw Error(
                fmt::format("{}: the variance layer must have color's shape", inputs.Path()));
        probe = MakeProbe(color);
        perturbed = Perturb(color, variance, probe, options.epsilon);
        noiseFrom = fmt::format(
            "SURE on the variance layer, Monte Carlo divergence with "
            "epsilon {} (bayes {})",
            options.epsilon, options.bayesEpsilon);
    } else if (options.combine != "mean" &&
               (options.noise == "frame" || (options.noise == "auto" && !halves))) {
        // No statistics (a plain Cycles frame): the variance of the mean from the frame
        // itself, the local mean of the albedo-demodulated colour's smallest squared
        // second difference over 4 directions (kernel auto_noise; README gives its ratio
        // to real variance layers). The candidates read it as the frame's variance too:
        // bayes's noise per band from it beat its own (MAD of the finest band) by 2-5x on
        // the Cycles frames.
        useVariance = ownNoise = true;
        vk::GpuImage gColor(context, w, h, channels, "auto.noise.color");
        vk::GpuImage gNoise(context, w, h, channels, "auto.noise");
        gColor.Upload(color);
        std::unique_ptr<vk::GpuImage> gAlbedo;
        if (inputs.Has("albedo")) {
            const Image &albedo = inputs.Get("albedo");
            if (albedo.width == w && albedo.height == h &&
                (albedo.channels == 1 || albedo.channels >= channels)) {
                gAlbedo = std::make_unique<vk::GpuImage>(context, w, h, albedo.channels,
                                                         "auto.noise.albedo");
                gAlbedo->Upload(albedo);
            }
        }
        vk::Recorder recorder(context);
        RecordAutoNoise(context, recorder, gColor, gAlbedo.get(), options.noiseRadius, gNoise);
        recorder.Submit();
        for (const auto &t : recorder.Timings()) noiseTimings.push_back({t.label, t.gpuMs});
        variance = gNoise.Download();
        probe = MakeProbe(color);
        perturbed = Perturb(color, variance, probe, options.epsilon);
        noiseFrom = fmt::format(
            "SURE on the frame's own noise estimate (no variance layer nor half-buffers: the "
            "{}colour's smallest squared second difference over 4 directions, averaged over "
            "{}x{} windows), Monte Carlo divergence with epsilon {} (bayes {})",
            gAlbedo ? "albedo-demodulated " : "", 2 * options.noiseRadius + 1,
            2 * options.noiseRadius + 1, options.epsilon, options.bayesEpsilon);
        inputs.Override("variance", variance);
    } else if (options.noise != "auto" && options.combine != "mean") {
        throw Error(fmt::format(
            "{}: --auto-noise {}: the frame has no {}", inputs.Path(), options.noise,
            options.noise == "halves" ? "half0.color and half1.color" : "variance layer"));
    }
    bool estimate = useHalves || useVariance;
    // bayes's split output D + G(I) is no function of the colour alone, but SURE extends to
    // it given c = Cov(I, y) (cpu_reference/auto_combine.h): the frame's variances of the
    // direct and indirect means beside the colour's give it, c = (v + v_I - v_D) / 2, where
    // y = D + I. Else bayes runs on the whole colour.
    SplitScore split;
    if (useVariance && !ownNoise)
        split = ScoreSplit(inputs, color, variance, probe, options.bayesEpsilon, &plan);
    // bayes's own perturbation: its log-domain shrinkage bends within a fraction of a
    // standard deviation, so its divergence takes a smaller step (--auto-bayes-epsilon).
    Image bayesPerturbed;
    if (useVariance) bayesPerturbed = Perturb(color, variance, probe, options.bayesEpsilon);
    // The frame's own estimate is rougher than a variance layer: milder weights over
    // smaller windows (measured on 10 frames without statistics, README: power 2 over 17x17
    // left double-textured x1.06 the best method and the Cycles cornell box at 4.3e-3; power
    // 1 over 9x9 keeps all 10 within 5%, 3.6e-3).
    int radius = ownNoise ? options.frameRadius : options.radius;
    float power = ownNoise ? options.framePower : options.power;
    if (!estimate)
        plan.push_back(
            "auto: no error estimate (--auto-combine mean): the candidates are averaged, each "
            "method with the same weight (shared by its variants)");

    // The candidates, while the budget lasts.
    struct Ran {
        std::string label;
        size_t variant;
        Image output, perturbed;
        double seconds;
        bool split = false;  // bayes's split output: the estimate takes split.offset
        float epsilon = 1;   // the probe's step (the halves: none)
    };
    std::vector<Ran> ran;
    std::vector<std::string> candidatePlans;  // what each candidate's own run did
    Result result;
    result.timings = noiseTimings;
    Image frameVariance =
        useHalves && inputs.Has("variance") ? inputs.Get("variance") : Image();
    std::vector<Variant> variants = Variants();
    // Each variant has a colour in the map and a slot in the kernels.
    if (variants.size() > std::size(kPalette) || variants.size() > AUTO_MAX_CANDIDATES)
        throw std::logic_error("auto: more variants than map colours or kernel slots");
    for (size_t v = 0; v < variants.size(); ++v) {
        const Variant &variant = variants[v];
        const FrontEnd *base = nullptr;
        for (const auto &m : methods)
            if (m->Name() == variant.method) base = m.get();
        std::unique_ptr<FrontEnd> method = base->Clone();
        for (const auto &[param, value] : variant.overrides) method->Set(param, value);
        // With an estimate bayes runs split only where the split can be scored; "bayes no
        // split" is then a variant of its own, else it is bayes again.
        bool runsSplit = false;
        if (variant.label == "bayes no split" &&
            (split.offset.Empty() || std::get<bool>(base->Get("no-split"))))
            continue;
        if (estimate && variant.method == "bayes") {
            runsSplit = !split.offset.Empty() && !std::get<bool>(method->Get("no-split"));
            if (!runsSplit) method->Set("no-split", true);
        }
        if (variant.label == "rhf 2 scales" && std::get<int>(base->Get("nscales")) == 2)
            continue;
        // Without guides to leave out (the user's --guides none, or a frame without normals
        // and ids) a "no ids" variant is its sibling again.
        bool noGuides = false;
        for (const auto &[param, value] : variant.overrides) noGuides |= param == "guides";
        if (noGuides &&
            (std::get<std::string>(base->Get("guides")) == "none" ||
             (!inputs.Has("normal") && !inputs.Has("objectId") && !inputs.Has("partId"))))
            continue;
        // With the frame's own estimate the variants run: without pivot k0, auto was x1.29
        // the best method on interior 16 spp with the ordinary passes only (pivot k0 is that
        // best method, 7x better than pivot); with it, at worst x1.06 over 10 such frames
        // (README). Without an estimate a variant cannot show where it is better: the
        // methods' own defaults only (on Cycles frames pivot k0 kept fireflies that k 0.3
        // removes).
        if (!estimate && !variant.overrides.empty()) {
            plan.push_back(
                fmt::format("auto: left out {}: a variant, and no error estimate to "
                            "weigh it by",
                            variant.label));
            continue;
        }
        if (std::string lacks = method->Missing(frame); !lacks.empty()) {
            plan.push_back(fmt::format("auto: left out {}: {}", variant.label, lacks));
            continue;
        }
        double elapsed = SecondsSince(start);
        if (!ran.empty() && elapsed > options.budget) {
            plan.push_back(
                fmt::format("auto: left out {}: the budget ({} s) was spent after "
                            "{:.2f} s",
                            variant.label, options.budget, elapsed));
            continue;
        }
        if (ran.size() == AUTO_MAX_CANDIDATES) break;
        auto begin = std::chrono::steady_clock::now();
        try {
            RunOptions quiet;
            Result one = method->Run(context, inputs, quiet);
            for (const std::string &line : one.plan)
                candidatePlans.push_back(variant.label + ": " + line);
            for (const Timing &t : one.timings)
                result.timings.push_back({variant.label + ": " + t.label, t.gpuMs});
            bool isBayes = variant.method == "bayes";
            Ran r{variant.label,
                  v,
                  std::move(one.image),
                  {},
                  0,
                  runsSplit,
                  useHalves ? 1.f
                  : isBayes ? options.bayesEpsilon
                            : options.epsilon};
            if (runsSplit) {
                // The probe perturbs I, the part bayes filters, by eps (c / sqrt(v)) b.
                inputs.Override("indirect", split.perturbedIndirect);
                Result probeRun = method->Run(context, inputs, quiet);
                inputs.Override("indirect", split.indirect);
                for (const Timing &t : probeRun.timings)
                    result.timings.push_back({variant.label + " (probe): " + t.label, t.gpuMs});
                r.perturbed = std::move(probeRun.image);
            } else if (estimate) {
                // The half run sees half the samples: the variance of its mean doubles.
                if (!frameVariance.Empty()) {
                    Image doubled = frameVariance;
                    for (float &x : doubled.data) x *= 2;
                    inputs.Override("variance", std::move(doubled));
                }
                inputs.Override("color", useHalves ? half0
                                         : isBayes ? bayesPerturbed
                                                   : perturbed);
                Result probeRun = method->Run(context, inputs, quiet);
                inputs.Override("color", color);
                if (!frameVariance.Empty()) inputs.Override("variance", frameVariance);
                for (const Timing &t : probeRun.timings)
                    result.timings.push_back({variant.label + " (probe): " + t.label, t.gpuMs});
                r.perturbed = std::move(probeRun.image);
            }
            if (!r.output.SameShape(color))
                throw Error(fmt::format("its output is {}x{}x{}", r.output.width,
                                        r.output.height, r.output.channels));
            r.seconds = SecondsSince(begin);
            ran.push_back(std::move(r));
        } catch (const Error &e) {
            inputs.Override("color", color);
            if (runsSplit) inputs.Override("indirect", split.indirect);
            if (!frameVariance.Empty()) inputs.Override("variance", frameVariance);
            plan.push_back(fmt::format("auto: left out {}: {}", variant.label, e.what()));
        }
    }
    if (ran.empty())
        throw Error(
            fmt::format("{}: --method auto found no method for this frame", inputs.Path()));

    // On the GPU: each candidate's estimate, their box means, the combination.
    int count = int(ran.size());
    vk::GpuImage gColor(context, w, h, channels, "auto.color");
    vk::GpuImage gCandidates(context, w, h, count * channels, "auto.candidates");
    vk::GpuImage gErrors(context, w, h, count, "auto.errors");
    vk::GpuImage gSmooth(context, w, h, count, "auto.smooth");
    vk::GpuImage gOutput(context, w, h, channels, "auto.output");
    vk::GpuImage gWeights(context, w, h, count, "auto.weights");
    gColor.Upload(color);
    Image packed(w, h, count * channels);
    size_t planeBytes = size_t(w) * h * sizeof(float);
    for (int k = 0; k < count; ++k)
        std::copy(ran[k].output.data.begin(), ran[k].output.data.end(),
                  packed.data.begin() + size_t(k) * channels * w * h);
    gCandidates.Upload(packed);
    vk::Recorder recorder(context);
    Image guideStage, rawErrors;  // kept with keepStages
    // Zero estimates weigh the candidates equally: the mean.
    vk::GpuImage gZeros(context, w, h, count, "auto.zeros");
    gZeros.Upload(Image(w, h, count));
    // Without an estimate every method gets the same weight, shared by its variants: a
    // constant "error" of the number of its variants that ran, weighed at power 1.
    vk::GpuImage gShares(context, w, h, count, "auto.shares");
    if (!estimate) {
        Image shares(w, h, count);
        for (int k = 0; k < count; ++k) {
            int siblings = 0;
            for (const Ran &other : ran)
                siblings += variants[other.variant].method == variants[ran[k].variant].method;
            std::fill(shares.data.begin() + size_t(k) * w * h,
                      shares.data.begin() + size_t(k + 1) * w * h, float(siblings));
        }
        gShares.Upload(shares);
    }
    if (estimate) {
        vk::GpuImage gVariance(context, w, h, channels, "auto.variance");
        vk::GpuImage gProbe(context, w, h, channels, "auto.probe");
        vk::GpuImage gOut(context, w, h, channels, "auto.candidate");
        vk::GpuImage gPerturbed(context, w, h, channels, "auto.perturbed");
        vk::GpuImage gError(context, w, h, 1, "auto.error");
        vk::GpuImage gOffset(context, w, h, channels, "auto.offset");
        vk::GpuImage gNoOffset(context, w, h, channels, "auto.nooffset");
        gVariance.Upload(variance);
        gProbe.Upload(probe);
        gNoOffset.Upload(Image(w, h, channels));
        if (!split.offset.Empty()) gOffset.Upload(split.offset);
        // With halves: F(h0) against h1 (zero probe, no divergence term).
        vk::GpuImage gHalf1(context, w, h, channels, "auto.half1");
        if (useHalves) gHalf1.Upload(half1);
        // Every candidate's estimate with the guide g in the denominator, g^2 + 0.01, then
        // their box means.
        auto estimateAll = [&](vk::GpuImage &gGuide, float noiseCap) {
            for (int k = 0; k < count; ++k) {
                gOut.Upload(useHalves ? ran[k].perturbed : ran[k].output);
                gPerturbed.Upload(ran[k].perturbed);
                RecordAutoEstimate(context, recorder, useHalves ? gHalf1 : gColor, gVariance,
                                   gProbe, gGuide, gOut, gPerturbed,
                                   ran[k].split ? gOffset : gNoOffset, ran[k].epsilon, noiseCap,
                                   gError);
                recorder.Copy(gError.buffer, gErrors.buffer, planeBytes, 0,
                              size_t(k) * planeBytes);
                recorder.Submit();
                for (const auto &t : recorder.Timings())
                    result.timings.push_back({t.label, t.gpuMs});
            }
            RecordAutoSmooth(context, recorder, gErrors, radius, gSmooth);
        };
        // relMSE's denominator needs the reference. The candidates' mean stood in for it,
        // but where one candidate overshoots (a firefly kept, a blotch) it inflates the
        // mean and so the denominator, which caps that candidate's estimated error at about
        // count^2 however far it is off: on relief-abc 16 spp 4% of the pixels carry 71-99%
        // of every candidate's error and the mean's denominator there is over 4 times the
        // reference's (README). So by default a first pass weighs the candidates by their
        // plain squared error (a zero guide: the same denominator everywhere) and its
        // combination, where the overshooting candidates already weigh little, is the guide.
        // Where the candidates disagree beyond what the estimates resolve it leans dark,
        // which suits relMSE: brightening a dark pixel costs without bound, darkening a
        // bright one at most 1.
        vk::GpuImage gGuide(context, w, h, channels, "auto.guide");
        if (options.guide == "mean") {
            RecordAutoCombine(context, recorder, gColor, gCandidates, gZeros, AutoMode::Weights,
                              1.f, 1.f, gGuide, gWeights);
        } else {
            vk::GpuImage gFlat(context, w, h, channels, "auto.flat");
            gFlat.Upload(Image(w, h, channels));
            estimateAll(gFlat, 0.f);
            RecordAutoCombine(context, recorder, gColor, gCandidates, gSmooth,
                              AutoMode::WeightsMedian, power, options.floorError, gGuide,
                              gWeights);
        }
        // The second pass bounds each pixel's weight by its noise: with a guide that can be
        // dark where a candidate is right to be bright (fireflies 4 spp: rhf darkens a light
        // seen by one sample, and so does the first pass), that pixel's estimate, of the
        // order of v / (g^2 + 0.01), would swamp every window around it.
        estimateAll(gGuide, options.noiseCap);
        if (run.keepStages) {
            recorder.Submit();
            for (const auto &t : recorder.Timings())
                result.timings.push_back({t.label, t.gpuMs});
            guideStage = gGuide.Download();
            rawErrors = gErrors.Download();
            for (int k = 0; k < count; ++k)
                result.stages.push_back({"auto." + ran[k].label + ".probe", ran[k].perturbed});
        }
    }
    // Where every estimate is under the floor they all weigh the same and tell nothing: the
    // candidates' median there, not their mean (at a firefly of a frame without statistics
    // every SURE estimate is negative, and the mean kept the firefly of the candidates that
    // keep it: fireflies 128x128 16 spp, ordinary passes, 0.088 -> 0.0146; README). The
    // relative combination (the default) takes the value of least expected relMSE under
    // the weights, and equal weights there and where the pixel's noise outweighs what the
    // windows' estimates resolve: a firefly that the candidates that remove it cannot win
    // by their window's estimates (README: double-textured 4 spp x2.45 -> x1.01).
    // On a frame without statistics the estimates are rougher and their weights milder
    // (power 1): there the relative value leaned to the dark candidates over whole areas
    // (our plain cornell 0.0019 -> 0.0079, README), so that path keeps the weighted mean.
    bool relative = estimate && options.combine == "relative" && !ownNoise;
    vk::GpuImage gMeanVariance(context, w, h, channels, "auto.meanvariance");
    if (relative) {
        // The variance of the pixel mean: the halves' estimate of it is (h0 - h1)^2 / 4.
        Image meanVariance = variance;
        if (useHalves) {
            if (!frameVariance.Empty())
                meanVariance = frameVariance;
            else
                for (float &x : meanVariance.data) x /= 2;
        }
        gMeanVariance.Upload(meanVariance);
        RecordAutoCombine(context, recorder, gColor, gCandidates, gSmooth, AutoMode::Relative,
                          power, options.floorError, gOutput, gWeights, &gMeanVariance,
                          options.noiseLimit, options.darkLimit);
    } else if (estimate)
        RecordAutoCombine(
            context, recorder, gColor, gCandidates, gSmooth,
            options.combine == "select" ? AutoMode::Select : AutoMode::WeightsMedian, power,
            options.floorError, gOutput, gWeights);
    else
        RecordAutoCombine(context, recorder, gColor, gCandidates, gShares, AutoMode::Weights,
                          1.f, 1e-3f, gOutput, gWeights);
    recorder.Submit();
    for (const auto &t : recorder.Timings()) result.timings.push_back({t.label, t.gpuMs});
    result.image = gOutput.Download();
    Image weights = gWeights.Download();
    if (run.keepStages) {
        for (int k = 0; k < count; ++k)
            result.stages.push_back({"auto." + ran[k].label, ran[k].output});
        if (estimate) {
            result.stages.push_back({"auto.guide", std::move(guideStage)});
            result.stages.push_back({"auto.estimates", std::move(rawErrors)});
            result.stages.push_back({"auto.errors", gSmooth.Download()});
        }
        result.stages.push_back({"auto.weights", weights});
    }

    // Each candidate's share (mean weight) and where it won (largest weight).
    size_t pixels = size_t(w) * h;
    std::vector<double> share(count, 0);
    std::vector<size_t> won(count, 0);
    Image map(w, h, 3);
    for (size_t i = 0; i < pixels; ++i) {
        int best = -1;
        for (int k = 0; k < count; ++k) {
            float wk = weights.data[k * pixels + i];
            share[k] += wk;
            if (wk > 0 && (best < 0 || wk > weights.data[best * pixels + i])) best = k;
        }
        if (best < 0) continue;
        ++won[best];
        for (int c = 0; c < 3; ++c) map.data[c * pixels + i] = kPalette[ran[best].variant][c];
    }
    std::string how = fmt::format("weighted per pixel by 1 / error^{}", power);
    if (options.combine == "select")
        how = "selected per pixel by";
    else if (!estimate)
        how = "averaged";
    else if (relative)
        how += fmt::format(
            ", the value of least expected relative squared error under those weights "
            "(equal where the pixel's variance is over {} x relMSE's denominator)",
            options.noiseLimit);
    plan.insert(plan.begin(),
                fmt::format("auto: {} candidate{} {}{}", count, count == 1 ? "" : "s", how,
                            estimate ? fmt::format(" (error estimates from {}, averaged over "
                                                   "{}x{} windows; relMSE's denominator from "
                                                   "{})",
                                                   noiseFrom, 2 * radius + 1, 2 * radius + 1,
                                                   options.guide == "mean"
                                                       ? "the candidates' mean"
                                                       : "a first combination by their "
                                                         "plain squared error")
                                     : ""));
    for (int k = 0; k < count; ++k)
        plan.insert(plan.begin() + 1 + k,
                    fmt::format("auto: ran {} ({}{:.2f} s): share {:.1f}%, largest weight in "
                                "{:.1f}% of the pixels (map: {})",
                                ran[k].label,
                                useHalves  ? "twice, on the frame and on half0, "
                                : estimate ? "twice, with the probe, "
                                           : "",
                                ran[k].seconds, 100 * share[k] / pixels,
                                100.0 * won[k] / pixels, kPaletteName[ran[k].variant]));
    if (!options.map.empty()) {
        WritePngThroughIo(options.map, map);
        plan.push_back("auto: wrote the map of the largest weights to " + options.map);
    }
    result.method = "auto";
    for (const Ran &r : ran) result.candidates.push_back(r.label);
    result.plan = std::move(plan);
    result.plan.insert(result.plan.end(), candidatePlans.begin(), candidatePlans.end());
    return result;
}

}  // namespace mcd::api
