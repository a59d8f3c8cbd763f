#include "host/methods/nfor.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "host/common/local_mean.h"
#include "host/error.h"
#include "host/kernels/nfor_kernels.h"
#include "host/methods/checks.h"
#include "host/methods/nfor_alpha.h"
#include "host/methods/nfor_band.h"
#include "host/methods/nfor_coarse.h"
#include "host/methods/nfor_kept.h"
#include "host/methods/nfor_lights.h"
#include "host/methods/nfor_line.h"
#include "host/methods/nfor_rare.h"
#include "host/methods/nfor_specks.h"
#include "host/methods/run_memo.h"
#include "host/vk/gpu_image.h"
#include "nfor/clamp.h"
#include "nfor/nfor.h"

namespace mcd {

namespace {

// The mean of the positive values of every channel (0 when none).
float PositiveMean(const Image *image) {
    if (!image) return 0;
    double sum = 0;
    size_t count = 0;
    for (float v : image->data)
        if (v > 0) sum += v, ++count;
    return count ? float(sum / double(count)) : 0.f;
}

}  // namespace

float NforDepthScale(const Image *depth) {
    return PositiveMean(depth);
}

float NforPivotScale(const Image *pivot) {
    return PositiveMean(pivot);
}

bool NforPilotMinVariance(const NforOptions &o) {
    return o.pilotMinVariance < 0 ? o.minVariance : o.pilotMinVariance != 0;
}

Image NforFeatures(const NforInputs &in, const NforOptions &o, std::vector<float> *weights,
                   std::vector<std::string> *names) {
    struct Group {
        const Image *image;
        const char *name;
        float scale, sigma;
        int planes;
    };
    float depthScale = in.depthScale > 0 ? in.depthScale : NforDepthScale(in.depth);
    float pivotScale = in.pivotScale > 0 ? in.pivotScale : NforPivotScale(in.pivot);
    std::vector<Group> groups;
    if (in.albedo) groups.push_back({in.albedo, "albedo", 1, o.albedoSigma, 3});
    if (in.normal) groups.push_back({in.normal, "normal", 1, o.normalSigma, 3});
    if (in.depth && depthScale > 0)
        groups.push_back({in.depth, "depth", 1 / depthScale, o.depthSigma, 1});
    if (in.pivot && pivotScale > 0)
        groups.push_back({in.pivot, "pivot", 1 / pivotScale, o.pivotSigma, 3});
    int w = in.color->width, h = in.color->height, planes = 0;
    for (const Group &g : groups) planes += g.planes;
    weights->clear();
    names->clear();
    if (planes == 0) {
        // No feature: one zero plane of weight 0 (the fit is then in screen position only).
        weights->push_back(0);
        return Image(w, h, 1);
    }
    Image features(w, h, planes);
    int at = 0;
    for (const Group &g : groups) {
        for (int k = 0; k < g.planes; ++k, ++at) {
            int c = std::min(k, g.image->channels - 1);
            for (size_t i = 0; i < features.PixelCount(); ++i)
                features.Plane(at)[i] = g.image->Plane(c)[i] * g.scale;
            weights->push_back(o.featureBandwidth > 0 ? 1 / (o.featureBandwidth * g.sigma) : 0);
        }
        names->push_back(g.name);
    }
    return features;
}

size_t GuardGlintFloor(const Image &clamped, const Image &floored, Image *output) {
    const int w = clamped.width, h = clamped.height, r = kNforGlintGuardReach;
    // The raised pixels' square of radius r: along rows, then columns.
    std::vector<char> rows(size_t(w) * h, 0), near(size_t(w) * h, 0);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int u = std::max(0, x - r); u <= std::min(w - 1, x + r); ++u)
                rows[size_t(y) * w + x] |= floored.data[size_t(y) * w + u] > 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int v = std::max(0, y - r); v <= std::min(h - 1, y + r); ++v)
                near[size_t(y) * w + x] |= rows[size_t(v) * w + x];
    size_t raised = 0;
    for (int c = 0; c < clamped.channels; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                if (!near[size_t(y) * w + x]) continue;
                float low = std::numeric_limits<float>::infinity();
                for (int v = std::max(0, y - 1); v <= std::min(h - 1, y + 1); ++v)
                    for (int u = std::max(0, x - 1); u <= std::min(w - 1, x + 1); ++u)
                        if (clamped.At(c, v, u) < low) low = clamped.At(c, v, u);
                float &value = output->At(c, y, x);
                if (std::isfinite(low) && low > value) {
                    value = low;
                    ++raised;
                }
            }
    return raised;
}

namespace {

void CheckLayer(const Image &image, const char *what, int width, int height, int channels,
                bool nonNegative) {
    mcd::CheckLayer("nfor", image, what, width, height, channels, nonNegative);
}

void CheckOptions(const NforOptions &o) {
    auto finite = [](float v) { return std::isfinite(v); };
    if (o.radius < 1 || o.radius > NFOR_MAX_RADIUS || o.patchRadius < 0 ||
        o.patchRadius > NFOR_MAX_PATCH)
        throw Error(fmt::format("nfor: radius {} (1..{}), patch radius {} (0..{})", o.radius,
                                NFOR_MAX_RADIUS, o.patchRadius, NFOR_MAX_PATCH),
                    ErrorKind::InvalidArgument);
    if (o.noisyRadius < 0 || o.noisyRadius > NFOR_MAX_RADIUS)
        throw Error(
            fmt::format("nfor: noisy radius {} (0..{})", o.noisyRadius, NFOR_MAX_RADIUS),
            ErrorKind::InvalidArgument);
    if (o.bandwidths.empty() || o.bandwidths.size() > NFOR_MAX_CANDIDATES)
        throw Error(fmt::format("nfor: {} bandwidths; 1 to {} allowed", o.bandwidths.size(),
                                NFOR_MAX_CANDIDATES),
                    ErrorKind::InvalidArgument);
    if (o.pilotBandwidths.size() > NFOR_MAX_CANDIDATES)
        throw Error(fmt::format("nfor: {} pilot bandwidths; at most {} allowed",
                                o.pilotBandwidths.size(), NFOR_MAX_CANDIDATES),
                    ErrorKind::InvalidArgument);
    std::vector<float> all = o.bandwidths;
    all.insert(all.end(), o.pilotBandwidths.begin(), o.pilotBandwidths.end());
    for (float k : all)
        if (!(finite(k) && k > 0))
            throw Error(fmt::format("nfor: bandwidth {} must be > 0", k),
                        ErrorKind::InvalidArgument);
    if (!(finite(o.ridge) && o.ridge > 0) || !(finite(o.alpha) && o.alpha >= 0) ||
        !(finite(o.featureBandwidth) && o.featureBandwidth >= 0) ||
        !(finite(o.fireflyThreshold) && o.fireflyThreshold >= 0) ||
        !(finite(o.fireflyLoneLight) && o.fireflyLoneLight >= 0) ||
        !(finite(o.fireflyLineFloor) && o.fireflyLineFloor >= 0) ||
        !(finite(o.noiseCalibration) && o.noiseCalibration > 0) ||
        !(finite(o.pilotAlpha) && o.pilotAlpha >= 0) ||
        !(finite(o.prefilterBandwidth) && o.prefilterBandwidth > 0) ||
        !(o.albedoSigma > 0 && o.normalSigma > 0 && o.depthSigma > 0 && o.pivotSigma > 0) ||
        o.meanRadius < 0 || o.clampLightRadius < 0 || o.clampLightFine < 0 ||
        o.clampLightReach < 0 || !(finite(o.coarseRelative) && o.coarseRelative >= 0) ||
        !(finite(o.coarseNoise) && o.coarseNoise >= 0) ||
        !(finite(o.coarseGate) && o.coarseGate >= 0) ||
        !(finite(o.wideAgreement) && o.wideAgreement >= 0) || !finite(o.speckRelative) ||
        !(finite(o.speckFloor) && o.speckFloor >= 0) ||
        !(o.weakLightShare >= 0 && o.weakLightShare <= 0.25f) ||
        !(o.lightShare >= 0 && o.lightShare <= 0.25f) ||
        !(finite(o.weakEmitterLine) && o.weakEmitterLine >= 0) ||
        !(finite(o.weakEmitterRange) && o.weakEmitterRange > 0) ||
        !(finite(o.layerNoiseCap) && o.layerNoiseCap >= 0) ||
        !(finite(o.pilotNoiseCap) && o.pilotNoiseCap >= 0) ||
        !(finite(o.albedoNoise) && o.albedoNoise >= 0) ||
        !(finite(o.glintNoise) && o.glintNoise >= 0) ||
        !(o.rareLightShare >= 0 && o.rareLightShare <= 1) ||
        !(finite(o.rareLightRatio) && o.rareLightRatio >= 1) || o.rareLightOthers < 1 ||
        o.rareLightPair < 1 || o.rareLightPair > kNforRarePair ||
        !(o.rimRatio == 0 || (finite(o.rimRatio) && o.rimRatio > 1)) || o.glintBandRadius < 0 ||
        o.glintBandRadius >= kNforGlintBandReach)
        throw Error(
            "nfor: ridge, noise calibration, prefilter bandwidth and the feature sigmas must "
            "be finite and > 0; alpha, feature bandwidth, firefly threshold, firefly lone "
            "light, pilot alpha, coarse relative, coarse noise, coarse gate, wide agreement, "
            "speck floor, layer and pilot noise caps, albedo noise, glint noise and weak "
            "emitter line finite and >= 0, weak emitter range finite and > 0, speck relative "
            "finite, mean radius >= 0, light shares 0 to 0.25, rare light share 0 to 1, "
            "ratio finite and >= 1, pair 1 to 16, others >= 1, rim ratio 0 or finite and "
            "above 1, glint band radius 0 to 15",
            ErrorKind::InvalidArgument);
    if (o.pilotWideRadius != 0 &&
        (o.pilotWideRadius <= o.radius || o.pilotWideRadius > NFOR_MAX_RADIUS ||
         o.pilotBandwidths.empty() || 2 * o.pilotBandwidths.size() > NFOR_MAX_CANDIDATES))
        throw Error(
            fmt::format("nfor: pilot wide radius {} must be 0 or above the radius {} "
                        "(at most {}), with 1 to {} pilot bandwidths",
                        o.pilotWideRadius, o.radius, NFOR_MAX_RADIUS, NFOR_MAX_CANDIDATES / 2),
            ErrorKind::InvalidArgument);
    if (o.noiseRadius < 1 || o.noiseRadius > NFOR_NOISE_MAX_RADIUS || o.prefilterRadius < 0 ||
        o.prefilterRadius > NFOR_PREFILTER_MAX_RADIUS || o.prefilterPatch < 0 ||
        o.prefilterPatch > NFOR_PREFILTER_MAX_PATCH || o.sureRadius < 0 ||
        o.sureRadius > NFOR_SURE_MAX_RADIUS || o.speckRank < 1 || o.speckRank > 8)
        throw Error(
            fmt::format("nfor: noise radius {} (1..{}), prefilter radius {} (0..{}) "
                        "and patch {} (0..{}), "
                        "SURE radius {} (0..{}), speck rank {} (1..8)",
                        o.noiseRadius, NFOR_NOISE_MAX_RADIUS, o.prefilterRadius,
                        NFOR_PREFILTER_MAX_RADIUS, o.prefilterPatch, NFOR_PREFILTER_MAX_PATCH,
                        o.sureRadius, NFOR_SURE_MAX_RADIUS, o.speckRank),
            ErrorKind::InvalidArgument);
}

// The largest window half-size of the passes.
int LargestRadius(const NforOptions &o) {
    return std::max(o.radius, o.pilotWideRadius);
}

// The candidates of the second pass: each bandwidth, and each again over wide windows.
int PilotCandidateCount(const NforOptions &o) {
    return int(o.pilotBandwidths.size()) * (o.pilotWideRadius > 0 ? 2 : 1);
}

// The layers' presence, shapes and values.
void CheckLayers(const NforInputs &in) {
    if (!in.color) throw Error("nfor: needs the color layer", ErrorKind::MissingLayer);
    const Image &color = *in.color;
    int w = color.width, h = color.height, ch = color.channels;
    if (w < 1 || h < 1) throw Error("nfor: the image is empty", ErrorKind::InvalidArgument);
    if (ch < 1 || ch > NFOR_MAX_CHANNELS)
        throw Error(fmt::format("nfor: color has {} channels; 1 to {} are supported", ch,
                                NFOR_MAX_CHANNELS),
                    ErrorKind::InvalidArgument);
    CheckLayer(color, "color", w, h, ch, false);
    if (in.variance) CheckLayer(*in.variance, "variance", w, h, ch, true);
    if (in.albedo) CheckLayer(*in.albedo, "albedo", w, h, 3, false);
    if (in.normal) CheckLayer(*in.normal, "normal", w, h, 3, false);
    if (in.depth) CheckLayer(*in.depth, "depth", w, h, 1, false);
    if (in.pivot) CheckLayer(*in.pivot, "pivot", w, h, 3, false);
    if (in.alpha) CheckLayer(*in.alpha, "alpha", w, h, 1, false);
    if (in.pilot) CheckLayer(*in.pilot, "pilot", w, h, ch, false);
}

// The inputs with each partly covered pixel divided by its alpha (host/methods/nfor_alpha.h):
// colour and features by alpha, the variance by alpha^2, depth and pivot then divided by
// the means of the layers as written (a tile's: the whole frame's). Without an alpha, with
// no pixel partly covered or with NforOptions::premultiplied: the inputs as they are.
struct StraightInputs {
    StraightInputs(const NforInputs &given, const NforOptions &o) : inputs(given) {
        inputs.alpha = nullptr;
        if (!given.alpha || o.premultiplied) return;
        const Image &alpha = *given.alpha;
        partlyCovered = NforPartlyCovered(alpha);
        if (partlyCovered == 0) return;
        auto divide = [&](const Image *image, std::optional<Image> &kept, const Image **field,
                          int power = 1) {
            if (!image) return;
            kept = NforDivideByAlpha(*image, alpha, power);
            *field = &*kept;
        };
        divide(given.color, color, &inputs.color);
        divide(given.albedo, albedo, &inputs.albedo);
        divide(given.normal, normal, &inputs.normal);
        divide(given.depth, depth, &inputs.depth);
        divide(given.pivot, pivot, &inputs.pivot);
        divide(given.variance, variance, &inputs.variance, 2);
        divide(given.pilot, pilot, &inputs.pilot);
        if (inputs.depthScale <= 0) inputs.depthScale = NforDepthScale(given.depth);
        if (inputs.pivotScale <= 0) inputs.pivotScale = NforPivotScale(given.pivot);
    }
    StraightInputs(const StraightInputs &) = delete;
    StraightInputs &operator=(const StraightInputs &) = delete;

    NforInputs inputs;
    size_t partlyCovered = 0;
    std::optional<Image> color, albedo, normal, depth, pivot, variance, pilot;
};

void CheckInputs(vk::Context &context, const NforInputs &in, const NforOptions &o) {
    CheckLayers(in);
    CheckOptions(o);
    int w = in.color->width, h = in.color->height;
    // The distance buffers hold one plane per stored offset in one binding each.
    double bytes = double(NforOffsetCount(LargestRadius(o))) * w * h * sizeof(float);
    if (bytes > double(context.BindingBytes()))
        throw Error(
            fmt::format("nfor: a {}x{} frame needs {:.0f} MB for the patch distances of radius "
                        "{}, above "
                        "this device's {:.0f} MB per binding; crop or tile the frame",
                        w, h, bytes / 1e6, o.radius, double(context.BindingBytes()) / 1e6),
            ErrorKind::OutOfMemory);
}

// The most candidates of a pass.
int CandidateCount(const NforOptions &o) {
    return std::max(int(o.bandwidths.size()), PilotCandidateCount(o));
}

// The GPU images of a run.
struct NforGpu {
    NforGpu(vk::Context &context, const NforInputs &in, const Image &featureImage,
            const NforOptions &o)
        : color(context, in.color->width, in.color->height, in.color->channels, "nfor.color"),
          variance(context, color.width, color.height, color.channels, "nfor.variance"),
          clampVariance(context, color.width, color.height, color.channels,
                        "nfor.clampVariance"),
          clamped(context, color.width, color.height, color.channels, "nfor.clamped"),
          mask(context, color.width, color.height, 1, "nfor.mask"),
          features(context, color.width, color.height, featureImage.channels, "nfor.features"),
          filtered(context, color.width, color.height, featureImage.channels, "nfor.filtered"),
          illumination(context, color.width, color.height, kNforIlluminationFloats,
                       "nfor.illumination"),
          packed(context, color.width, color.height, NforPackedFloats(featureImage.channels),
                 "nfor.packed"),
          beta(context, color.width, color.height,
               NforBetaStride(featureImage.channels, color.channels), "nfor.beta"),
          hat(context, color.width, color.height, CandidateCount(o), "nfor.hat"),
          candidates(context, color.width, color.height, CandidateCount(o) * color.channels,
                     "nfor.candidates") {
        color.Upload(*in.color);
        features.Upload(featureImage);
        if (in.variance) variance.Upload(*in.variance);
        if (in.albedo) {
            albedo.emplace(context, color.width, color.height, 3, "nfor.albedo");
            albedo->Upload(*in.albedo);
            if (o.albedoNoise > 0 && !o.noDemodulatedDistance)
                trust.emplace(context, color.width, color.height, 1, "nfor.trust");
            if (trust && !in.variance && !o.noEdgeNoise && o.glintNoise > 0 &&
                NforLineSpreads(*in.albedo, kNforGlintAlbedo)) {
                glintNear.emplace(context, color.width, color.height, 1, "nfor.glintNear");
                glint.emplace(context, color.width, color.height, 1, "nfor.glint");
            }
        }
        // A pass's candidates differing in their bandwidth alone are fitted two at a time.
        if (CandidateCount(o) > 1)
            secondBeta.emplace(context, color.width, color.height, beta.channels,
                               "nfor.secondBeta");
        if (!o.pilotBandwidths.empty()) {
            pilot.emplace(context, color.width, color.height, color.channels, "nfor.pilot");
            if (in.pilot) pilot->Upload(*in.pilot);
            if (in.variance && o.pilotNoiseCap > 0)
                pilotVariance.emplace(context, color.width, color.height, color.channels,
                                      "nfor.pilotVariance");
        }
    }
    // The patch distances over the run's windows, made once the coarse gate has decided
    // them (`o`: NforNoisyOptions on a noisy frame), so a run makes one set of them.
    void MakeDistances(vk::Context &context, const NforOptions &o) {
        const int w = color.width, h = color.height, offsets = NforOffsetCount(o.radius);
        distance = vk::GpuImage(context, w, h, offsets, "nfor.distance");
        scratch = vk::GpuImage(context, w, h, offsets, "nfor.scratch");
        if (!o.pilotBandwidths.empty())
            pilotDistance.emplace(context, w, h, offsets, "nfor.pilotDistance");
        if (o.pilotWideRadius > 0) {
            const int wide = NforOffsetCount(o.pilotWideRadius);
            wideDistance.emplace(context, w, h, wide, "nfor.wideDistance");
            wideScratch.emplace(context, w, h, wide, "nfor.wideScratch");
        }
    }

    vk::GpuImage color, variance, clampVariance, clamped, mask, features, filtered, distance,
        scratch, illumination, packed, beta, hat, candidates;
    std::optional<vk::GpuImage> albedo, trust, pilot, pilotVariance, pilotDistance,
        wideDistance, wideScratch, secondBeta, glintNear, glint;
};

// Planes [first, first + count) of a downloaded image.
Image PlanesOf(const Image &image, int first, int count) {
    Image part(image.width, image.height, count);
    std::copy(image.Plane(first), image.Plane(first) + part.Size(), part.data.begin());
    return part;
}

void PlanNoise(StagedRun &run, const NforInputs &in, const NforOptions &o) {
    if (in.variance) {
        run.Plan(o.layerNoiseCap > 0
                     ? fmt::format("noise of the colour: the frame's variance layer, capped at "
                                   "{} x the clamped colour's noise estimated from the frame "
                                   "(--layer-noise-cap)",
                                   o.layerNoiseCap)
                     : std::string("noise of the colour: the frame's variance layer"));
        if (o.pilotNoiseCap > 0 && !o.pilotBandwidths.empty())
            run.Plan(fmt::format(
                "the second pass's distance reads that noise capped at {} x the clamped "
                "colour's noise estimated from the frame (--pilot-noise-cap: a bright path's "
                "variance in the layer would let its pixel weigh with any neighbour)",
                o.pilotNoiseCap));
        return;
    }
    run.Plan(fmt::format(
        "noise of the colour estimated from the frame (no variance layer): per channel colour "
        "/ albedo{}, the median of half squared neighbour differences over {}x{} windows along "
        "4 directions{}, the smallest direction x {} (unbiased on Gaussian noise), x albedo^2",
        in.albedo ? "" : " (no albedo: the colour itself)", 2 * o.noiseRadius + 1,
        2 * o.noiseRadius + 1,
        o.noSparseNoise ? " (--no-sparse-noise)"
                        : " (their mean where that median is 0: most of a few samples 0)",
        o.noiseCalibration));
    if (o.noEdgeNoise)
        run.Plan("the same estimate for the firefly clamp and the weights (--no-edge-noise)");
    else
        run.Plan(
            "the firefly clamp reads that estimate; the weights one of the clamped colour "
            "in which a pixel with under 3 pairs divided alike along every direction (an edge "
            "pixel, its albedo a mix) takes its neighbours' pairs divided as it is");
}

void PlanFeatures(StagedRun &run, const std::vector<std::string> &names, const NforOptions &o) {
    std::string list;
    for (const std::string &n : names) list += (list.empty() ? "" : ", ") + n;
    if (names.empty()) {
        run.Plan(
            "features: none (no albedo, normal, depth or pivot layer): the fit is in the "
            "screen position only");
        return;
    }
    run.Plan(fmt::format(
        "features: {} (depth and pivot divided by their means), screen "
        "position; feature weights {}",
        list,
        o.featureBandwidth > 0 ? fmt::format("exp(-|dF|^2 / ({} sigma)^2), sigma albedo {}, "
                                             "normal {}, depth {}, pivot {}",
                                             o.featureBandwidth, o.albedoSigma, o.normalSigma,
                                             o.depthSigma, o.pivotSigma)
                               : std::string("off")));
    if (o.prefilterRadius > 0)
        run.Plan(fmt::format(
            "features prefiltered plane by plane: NL-means over {}x{}, patches {}x{}, "
            "bandwidth {}, with each plane's noise estimated from itself like the colour's",
            2 * o.prefilterRadius + 1, 2 * o.prefilterRadius + 1, 2 * o.prefilterPatch + 1,
            2 * o.prefilterPatch + 1, o.prefilterBandwidth));
    else
        run.Plan("left out: the features' prefilter (--prefilter-radius 0)");
}

// The clamp's light counts as the frame's own only where it clamped at least this share of
// the pixel-channels: a few fireflies may carry much of a small frame's light.
constexpr double kClampLossMinShare = 1e-3;

// The fraction of the colour's sum over every pixel and channel that the clamp took off
// (0 where the sum is not positive or it clamped under kClampLossMinShare of the values).
double ClampLoss(const Image &color, const Image &clamped) {
    double sum = 0, taken = 0;
    size_t count = 0;
    for (size_t i = 0; i < color.Size(); ++i) {
        sum += color.data[i];
        taken += double(color.data[i]) - clamped.data[i];
        count += clamped.data[i] != color.data[i];
    }
    if (!(sum > 0) || double(count) < kClampLossMinShare * double(color.Size())) return 0;
    return taken / sum;
}

// Emitters and fireflies: the clamp against the frame's own estimate where it has one (by
// default also beside a variance layer), else against the layer; beside a layer, against
// the layer after all where the estimate's clamp took more than clampLoss of the light.
void RecordClamp(StagedRun &run, NforGpu &gpu, const NforInputs &in, const NforOptions &o,
                 bool ownClamp, NforResult &result) {
    vk::Context &context = run.Context();
    const vk::GpuImage *albedo = gpu.albedo ? &*gpu.albedo : nullptr;
    vk::GpuImage &clampVariance = ownClamp ? gpu.clampVariance : gpu.variance;
    // Without a layer the clamp always reads the frame's own estimate: under --no-edge-noise
    // it is made once, here, and the weights read it too.
    if (ownClamp || !in.variance)
        RecordNforNoise(context, run.Recorder(), gpu.color, albedo, o.noiseRadius,
                        o.noiseCalibration, clampVariance, false, !o.noSparseNoise);
    auto clamp = [&](vk::GpuImage &variance) {
        RecordNforClamp(context, run.Recorder(), gpu.color, variance, albedo,
                        o.fireflyThreshold, o.fireflyRelative, o.emitterAlbedo, o.fireflyRank,
                        o.fireflyLightEdge, !o.fireflyEachChannel, o.fireflyLine,
                        o.fireflyLoneLight, o.fireflyLineFloor, gpu.clamped, gpu.mask);
    };
    // The layer as the clamp reads it: its isolated lone samples' values capped
    // (NforCapLoneSamples), where any are in a buffer of its own submitted before it is
    // freed.
    auto clampLayer = [&]() {
        if (o.noLoneSampleCap) return clamp(gpu.variance);
        Image layer;
        result.loneSamples = NforCapLoneSamples(*in.variance, *in.color, &layer);
        if (result.loneSamples == 0) return clamp(gpu.variance);
        vk::GpuImage capped(context, gpu.variance.width, gpu.variance.height,
                            gpu.variance.channels, "nfor.clampLayer");
        capped.Upload(layer);
        clamp(capped);
        run.Submit();
    };
    if (in.variance && !ownClamp) return clampLayer();
    clamp(clampVariance);
    if (!in.variance) return;
    if (in.clampLoss >= 0) {
        result.clampLoss = in.clampLoss;  // the whole frame's: every tile decides alike
    } else {
        run.Submit();
        result.clampLoss = ClampLoss(*in.color, gpu.clamped.Download());
    }
    result.clampOnLayer = result.clampLoss > o.clampLoss;
    if (result.clampOnLayer) clampLayer();
}

// Rows [y0, y1) of every channel of `image`.
Image Rows(const Image &image, int y0, int y1) {
    Image rows(image.width, y1 - y0, image.channels);
    const size_t offset = size_t(y0) * image.width, count = size_t(y1 - y0) * image.width;
    for (int c = 0; c < image.channels; ++c)
        std::copy_n(image.Plane(c) + offset, count, rows.Plane(c));
    return rows;
}

// The colour clamped against its own noise estimate as RecordClamp clamps it (or, without
// `clamp`, that estimate), run on strips of whole rows with a halo of the clamp's reach (the
// estimate's pairs around the pixel's neighbours), each of at most stripPixels (at least
// one row): every row as a run on the whole frame clamps it.
Image EstimateOnStrips(vk::Context &context, const Image &color, const Image *albedo,
                       const NforOptions &o, int stripPixels, bool clamp) {
    const int w = color.width, h = color.height, ch = color.channels;
    const int floorReach = o.fireflyLineFloor > 0 ? kNforLineFloorReach : 0;
    const int halo = o.noiseRadius + std::max(2, floorReach),
              rows = std::max(1, stripPixels / w);
    Image frame(w, h, ch);
    for (int y0 = 0; y0 < h; y0 += rows) {
        const int y1 = std::min(h, y0 + rows);
        const int wy0 = std::max(0, y0 - halo), wy1 = std::min(h, y1 + halo);
        vk::GpuImage strip(context, w, wy1 - wy0, ch, "nfor.strip.color"),
            variance(context, w, wy1 - wy0, ch, "nfor.strip.variance"),
            out(context, w, wy1 - wy0, ch, "nfor.strip.clamped"),
            mask(context, w, wy1 - wy0, 1, "nfor.strip.mask");
        strip.Upload(Rows(color, wy0, wy1));
        std::optional<vk::GpuImage> divisor;
        if (albedo) {
            divisor.emplace(context, w, wy1 - wy0, 3, "nfor.strip.albedo");
            divisor->Upload(Rows(*albedo, wy0, wy1));
        }
        StagedRun run(context, false);
        const vk::GpuImage *a = divisor ? &*divisor : nullptr;
        RecordNforNoise(context, run.Recorder(), strip, a, o.noiseRadius, o.noiseCalibration,
                        variance, false, !o.noSparseNoise);
        if (clamp)
            RecordNforClamp(context, run.Recorder(), strip, variance, a, o.fireflyThreshold,
                            o.fireflyRelative, o.emitterAlbedo, o.fireflyRank,
                            o.fireflyLightEdge, !o.fireflyEachChannel, o.fireflyLine,
                            o.fireflyLoneLight, o.fireflyLineFloor, out, mask);
        run.Submit();
        Image part = clamp ? out.Download() : variance.Download();
        const size_t skip = size_t(y0 - wy0) * w, count = size_t(y1 - y0) * w;
        for (int c = 0; c < ch; ++c)
            std::copy_n(part.Plane(c) + skip, count, frame.Plane(c) + size_t(y0) * w);
    }
    return frame;
}

// Prefiltered features kept for later runs on the same features (RunSetup::memo).
struct NforFeaturesMemo {
    vk::Buffer filtered;
};

// The memo's key of the prefiltered features: the features and every option the noise
// estimate and the prefilter read.
std::string FeaturesKey(const std::string &featuresId, const NforOptions &o) {
    return fmt::format("nfor.filtered {} noise {} {:a} prefilter {} {} {:a}", featuresId,
                       o.noiseRadius, o.noiseCalibration, o.prefilterRadius, o.prefilterPatch,
                       o.prefilterBandwidth);
}

// The features prefiltered by NL-means with their own noise estimated (they depend on the
// feature layers alone), or with a memo those an earlier run on the same features made.
void RecordFeatures(StagedRun &run, NforGpu &gpu, const NforOptions &o, RunMemo *memo,
                    const std::string &featuresId) {
    vk::Context &context = run.Context();
    const size_t bytes = gpu.filtered.buffer.Bytes();
    if (o.prefilterRadius <= 0) {
        run.Recorder().Copy(gpu.features.buffer, gpu.filtered.buffer, bytes);
        return;
    }
    const std::string key = memo ? FeaturesKey(featuresId, o) : std::string();
    if (NforFeaturesMemo *kept = memo ? memo->Find<NforFeaturesMemo>(key) : nullptr) {
        run.Recorder().Copy(kept->filtered, gpu.filtered.buffer, bytes);
        return;
    }
    // The features' own noise, for this filter only (submitted before it is freed).
    vk::GpuImage featureVariance(context, gpu.features.width, gpu.features.height,
                                 gpu.features.channels, "nfor.featureVariance");
    RecordNforNoise(context, run.Recorder(), gpu.features, nullptr, o.noiseRadius,
                    o.noiseCalibration, featureVariance);
    RecordNforPrefilter(context, run.Recorder(), gpu.features, featureVariance,
                        o.prefilterRadius, o.prefilterPatch, o.prefilterBandwidth,
                        gpu.filtered);
    std::shared_ptr<NforFeaturesMemo> entry;
    if (memo) {
        entry = std::make_shared<NforFeaturesMemo>();
        entry->filtered = vk::Buffer(context, bytes, "nfor.filtered.memo");
        run.Recorder().Copy(gpu.filtered.buffer, entry->filtered, bytes);
    }
    run.Submit();
    // Keep the entry only once the GPU has written it: a run that throws leaves none.
    if (memo) memo->Add(key, std::move(entry));
}

// Whether the firefly clamp reads the frame's own estimate of the colour's noise
// (gpu.clampVariance, the one NforCoarseLevel reads).
bool OwnClampEstimate(const NforInputs &in, const NforOptions &o) {
    return (!in.variance && !o.noEdgeNoise) || (in.variance && !o.clampLayer);
}

// Whether the passes of a frame without a variance layer run (the specks, the clamp's
// light, the kept pixels' mean, the lights' spread): without a layer, or beside one where
// the clamp read the frame's own estimate (NforOptions::noLayerPasses).
bool PlainPasses(const NforInputs &in, const NforOptions &o, const NforResult &result) {
    return !in.variance || (!o.noLayerPasses && !o.clampLayer && !result.clampOnLayer);
}

// `variance` capped at `cap` times `estimate`, value by value.
Image CapNoise(Image variance, const Image &estimate, float cap) {
    for (size_t i = 0; i < variance.data.size(); ++i)
        variance.data[i] = std::min(variance.data[i], cap * estimate.data[i]);
    return variance;
}

// Beside a variance layer: the layer (gpu.variance) capped at o.layerNoiseCap times the
// frame's own estimate of the clamped colour's noise, made as without a layer, and the
// second pass's noise (gpu.pilotVariance) at o.pilotNoiseCap times it.
void CapLayerNoise(StagedRun &run, NforGpu &gpu, const NforInputs &in, const NforOptions &o,
                   const Image *alpha) {
    vk::GpuImage estimate(run.Context(), gpu.variance.width, gpu.variance.height,
                          gpu.variance.channels, "nfor.capVariance");
    RecordNforNoise(run.Context(), run.Recorder(), gpu.clamped,
                    gpu.albedo ? &*gpu.albedo : nullptr, o.noiseRadius, o.noiseCalibration,
                    estimate, true, !o.noSparseNoise);
    run.Submit();
    Image own = estimate.Download();
    if (alpha) own = NforDivideByAlpha(own, *alpha);
    Image capped =
        o.layerNoiseCap > 0 ? CapNoise(*in.variance, own, o.layerNoiseCap) : *in.variance;
    if (o.layerNoiseCap > 0) gpu.variance.Upload(capped);
    if (gpu.pilotVariance) gpu.pilotVariance->Upload(CapNoise(capped, own, o.pilotNoiseCap));
}

// Where the colour distance trusts the albedo (albedoNoise > 0), from the clamped colour.
void RecordTrust(StagedRun &run, NforGpu &gpu, const NforOptions &o) {
    if (!gpu.trust) return;
    RecordNforTrust(run.Context(), run.Recorder(), gpu.clamped, *gpu.albedo, o.albedoNoise,
                    *gpu.trust);
    run.StageAtEnd("trust", *gpu.trust);
}

// Near a glint, where the albedo is noise: the weights' noise at least o.glintNoise times the
// clamped colour's 3x3 variance (a frame without a variance layer; NforOptions::glintNoise).
void RecordGlintNoise(StagedRun &run, NforGpu &gpu, const NforOptions &o) {
    if (!gpu.glint) return;
    RecordNforGlintNoise(run.Context(), run.Recorder(), gpu.clamped, *gpu.albedo, *gpu.trust,
                         kNforGlintAlbedo, kNforGlintReach, o.glintNoise, *gpu.glintNear,
                         gpu.variance, *gpu.glint);
    run.StageAtEnd("glint", *gpu.glint);
    run.StageAtEnd("glint.variance", gpu.variance);
}

// The firefly clamp, against the clamp's own estimate of the colour's noise where it reads
// one (OwnClampEstimate), and its stages.
void RecordClampStages(StagedRun &run, NforGpu &gpu, const NforInputs &in, const NforOptions &o,
                       NforResult &result) {
    const bool ownClamp = OwnClampEstimate(in, o);
    RecordClamp(run, gpu, in, o, ownClamp, result);
    run.StageAtEnd("mask", gpu.mask);
    run.StageAtEnd("color", gpu.clamped);
    if (ownClamp) run.StageAtEnd("clamp.variance", gpu.clampVariance);
}

// After the clamp (RecordClampStages): the weights' noise estimate, the features, the trust,
// the glint floor and the patch distances. `alpha`: the coverage of a frame whose partly
// covered pixels were divided by it (nullptr: none).
void RecordPrepare(StagedRun &run, NforGpu &gpu, const NforInputs &in, const NforOptions &o,
                   RunMemo *memo, const std::string &featuresId, const Image *alpha,
                   NforResult &result) {
    vk::Context &context = run.Context();
    const vk::GpuImage *albedo = gpu.albedo ? &*gpu.albedo : nullptr;
    // With edge noise the weights' estimate is made again, from the clamped colour.
    if (!in.variance && !o.noEdgeNoise)
        RecordNforNoise(context, run.Recorder(), gpu.clamped, albedo, o.noiseRadius,
                        o.noiseCalibration, gpu.variance, true, !o.noSparseNoise);
    if (!in.variance && alpha) {
        // A partly covered pixel divided by its alpha is the mean of a N of its N samples:
        // 1 / a times the variance of the covered pixels whose pairs its estimate read (the
        // weights' estimate; under --no-edge-noise the one the clamp read before).
        run.Submit();
        gpu.variance.Upload(NforDivideByAlpha(gpu.variance.Download(), *alpha));
    }
    if (in.variance && (o.layerNoiseCap > 0 || gpu.pilotVariance))
        CapLayerNoise(run, gpu, in, o, alpha);
    // The glint floor rewrites the variance below: its stage is read before.
    if (gpu.glint)
        run.Stage("variance", gpu.variance);
    else
        run.StageAtEnd("variance", gpu.variance);
    RecordFeatures(run, gpu, o, memo, featuresId);
    run.StageAtEnd("features", gpu.filtered);
    RecordTrust(run, gpu, o);
    RecordGlintNoise(run, gpu, o);
    // Computed with a given pilot too: the CPU twin's "distance" stage stays aligned.
    RecordNforDistance(context, run.Recorder(), gpu.clamped, gpu.variance,
                       o.noDemodulatedDistance ? nullptr : albedo, o.radius, o.patchRadius,
                       o.alpha, o.minVariance, gpu.illumination, gpu.scratch, gpu.distance,
                       gpu.trust ? &*gpu.trust : nullptr);
    run.StageAtEnd("distance", gpu.distance);
}

int GatherRadius(const NforOptions &o) {
    return o.gatherRadius < 0 ? o.radius : std::min(o.gatherRadius, o.radius);
}

// A candidate of a pass: its window half-size and bandwidth, and the distances over its
// windows.
struct PassCandidate {
    int radius;
    float bandwidth;
    const vk::GpuImage *distance;
};

// One pass: per candidate the fits weighted by its distance and their collaborative
// average, then per pixel the one of smallest SURE; stages named `prefix` + k<i>.beta,
// .hat, .output and choice.
void RecordPass(StagedRun &run, NforGpu &gpu, const std::vector<float> &weights,
                const NforOptions &o, const std::vector<PassCandidate> &candidates,
                const std::string &prefix, vk::GpuImage &out, vk::GpuImage &choice,
                float agreement = 0) {
    vk::Context &context = run.Context();
    int ch = gpu.color.channels, count = int(candidates.size());
    auto settingsOf = [&](int i) {
        const PassCandidate &k = candidates[i];
        return NforFitSettings{k.radius, std::min(GatherRadius(o), k.radius), k.bandwidth,
                               o.ridge, weights};
    };
    // Candidate i's collaborative average from its coefficients, and its stages.
    auto gather = [&](int i, const vk::GpuImage &beta) {
        run.Stage(fmt::format("{}k{}.beta", prefix, i),
                  [&] { return NforBetaPlanes(beta.Download(), gpu.filtered.channels, ch); });
        RecordNforGather(context, run.Recorder(), gpu.clamped, gpu.packed,
                         gpu.filtered.channels, *candidates[i].distance, beta, settingsOf(i),
                         gpu.candidates, i * ch);
        // One submission per candidate: its gather, after the regress dispatch that fitted it
        // (a pair's both, in the first's); none long enough to trip a GPU watchdog.
        run.Submit();
        run.Stage(fmt::format("{}k{}.hat", prefix, i),
                  [&, i] { return PlanesOf(gpu.hat.Download(), i, 1); });
        run.Stage(fmt::format("{}k{}.output", prefix, i),
                  [&, i] { return PlanesOf(gpu.candidates.Download(), i * ch, ch); });
    };
    for (int i = 0; i < count; ++i) {
        NforFitSettings settings = settingsOf(i);
        // The next candidate over the same distances and window is fitted in the same pass:
        // the window's reads and weights' features are shared.
        bool pair = i + 1 < count && gpu.secondBeta &&
                    candidates[i + 1].distance == candidates[i].distance &&
                    NforSameWindow(settings, settingsOf(i + 1));
        NforFitSettings next = pair ? settingsOf(i + 1) : settings;
        RecordNforRegress(context, run.Recorder(), gpu.packed, gpu.filtered.channels, ch,
                          *candidates[i].distance, settings, gpu.beta, gpu.hat, i,
                          pair ? &next : nullptr, pair ? &*gpu.secondBeta : nullptr);
        gather(i, gpu.beta);
        if (pair) gather(++i, *gpu.secondBeta);
    }
    if (count > 1) {
        RecordNforSelect(context, run.Recorder(), gpu.clamped, gpu.variance, gpu.candidates,
                         gpu.hat, count, o.sureRadius, out, choice, agreement);
        run.Stage(prefix + "choice", choice);
    } else {
        run.Recorder().Copy(gpu.candidates.buffer, out.buffer, out.buffer.Bytes());
    }
}

// Both passes: the first weighted by the colour's distance; with pilot bandwidths a second
// weighted by the distance of the first's output (the pilot) against the colour's variance.
void RecordPasses(StagedRun &run, NforGpu &gpu, const std::vector<float> &weights,
                  const NforOptions &o, bool givenPilot, vk::GpuImage &out,
                  vk::GpuImage &choice) {
    RecordNforPack(run.Context(), run.Recorder(), gpu.clamped, gpu.filtered, gpu.mask,
                   gpu.packed);
    std::vector<PassCandidate> first;
    for (float k : o.bandwidths) first.push_back({o.radius, k, &gpu.distance});
    if (!gpu.pilot) {
        RecordPass(run, gpu, weights, o, first, "", out, choice);
        return;
    }
    // A pilot given from outside replaces the first pass.
    if (!givenPilot) RecordPass(run, gpu, weights, o, first, "", *gpu.pilot, choice);
    run.Stage("pilot", *gpu.pilot);
    bool pilotMin = NforPilotMinVariance(o);
    // The pilot's distance trusts the albedo where the first's did (of the clamped colour).
    const vk::GpuImage *albedo =
        gpu.albedo && !o.noDemodulatedDistance ? &*gpu.albedo : nullptr;
    // Beside a layer with --pilot-noise-cap, the second pass's distances read it capped.
    vk::GpuImage &variance = gpu.pilotVariance ? *gpu.pilotVariance : gpu.variance;
    if (gpu.pilotVariance) run.Stage("pilot.variance", *gpu.pilotVariance);
    RecordNforDistance(run.Context(), run.Recorder(), *gpu.pilot, variance, albedo, o.radius,
                       o.patchRadius, o.pilotAlpha, pilotMin, gpu.illumination, gpu.scratch,
                       *gpu.pilotDistance, gpu.trust ? &*gpu.trust : nullptr);
    run.Stage("pilot.distance", *gpu.pilotDistance);
    std::vector<PassCandidate> second;
    for (float k : o.pilotBandwidths) second.push_back({o.radius, k, &*gpu.pilotDistance});
    if (gpu.wideDistance) {
        // The pilot distance's illumination: the same pilot, variance, albedo and trust.
        RecordNforDistanceOfIllumination(run.Context(), run.Recorder(), gpu.illumination,
                                         gpu.pilot->channels, o.pilotWideRadius, o.patchRadius,
                                         o.pilotAlpha, pilotMin, *gpu.wideScratch,
                                         *gpu.wideDistance);
        run.Stage("pilot.wide.distance", *gpu.wideDistance);
        for (float k : o.pilotBandwidths)
            second.push_back({o.pilotWideRadius, k, &*gpu.wideDistance});
    }
    float agreement = gpu.wideDistance && o.pilotBandwidths.size() == 1 ? o.wideAgreement : 0;
    RecordPass(run, gpu, weights, o, second, "pilot.", out, choice, agreement);
}

// Which noise the firefly clamp read beside a variance layer, and why.
void PlanClamp(StagedRun &run, const NforInputs &in, const NforOptions &o,
               const NforResult &result) {
    const std::string frame =
        in.clampLoss >= 0 ? " (measured over the whole frame before its tiles, so every "
                            "tile reads the same)"
                          : "";
    const bool onLayer = o.clampLayer || result.clampOnLayer;
    if (onLayer && !o.noLoneSampleCap)
        run.Plan(fmt::format(
            "lone samples: {} pixels whose layer says about one sample holds their mean, "
            "above {}x their neighbours' median and with no other such pixel within {}, read "
            "their neighbours' median variance in the clamp (a firefly on a quiet ground; a "
            "caustic's samples come in numbers) (--no-lone-sample-cap: off)",
            result.loneSamples, kNforLoneRatio, kNforLoneReach));
    if (o.clampLayer)
        run.Plan("the firefly clamp reads the variance layer (--clamp-layer)");
    else if (result.clampOnLayer)
        run.Plan(fmt::format(
            "the firefly clamp against the frame's own estimate took off {:.1f}% of the "
            "light, above {:.1f}% (--clamp-loss): the light is in rare bright samples, not in "
            "fireflies, so it reads the variance layer{}",
            100 * result.clampLoss, 100 * o.clampLoss, frame));
    else {
        run.Plan(fmt::format(
            "the firefly clamp reads the frame's own estimate, not the variance layer (a "
            "firefly's few samples report its own variance there): it took off {:.2f}% of "
            "the light (at most {:.1f}%, --clamp-loss){}",
            100 * result.clampLoss, 100 * o.clampLoss, frame));
        if (!o.noLayerPasses)
            run.Plan(
                "so the specks' clamp, the clamp's light, the weak emitters' mean and the "
                "lights' spread run as without a layer (--no-layer-passes: off)");
    }
}

// What the colour distance compared (after the run's submit: it reads the trust back).
void PlanDistance(StagedRun &run, NforGpu &gpu, const NforOptions &o) {
    if (!gpu.albedo || o.noDemodulatedDistance) {
        run.Plan(gpu.albedo ? "the colour distance compares the colour itself "
                              "(--no-demodulated-distance)"
                            : "the colour distance compares the colour itself (no albedo)");
        return;
    }
    if (!gpu.trust) {
        run.Plan("the colour distance compares colour / albedo (--albedo-noise 0)");
        return;
    }
    const Image trust = gpu.trust->Download();
    size_t untrusted = 0;
    for (float t : trust.data) untrusted += t == 0;
    run.Plan(fmt::format(
        "the colour distance compares colour / albedo where both pixels' albedos are trusted, "
        "the colours themselves where either is not: {} pixels ({:.1f}%) whose albedo is "
        "noise (its relative variance over 3x3 above {}, --albedo-noise, and dividing by it "
        "roughens the colour)",
        untrusted, 100.0 * double(untrusted) / double(trust.PixelCount()), o.albedoNoise));
}

// Where the glint floor raised the weights' noise (`floored`: its mask, read back after the
// run's submit).
void PlanGlintNoise(StagedRun &run, const Image &floored, const NforOptions &o) {
    size_t count = 0;
    for (float f : floored.data) count += f > 0;
    run.Plan(fmt::format(
        "glint floor: the weights' noise raised to {} x the clamped colour's 3x3 variance at "
        "{} pixels whose albedo is noise within {} of a glint (an albedo above {}; "
        "--glint-noise)",
        o.glintNoise, count, kNforGlintReach, kNforGlintAlbedo));
}

// The kept pixels' and weak emitters' pass over radius keptPass, its stage and plan line.
void SmoothKept(StagedRun &run, const NforInputs &in, const NforOptions &o, NforGpu &gpu,
                const std::vector<float> &weights, const Image &mask, int keptPass,
                NforResult &result) {
    run.AddStage("unkept", result.image);
    NforKeptSettings kept{keptPass, o.weakEmitterAlbedo, in.albedo, in.albedo ? 3 : 0,
                          o.keptRadius > 0};
    kept.lineRatio = o.weakEmitterLine;
    kept.lineRange = o.weakEmitterRange;
    result.kept =
        NforSmoothKept(*in.color, gpu.filtered.Download(), weights, mask, kept, &result.image);
    std::string what = o.keptRadius > 0 ? "kept pixels (the fits left them as they came "
                                          "in: no neighbour weighed)"
                                        : "";
    if (o.weakEmitterAlbedo > 0)
        what += fmt::format(
            "{}emitters of albedo below {} (a light's partly covered edge; "
            "their albedo not compared{})",
            what.empty() ? "" : " and ", o.weakEmitterAlbedo,
            o.weakEmitterLine > 0
                ? fmt::format("; one on a bright line, a pixel at least {} x as bright on "
                              "both sides within 2 steps, weighs them by their brightness too, "
                              "a Gaussian of {} in the log",
                              o.weakEmitterLine, o.weakEmitterRange)
                : "");
    run.Plan(
        fmt::format("{}: {}, each given the output's mean over {}x{} weighted by the "
                    "features",
                    what, result.kept, 2 * keptPass + 1, 2 * keptPass + 1));
}

// The glint floor's guard on the output, its stage and its plan line.
void GuardGlint(StagedRun &run, const Image &clamped, const Image &floored,
                NforResult &result) {
    const size_t guarded = GuardGlintFloor(clamped, floored, &result.image);
    run.AddStage("glint.guard", result.image);
    run.Plan(fmt::format(
        "glint guard: {} pixel-channels within {} of a raised pixel lifted to the clamped "
        "colour's 3x3 minimum",
        guarded, kNforGlintGuardReach));
}

// The bandwidths of each pass and the shares of the last pass's choice.
void PlanPasses(StagedRun &run, const NforOptions &o, bool givenPilot,
                const vk::GpuImage &choice, NforResult &result) {
    auto list = [](const std::vector<float> &ks) {
        std::string text;
        for (float k : ks) text += fmt::format("{}{}", text.empty() ? "" : ", ", k);
        return text;
    };
    // A given pilot replaces the first pass: its bandwidths are not used.
    givenPilot = givenPilot && !o.pilotBandwidths.empty();
    run.Plan(fmt::format(
        "regression over {}x{} windows, colour patches {}x{} (alpha {}), "
        "ridge {}; {}each window's fit averaged at every pixel it holds",
        2 * o.radius + 1, 2 * o.radius + 1, 2 * o.patchRadius + 1, 2 * o.patchRadius + 1,
        o.alpha, o.ridge,
        givenPilot ? std::string() : fmt::format("bandwidths k = {}; ", list(o.bandwidths))));
    if (!o.pilotBandwidths.empty())
        run.Plan(
            fmt::format("second pass: the colour distance of {} over the colour's "
                        "variance (alpha {}), bandwidths k = {}{}",
                        givenPilot ? "the pilot" : "the first pass's output (the pilot)",
                        o.pilotAlpha, list(o.pilotBandwidths),
                        givenPilot ? "; the pilot read from a layer of the frame, the first "
                                     "pass did not run"
                                   : ""));
    // The last pass's candidates, named by bandwidth (and window where two sizes run).
    std::vector<std::string> last;
    for (float k : o.pilotBandwidths.empty() ? o.bandwidths : o.pilotBandwidths)
        last.push_back(fmt::format("k = {}", k));
    if (o.pilotWideRadius > 0) {
        run.Plan(fmt::format("second pass also over {}x{} windows, the same bandwidths",
                             2 * o.pilotWideRadius + 1, 2 * o.pilotWideRadius + 1));
        for (size_t i = 0, n = last.size(); i < n; ++i) {
            last.push_back(fmt::format("{} over {}x{}", last[i], 2 * o.pilotWideRadius + 1,
                                       2 * o.pilotWideRadius + 1));
            last[i] += fmt::format(" over {}x{}", 2 * o.radius + 1, 2 * o.radius + 1);
        }
    }
    if (last.size() < 2) return;
    Image picked = choice.Download();
    result.share.assign(last.size(), 0.0);
    for (float c : picked.data) result.share[size_t(c)] += 1.0 / double(picked.Size());
    std::string shares;
    for (size_t i = 0; i < result.share.size(); ++i)
        shares += fmt::format("{}{}: {:.1f}%", i ? ", " : "", last[i], 100 * result.share[i]);
    run.Plan(fmt::format("per pixel the candidate of smallest SURE over {}x{} ({}{})",
                         2 * o.sureRadius + 1, 2 * o.sureRadius + 1,
                         o.pilotBandwidths.empty() ? "" : "second pass: ", shares));
}

// The values the fits leave by design: every channel of an emitter (mask 0), whose
// gather copies the clamped colour. A fit that weighs little but its own pixel gives it
// back only to within rounding, so kept-ness is not read from the output's equality.
std::vector<bool> FitsLeft(const Image &mask, int channels) {
    const size_t n = mask.PixelCount();
    std::vector<bool> left(n * channels, false);
    for (size_t p = 0; p < n; ++p)
        if (mask.data[p] == 0)
            for (int c = 0; c < channels; ++c) left[c * n + p] = true;
    return left;
}

// The pixels on an exact ground (NforExactGround) given their input back in the fits'
// output, the plan told; their flags.
std::vector<char> KeepExactGround(StagedRun &run, const NforInputs &in, const Image &mask,
                                  const Image &clamped, NforResult &result) {
    std::vector<char> exact = NforExactGround(*in.color, clamped, mask);
    const size_t n = exact.size();
    for (size_t p = 0; p < n; ++p) {
        if (!exact[p]) continue;
        ++result.exactGround;
        for (int c = 0; c < clamped.channels; ++c)
            result.image.Plane(c)[p] = clamped.Plane(c)[p];
    }
    if (result.exactGround > 0)
        run.Plan(fmt::format(
            "exact ground: {} pixels unlike their 8 neighbours, whose colours are the same bit "
            "for bit and lit (every sample there saw the same: a mirror's or a sky's "
            "constant), keep their input (a light under a pixel, not noise) and stay out of "
            "the local means (--no-exact-ground: fitted)",
            result.exactGround));
    return exact;
}

// The fits' output (result.image) with its specks clamped on a frame without a variance
// layer, then the clamped colour's local means restored; `meansLeft` receives the values the
// restore left (FitsLeft's and the highlights it gave their input back).
void RestoreMeans(StagedRun &run, const NforInputs &in, const NforOptions &o, const Image &mask,
                  const Image &clamped, NforResult &result, std::vector<bool> *meansLeft) {
    run.AddStage("fit", result.image);
    std::vector<char> exact;
    if (o.speckRelative >= 0 && PlainPasses(in, o, result)) {
        result.specks = NforClampSpecks(
            mask,
            {o.speckRelative, o.speckFloor, o.speckRank, o.speckFlatShare, o.speckFlatRelative},
            &result.image);
        if (!o.noExactGround) exact = KeepExactGround(run, in, mask, clamped, result);
        run.AddStage("specks", result.image);
        run.Plan(fmt::format(
            "specks: {} pixels of the fits' output above (1 + {}) x the luminance of their "
            "neighbour ranked {} by brightness + {}{} scaled down to that, before the local "
            "means give the pixels around them what of their light they hold for certain",
            result.specks, o.speckRelative, o.speckRank, o.speckFloor,
            o.speckFlatShare > 0
                ? fmt::format(" ((1 + {}) x where the neighbours' median is at least {} x "
                              "that neighbour's: a flat ground)",
                              o.speckFlatRelative, o.speckFlatShare)
                : std::string()));
    }
    *meansLeft = FitsLeft(mask, clamped.channels);
    for (size_t p = 0; p < exact.size(); ++p)
        if (exact[p])
            for (int c = 0; c < clamped.channels; ++c)
                (*meansLeft)[c * exact.size() + p] = true;
    LocalMeanFactors f =
        RestoreLocalMeans(clamped, o.meanRadius, &result.image, nullptr, -1, false, meansLeft);
    run.Plan(
        fmt::format("local mean: the clamped colour's means over tents of radius {}, "
                    "then {} restored (factors {:.3g} to {:.3g})",
                    8 * o.meanRadius, 2 * o.meanRadius, f.lo, f.hi));
}

// Whether each pixel lies within `reach` of an emitter or of a partly covered pixel (their
// own light is the lights' spread's and the kept pixels' to place). An empty pixel (alpha 0)
// is no partly covered one: a hard edge blocks nothing, so that a tile holding no partly
// covered pixel (run without the alpha) blocks what the whole frame's run does.
std::vector<char> ClampLightNear(const Image &mask, const Image *alpha, int reach) {
    const int w = mask.width, h = mask.height;
    std::vector<char> blocked(size_t(w) * h), rows(size_t(w) * h), near(size_t(w) * h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            blocked[size_t(y) * w + x] =
                mask.At(0, y, x) == 0 || (alpha && NforPartlyCovered(alpha->At(0, y, x)));
    // A square of radius reach around each blocked pixel: along rows, then columns.
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            char any = 0;
            for (int u = std::max(0, x - reach); u <= std::min(w - 1, x + reach) && !any; ++u)
                any = blocked[size_t(y) * w + u];
            rows[size_t(y) * w + x] = any;
        }
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            char any = 0;
            for (int v = std::max(0, y - reach); v <= std::min(h - 1, y + reach) && !any; ++v)
                any = rows[size_t(v) * w + x];
            near[size_t(y) * w + x] = any;
        }
    return near;
}

// The colour whose local means give the clamp's light back: the clamped colour where
// ClampLightNear flags the pixel, the colour elsewhere.
Image ClampLightSource(const Image &color, const Image &clamped,
                       const std::vector<char> &near) {
    Image source = clamped;
    for (size_t i = 0; i < color.PixelCount(); ++i) {
        if (near[i]) continue;
        for (int c = 0; c < color.channels; ++c) source.Plane(c)[i] = color.Plane(c)[i];
    }
    return source;
}

// After the clamp's light: a share of the light the clamp took from the pixels it cut far
// down (rare bright samples: a glossy floor's reflection of a light, hit by few samples)
// given to the pixels around them (host/methods/nfor_rare.h).
void SpreadRareLight(StagedRun &run, const NforInputs &in, const NforOptions &o,
                     const Image &clamped, const std::vector<char> &near, NforResult &result) {
    NforRareLightSettings s;
    s.share = o.rareLightShare;
    s.ratio = o.rareLightRatio;
    s.pair = o.rareLightPair;
    s.others = o.rareLightOthers;
    const size_t sources = NforSpreadRareLight(*in.color, clamped, near, s, &result.image);
    run.AddStage("rare", result.image);
    run.Plan(fmt::format(
        "rare light: {} pixels the firefly clamp cut to under 1/{} of their colour, each "
        "with {} more such within {} (away from emitters and partly covered pixels), gave "
        "{} of the light it took to the pixels around them, a Gaussian of {} pixels",
        sources, s.ratio, s.others, s.pair, s.share, s.sigma));
}

// After the local means, the colour's own (the clamp's light back) over the tents of
// o.clampLightRadius, then o.clampLightFine: the clamp takes a glint's light from the few
// pixels its samples hit, and where many such are near (a wire mesh's glints, a ring's
// highlight) that light is the frame's; each value's own difference as its noise leaves a
// lone firefly's light out.
// `meansLeft`: the values the local means' restore left as the clamped colour has them; those
// whose source value is that too stay here.
void RestoreClampLight(StagedRun &run, const NforInputs &in, const NforOptions &o,
                       const Image &mask, const Image &clamped, const Image *alpha,
                       const std::vector<bool> &meansLeft, NforResult &result) {
    const std::vector<char> near = ClampLightNear(mask, alpha, o.clampLightReach);
    Image source = ClampLightSource(*in.color, clamped, near);
    // Both are inputs: the colour where the clamp left it, or the clamped colour copied.
    std::vector<bool> left(meansLeft.size());
    for (size_t i = 0; i < left.size(); ++i)
        left[i] = meansLeft[i] && source.data[i] == clamped.data[i];
    LocalMeanFactors f =
        RestoreLocalMeanAt(source, o.clampLightRadius, kClampLightNoise, &result.image, &left);
    if (o.clampLightFine > 0) {
        LocalMeanFactors g = RestoreLocalMeanAt(source, o.clampLightFine, kClampLightNoise,
                                                &result.image, &left);
        f.lo = std::min(f.lo, g.lo);
        f.hi = std::max(f.hi, g.hi);
    }
    run.AddStage("clamp.light", result.image);
    run.Plan(fmt::format(
        "the clamp's light: the colour's own means over tents of radius {}{} restored, each "
        "value's difference its noise x {}, the clamped colour kept within {} of an emitter "
        "or a partly covered pixel{} (factors {:.3g} to {:.3g})",
        2 * o.clampLightRadius,
        o.clampLightFine > 0 ? fmt::format(", then {}", 2 * o.clampLightFine) : "",
        kClampLightNoise, o.clampLightReach,
        o.premultiplied ? " (no alpha read: --premultiplied)" : "", f.lo, f.hi));
    if (o.rareLightShare > 0) SpreadRareLight(run, in, o, clamped, near, result);
}

// Last, where the lights spread: a light's rim pixels hit by few samples brought down to
// their ground, their light moved into the light's core.
void FoldRimHits(StagedRun &run, const Image &color, const Image &albedo, const Image *alpha,
                 const NforOptions &o, NforResult &result) {
    NforRimSettings s;
    s.emitterAlbedo = o.emitterAlbedo;
    s.coreRatio = o.rimRatio;
    const size_t folded = NforFoldRimHits(color, albedo, alpha, s, &result.image);
    if (folded == 0) return;
    run.AddStage("rim", result.image);
    run.Plan(fmt::format(
        "rim hits: {} emitter pixels of albedo at most 1/{:g} of an emitter's within {} (a "
        "light's rim that at most {} of the {:g} samples hit, reading the light times their "
        "share) brought down to the geometric mean of their input and their ground's (the "
        "median of their neighbours that are no emitter), the light they lost given to that "
        "light's core",
        folded, s.coreRatio, s.radius, o.rimHits, s.coreRatio * float(o.rimHits)));
}

// Last, near glints: each pixel towards the output's mean along its line, a highlight's band
// the fits left broken (host/methods/nfor_band.h).
void SmoothGlintBands(StagedRun &run, const Image &albedo, const Image *alpha,
                      const NforOptions &o, NforResult &result) {
    NforGlintBandSettings s;
    s.radius = o.glintBandRadius;
    s.glintAlbedo = kNforGlintAlbedo;
    s.reach = kNforGlintReach;
    s.emitterAlbedo = o.emitterAlbedo;
    const size_t moved = NforSmoothGlintBands(albedo, alpha, s, &result.image);
    if (moved == 0) return;
    run.AddStage("glint.band", result.image);
    run.Plan(fmt::format(
        "glint bands: {} pixels within {} of a glint (an albedo channel above {}) moved "
        "towards the output's mean along their line ({} samples each side, a Gaussian of {}; "
        "the structure tensor's of {}), by its coherence, emitters left out",
        moved, s.reach, s.glintAlbedo, s.radius, s.sigma, s.tensorSigma));
}

// Each emitter's share of its output given to its neighbours that are no emitter.
void SpreadLights(StagedRun &run, const NforInputs &in, const NforOptions &o,
                  const Image *alpha, NforResult &result) {
    NforLightSettings s{o.emitterAlbedo, o.weakEmitterAlbedo, o.weakLightShare, o.lightShare};
    result.lights = NforSpreadLights(*in.albedo, alpha, s, &result.image);
    run.AddStage("lights", result.image);
    run.Plan(fmt::format(
        "lights: {} emitter pixels gave {} (albedo below {}) or {} of their output to each of "
        "their 4 neighbours that is no emitter (a light's rim, which few of the samples hit)",
        result.lights, o.weakLightShare, o.weakEmitterAlbedo, o.lightShare));
}

// The clamp's light of a line near a light shared along it, last, on the output, the colour
// and the clamped colour as written.
void SpreadLine(StagedRun &run, const Image &color, const Image &clamped, const Image &albedo,
                const Image *alpha, const NforOptions &o, NforResult &result) {
    NforLineSettings s;
    s.lightAlbedo = o.lineSpread;
    const NforLineStats stats = NforSpreadLine(color, clamped, albedo, alpha, s, &result.image);
    result.lineGivers = stats.givers;
    result.lineMoved = stats.moved, result.lineDropped = stats.dropped;
    run.AddStage("line", result.image);
    run.Plan(fmt::format(
        "line spread: {} pixels within {} of a light (albedo above {}) on a line (the clamped "
        "luminance along it above {}x across) gave the light the firefly clamp took, {:.4g} "
        "(luminance summed), shared over {} steps along the line; the cap (a pixel given at "
        "most up to the input's light along its line) dropped {:.4g} of it",
        stats.givers, s.gateReach, o.lineSpread, s.ratio, stats.moved, s.radius,
        stats.dropped));
}

std::string GpuTimes(const std::vector<vk::DispatchTiming> &timings) {
    std::vector<std::pair<std::string, double>> perKernel;
    double total = 0;
    for (const vk::DispatchTiming &t : timings) {
        auto it = std::find_if(perKernel.begin(), perKernel.end(),
                               [&](const auto &p) { return p.first == t.label; });
        if (it == perKernel.end())
            perKernel.push_back({t.label, t.gpuMs});
        else
            it->second += t.gpuMs;
        total += t.gpuMs;
    }
    std::string text = fmt::format("GPU time: {:.1f} ms (", total);
    for (size_t i = 0; i < perKernel.size(); ++i)
        text +=
            fmt::format("{}{} {:.1f}", i ? ", " : "", perKernel[i].first, perKernel[i].second);
    return text + ")";
}

}  // namespace

namespace {

// The frame at half the resolution (NforHalf of every layer; depth and pivot divided by the
// whole frame's means), denoised with the same options but no coarse pass of its own.
Image CoarseOutput(vk::Context &context, const NforInputs &in, const NforOptions &o) {
    auto half = [](const Image *image, bool ofMean = false) {
        return image ? std::optional<Image>(NforHalf(*image, ofMean)) : std::nullopt;
    };
    std::optional<Image> color = half(in.color), albedo = half(in.albedo),
                         normal = half(in.normal), depth = half(in.depth),
                         pivot = half(in.pivot), variance = half(in.variance, true),
                         pilot = half(in.pilot);
    auto pointer = [](std::optional<Image> &image) { return image ? &*image : nullptr; };
    NforInputs coarse{pointer(color),
                      pointer(albedo),
                      pointer(normal),
                      pointer(depth),
                      pointer(pivot),
                      pointer(variance),
                      in.depthScale > 0 ? in.depthScale : NforDepthScale(in.depth),
                      in.pivotScale > 0 ? in.pivotScale : NforPivotScale(in.pivot)};
    coarse.clampLoss = in.coarseClampLoss;
    coarse.pilot = pointer(pilot);
    NforOptions options = o;
    options.coarse = false;
    options.coarseGate = 0;
    // The lights are spread once, over the whole resolution's output.
    options.weakLightShare = options.lightShare = 0;
    options.clampLightRadius = 0;
    options.keepStages = false;
    return NforDenoise(context, coarse, options).image;
}

// What the coarse pass's gate read, for the plan.
std::string PlanCoarseGate(const NforInputs &in, const NforOptions &o, double level) {
    if (o.coarse) return " (--nfor-coarse: on every frame)";
    return fmt::format(
        " (the frame's noise as relMSE weighs it, the median over the pixels of its own "
        "estimate / (colour^2 + 0.01), is {:.4f}{}, {} --coarse-gate {})",
        level, in.coarseLevel >= 0 ? " over the whole frame" : "",
        level >= o.coarseGate ? "at least" : "under", o.coarseGate);
}

// Whether the coarse pass runs, and the frame's noise level that decided it (-1: none
// read). The gate reads the clamp's estimate this run made where it has one (the same bits
// as NforCoarseLevel's strips), so a frame it leaves spends nothing more.
struct CoarseGate {
    double level = -1;
    bool runs = false;
};

CoarseGate DecideCoarse(vk::Context &context, NforGpu &gpu, const NforInputs &in,
                        const NforOptions &o) {
    CoarseGate gate{-1, o.coarse};
    if (!o.coarse && o.coarseGate > 0) {
        gate.level = in.coarseLevel >= 0 || !OwnClampEstimate(in, o)
                         ? NforCoarseLevel(context, in, o)
                         : NforRelativeNoise(*in.color, gpu.clampVariance.Download());
        gate.runs = gate.level >= o.coarseGate;
    }
    return gate;
}

// Give the output the coarse pass's low frequencies where the gate lets it run.
void AddCoarsePass(vk::Context &context, StagedRun &run, const NforInputs &in,
                   const NforOptions &o, CoarseGate gate, NforResult &result) {
    const double coarseLevel = gate.level;
    const bool coarseRuns = gate.runs;
    std::optional<Image> coarse;
    if (coarseRuns) coarse = CoarseOutput(context, in, o);
    result.coarseLevel = coarseLevel;
    result.coarseRan = coarseRuns;
    if (coarse) {
        run.AddStage("coarse", *coarse);
        NforAddCoarse(*in.color, *coarse, in.albedo, o.emitterAlbedo, o.coarseRelative,
                      o.coarseNoise, &result.image);
        run.Plan(fmt::format(
            "coarse pass: the frame denoised again at half the resolution; its low "
            "frequencies taken where they differ by under min({} x the output's magnitude, "
            "{} x its residual){}",
            o.coarseRelative, o.coarseNoise, PlanCoarseGate(in, o, coarseLevel)));
    } else if (o.coarseGate > 0) {
        run.Plan("left out: the coarse pass" + PlanCoarseGate(in, o, coarseLevel));
    }
}

}  // namespace

void NforFrameClampLoss(vk::Context &context, NforInputs *in, const NforOptions &o,
                        int stripPixels) {
    if (!in->variance || o.clampLayer) return;
    CheckLayers(*in);
    CheckOptions(o);
    // The frame as NforDenoise clamps it.
    StraightInputs straight(*in, o);
    const NforInputs &frame = straight.inputs;
    in->clampLoss =
        ClampLoss(*frame.color,
                  EstimateOnStrips(context, *frame.color, frame.albedo, o, stripPixels, true));
    if (!NforCoarseRuns(context, frame, o, nullptr, stripPixels)) return;
    // The coarse pass's frame, as CoarseOutput halves it.
    Image color = NforHalf(*frame.color);
    std::optional<Image> albedo;
    if (frame.albedo) albedo = NforHalf(*frame.albedo);
    in->coarseClampLoss = ClampLoss(
        color,
        EstimateOnStrips(context, color, albedo ? &*albedo : nullptr, o, stripPixels, true));
}

double NforCoarseLevel(vk::Context &context, const NforInputs &in, const NforOptions &o,
                       int stripPixels) {
    if (in.coarseLevel >= 0) return in.coarseLevel;
    CheckLayers(in);
    CheckOptions(o);
    // The frame as NforDenoise estimates its noise.
    StraightInputs straight(in, o);
    const NforInputs &frame = straight.inputs;
    return NforRelativeNoise(*frame.color, EstimateOnStrips(context, *frame.color, frame.albedo,
                                                            o, stripPixels, false));
}

bool NforCoarseRuns(vk::Context &context, const NforInputs &in, const NforOptions &o,
                    double *level, int stripPixels) {
    double measured =
        o.coarse || o.coarseGate <= 0 ? -1 : NforCoarseLevel(context, in, o, stripPixels);
    if (level) *level = measured;
    return o.coarse || (o.coarseGate > 0 && measured >= o.coarseGate);
}

NforOptions NforNoisyOptions(const NforOptions &options) {
    NforOptions o = options;
    o.radius = std::max(o.radius, o.noisyRadius);
    if (o.pilotWideRadius <= o.radius) o.pilotWideRadius = 0;
    return o;
}

namespace {

// The options a run takes after its clamp: where the coarse pass runs, the noisy radius's
// (NforNoisyOptions), the plan told; elsewhere `options`.
NforOptions NoisyRun(StagedRun &run, const NforInputs &given, const NforOptions &options,
                     const CoarseGate &gate) {
    if (!gate.runs || options.noisyRadius <= options.radius) return options;
    const NforOptions o = NforNoisyOptions(options);
    CheckInputs(run.Context(), given, o);
    run.Plan(fmt::format(
        "windows of {0}x{0} (--noisy-radius {1}, where the radius gives {2}x{2}{3}): the "
        "coarse pass runs on this frame, which is noisy",
        2 * o.radius + 1, o.noisyRadius, 2 * options.radius + 1,
        o.pilotWideRadius != options.pilotWideRadius
            ? fmt::format("; the second pass's {0}x{0} windows left out",
                          2 * options.pilotWideRadius + 1)
            : std::string()));
    return o;
}

}  // namespace

NforResult NforDenoise(vk::Context &context, const NforInputs &given,
                       const NforOptions &options, RunMemo *memo) {
    CheckInputs(context, given, options);
    StraightInputs straight(given, options);
    const NforInputs &in = straight.inputs;
    std::vector<float> weights;
    std::vector<std::string> names;
    Image featureImage = NforFeatures(in, options, &weights, &names);
    NforResult result;
    StagedRun run(context, options.keepStages);
    PlanNoise(run, in, options);
    PlanFeatures(run, names, options);
    NforGpu gpu(context, in, featureImage, options);
    RecordClampStages(run, gpu, in, options, result);
    // The coarse pass's gate reads the clamp's estimate; a noisy frame it lets through is
    // fitted over the noisy radius's windows from here on.
    run.Submit();
    const CoarseGate gate = DecideCoarse(context, gpu, in, options);
    const NforOptions o = NoisyRun(run, given, options, gate);
    gpu.MakeDistances(context, o);
    RecordPrepare(run, gpu, in, o, memo, memo ? MemoImageId(featureImage) : std::string(),
                  straight.partlyCovered > 0 ? given.alpha : nullptr, result);
    int w = in.color->width, h = in.color->height, ch = in.color->channels;
    vk::GpuImage out(context, w, h, ch, "nfor.out"), choice(context, w, h, 1, "nfor.choice");
    RecordPasses(run, gpu, weights, o, in.pilot != nullptr, out, choice);
    run.Submit();
    PlanDistance(run, gpu, o);
    // The glint floor's mask, read once for its plan line and its guard.
    const Image floored = gpu.glint ? gpu.glint->Download() : Image();
    if (gpu.glint) PlanGlintNoise(run, floored, o);
    result.image = out.Download();
    Image mask = gpu.mask.Download(), clamped = gpu.clamped.Download();
    for (float m : mask.data) result.emitters += m == 0;
    for (size_t i = 0; i < clamped.Size(); ++i)
        result.clamped += clamped.data[i] != in.color->data[i];
    if (o.meanRadius > 0) {
        std::vector<bool> meansLeft;
        RestoreMeans(run, in, o, mask, clamped, result, &meansLeft);
        // Under --premultiplied no alpha: the run is one without it.
        if (o.clampLightRadius > 0 && PlainPasses(in, o, result) && !gate.runs)
            RestoreClampLight(run, in, o, mask, clamped,
                              straight.partlyCovered > 0 ? given.alpha : nullptr, meansLeft,
                              result);
    }
    const bool plain = PlainPasses(in, o, result);
    const int keptPass = NforKeptPassRadius(o, plain, in.albedo);
    if (keptPass > 0) SmoothKept(run, in, o, gpu, weights, mask, keptPass, result);
    AddCoarsePass(context, run, in, o, gate, result);
    if (gpu.glint) GuardGlint(run, clamped, floored, result);
    run.Plan(
        fmt::format("emitters (largest albedo channel > {}): {} pixels, left out of every "
                    "window and kept as they are but for the lights' spread (a lone one far "
                    "above its neighbours: clamped like a firefly)",
                    o.emitterAlbedo, result.emitters));
    run.Plan(o.fireflyThreshold > 0
                 ? fmt::format("fireflies: {} pixel-channels clamped to the median of their 8 "
                               "neighbours (colour / albedo, of the neighbours divided alike; "
                               "colour where none is) + {} sigma + {} x the median{}",
                               result.clamped, o.fireflyThreshold, o.fireflyRelative,
                               o.fireflyLoneLight > 0
                                   ? fmt::format("; an emitter with none beside it, of albedo "
                                                 "{} or more and its colour within {}x of its "
                                                 "albedo (a light under a pixel, seen "
                                                 "directly) kept",
                                                 o.fireflyLoneLight, NFOR_LONE_LIGHT_RATIO)
                                   : std::string())
                 : std::string("left out: the firefly clamp (--firefly-threshold 0)"));
    if (in.variance) PlanClamp(run, in, o, result);
    PlanPasses(run, o, in.pilot != nullptr, choice, result);
    if (straight.partlyCovered > 0) {
        run.AddStage("straight", result.image);
        NforMultiplyByAlpha(*given.alpha, &result.image);
        result.partlyCovered = straight.partlyCovered;
        run.Plan(fmt::format(
            "alpha: {} partly covered pixels (alpha from {} to under 1) denoised as the "
            "surface they show: colour and features divided by their alpha (a variance layer "
            "by its square; the frame's own estimate of their noise, read from the covered "
            "pixels around, by alpha), the output multiplied back (--premultiplied: as the "
            "frame holds them)",
            result.partlyCovered, kNforMinAlpha));
    }
    // On the output as written, so that light moved between pixels of any coverage stays.
    if (NforSpreadsLights(o, plain, in.albedo)) SpreadLights(run, in, o, given.alpha, result);
    if (o.lineSpread > 0 && in.albedo) {
        // The colour, the clamped colour and the albedo as written, like the output.
        if (straight.partlyCovered > 0) NforMultiplyByAlpha(*given.alpha, &clamped);
        SpreadLine(run, *given.color, clamped, *given.albedo, given.alpha, o, result);
    }
    if (plain && o.glintBandRadius > 0 && given.albedo)
        SmoothGlintBands(run, *given.albedo, given.alpha, o, result);
    if (plain && in.albedo && o.rimRatio > 0)
        FoldRimHits(run, *given.color, *in.albedo, given.alpha, o, result);
    else if (plain && in.albedo && o.rimHits > 0)
        run.Plan(
            "left out: the rim hits (the frame states no samples per pixel, no spp layer "
            "nor metadata such as Cycles' cycles.<view layer>.samples, or too few for "
            "--rim-hits: under 4 per hit)");
    run.AddStage("output", result.image);
    run.Plan(GpuTimes(run.Timings()));
    run.Finish(result);
    return result;
}

}  // namespace mcd
