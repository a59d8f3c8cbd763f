#include "host/methods/auto.h"

#include <fmt/format.h>

#include <algorithm>
#include <memory>

#include "host/error.h"
#include "host/kernels/auto_combine.h"
#include "host/kernels/auto_estimate.h"
#include "host/kernels/auto_guided.h"
#include "host/kernels/auto_noise.h"
#include "host/kernels/auto_smooth.h"
#include "host/methods/auto_halves.h"
#include "host/methods/auto_object_floor.h"
#include "host/vk/gpu_image.h"
#include "shaders/auto/auto.h"
#include "shaders/auto/noise.h"

namespace mcd {

static_assert(kAutoMaxCandidates == AUTO_MAX_CANDIDATES);
static_assert(kAutoNoiseMaxRadius == AUTO_NOISE_MAX_RADIUS);

void PrepareAutoNoiseKernels(vk::Context &context) {
    context.PrepareKernel(AutoNoiseKernel());
}

MethodResult AutoNoise(vk::Context &context, const Image &color, const Image *albedo,
                       int radius) {
    StagedRun run(context, false);
    vk::GpuImage gColor(context, color.width, color.height, color.channels, "auto.noise.color");
    vk::GpuImage gNoise(context, color.width, color.height, color.channels, "auto.noise");
    gColor.Upload(color);
    std::unique_ptr<vk::GpuImage> gAlbedo;
    if (albedo) {
        gAlbedo = std::make_unique<vk::GpuImage>(context, albedo->width, albedo->height,
                                                 albedo->channels, "auto.noise.albedo");
        gAlbedo->Upload(*albedo);
    }
    RecordAutoNoise(context, run.Recorder(), gColor, gAlbedo.get(), radius, gNoise);
    run.Submit();
    MethodResult result;
    result.image = gNoise.Download();
    run.Finish(result);
    return result;
}

namespace {

void CheckAutoInputs(const Image &color, const std::vector<AutoCandidate> &candidates,
                     const AutoEstimateInputs &estimate, const AutoOptions &options) {
    if (color.channels < 1 || color.channels > 4)
        throw Error(
            fmt::format("auto: {} colour channels; 1 to 4 are combined", color.channels),
            ErrorKind::InvalidArgument);
    if (candidates.empty() || candidates.size() > size_t(kAutoMaxCandidates))
        throw Error(fmt::format("auto: {} candidates; 1 to {} are combined", candidates.size(),
                                kAutoMaxCandidates),
                    ErrorKind::Internal);
    bool scored = !estimate.variance.Empty(), halves = !estimate.half1.Empty();
    for (const AutoCandidate &c : candidates)
        if (!c.output.SameShape(color) || (scored && !c.probe.SameShape(color)))
            throw Error(
                fmt::format("auto: candidate {}'s output or probe is not of the colour's "
                            "shape {}x{}x{}",
                            c.label, color.width, color.height, color.channels),
                ErrorKind::Internal);
    if (scored != (options.combination != AutoCombination::Mean))
        throw Error("auto: the mean takes no estimate, the other combinations need one",
                    ErrorKind::Internal);
    if (!scored) return;
    for (const Image *image : {&estimate.variance, &estimate.probe})
        if (!image->SameShape(color))
            throw Error("auto: the estimate's variance and probe must have the colour's shape",
                        ErrorKind::Internal);
    if ((halves && !estimate.half1.SameShape(color)) ||
        (!estimate.offset.Empty() && !estimate.offset.SameShape(color)))
        throw Error("auto: half1 and the split's offset must have the colour's shape",
                    ErrorKind::Internal);
    if (!estimate.objectFactors.Empty() &&
        (estimate.objectFactors.width != color.width ||
         estimate.objectFactors.height != color.height ||
         estimate.objectFactors.channels != int(candidates.size())))
        throw Error("auto: the object guard's factors need one plane per candidate",
                    ErrorKind::Internal);
    if (options.combination == AutoCombination::Relative &&
        !estimate.meanVariance.SameShape(color))
        throw Error("auto: the relative combination needs the variance of the pixel mean",
                    ErrorKind::Internal);
    // The guard's tents must lie within the strips' halo of twice the estimates' radius.
    if (options.meanGuard > 0 &&
        (options.meanGuardRadius < 0 || options.meanGuardRadius > options.radius))
        throw Error(fmt::format("auto: the guard's radius {} is not within 0 to the "
                                "estimates' radius {}",
                                options.meanGuardRadius, options.radius),
                    ErrorKind::Internal);
}

// The buffers of a combination: K candidates of C channels, W x H.
struct AutoGpu {
    int width, height, channels, count;
    vk::GpuImage color, candidates, errors, smooth, smoothScratch, output, weights;

    AutoGpu(vk::Context &context, const Image &image,
            const std::vector<AutoCandidate> &candidates)
        : width(image.width),
          height(image.height),
          channels(image.channels),
          count(int(candidates.size())),
          color(context, width, height, channels, "auto.color"),
          candidates(context, width, height, count * channels, "auto.candidates"),
          errors(context, width, height, count, "auto.errors"),
          smooth(context, width, height, count, "auto.smooth"),
          smoothScratch(context, width, height, 2 * count, "auto.smooth.rows"),
          output(context, width, height, channels, "auto.output"),
          weights(context, width, height, count, "auto.weights") {
        color.Upload(image);
        Image packed(width, height, count * channels);
        for (int k = 0; k < count; ++k)
            std::copy(candidates[k].output.data.begin(), candidates[k].output.data.end(),
                      packed.data.begin() + size_t(k) * channels * width * height);
        this->candidates.Upload(packed);
    }
    vk::GpuImage Planes(vk::Context &context, int planes, const char *name,
                        const Image &image) const {
        vk::GpuImage gpu(context, width, height, planes, name);
        gpu.Upload(image);
        return gpu;
    }
};

// The inputs every candidate's estimate reads, and its scratch.
struct EstimateGpu {
    vk::GpuImage variance, probe, scored, perturbed, error, offset, noOffset, half1;

    EstimateGpu(vk::Context &context, const AutoGpu &gpu, const AutoEstimateInputs &in)
        : variance(gpu.Planes(context, gpu.channels, "auto.variance", in.variance)),
          probe(gpu.Planes(context, gpu.channels, "auto.probe", in.probe)),
          scored(context, gpu.width, gpu.height, gpu.channels, "auto.candidate"),
          perturbed(context, gpu.width, gpu.height, gpu.channels, "auto.perturbed"),
          error(context, gpu.width, gpu.height, 1, "auto.error"),
          noOffset(gpu.Planes(context, gpu.channels, "auto.nooffset",
                              Image(gpu.width, gpu.height, gpu.channels))) {
        if (!in.offset.Empty())
            offset = gpu.Planes(context, gpu.channels, "auto.offset", in.offset);
        if (!in.half1.Empty())
            half1 = gpu.Planes(context, gpu.channels, "auto.half1", in.half1);
    }
};

// The window means of `errors`' planes into `out`: the tents (`rows`, twice the planes, their
// scratch), or with bandwidth > 0 the tents weighed by the guide's colour.
void RecordWindowMean(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &errors,
                      const vk::GpuImage &guide, int radius, float bandwidth,
                      vk::GpuImage &rows, vk::GpuImage &out) {
    if (bandwidth > 0)
        RecordAutoSmoothGuided(context, recorder, errors, guide, radius, bandwidth, out);
    else
        RecordAutoSmooth(context, recorder, errors, radius, rows, out);
}

// Every candidate's estimate with the guide g in relMSE's denominator (g^2 + 0.01, or the
// pixel's variance over noiseCap where that is larger), one plane each in gpu.errors, then
// their window means in gpu.smooth. With the half-buffers F(half0) is compared with half1
// (the zero probe drops the divergence term).
void RecordEstimates(StagedRun &run, AutoGpu &gpu, EstimateGpu &est,
                     const std::vector<AutoCandidate> &candidates, bool halves,
                     const vk::GpuImage &guide, float noiseCap, int radius,
                     float bandwidth = 0) {
    vk::Context &context = run.Context();
    size_t planeBytes = size_t(gpu.width) * gpu.height * sizeof(float);
    for (int k = 0; k < gpu.count; ++k) {
        const AutoCandidate &c = candidates[k];
        est.scored.Upload(halves ? c.probe : c.output);
        est.perturbed.Upload(c.probe);
        RecordAutoEstimate(context, run.Recorder(), halves ? est.half1 : gpu.color,
                           est.variance, est.probe, guide, est.scored, est.perturbed,
                           c.split ? est.offset : est.noOffset, c.epsilon, noiseCap, est.error);
        run.Recorder().Copy(est.error.buffer, gpu.errors.buffer, planeBytes, 0,
                            size_t(k) * planeBytes);
        // The next candidate's upload reuses the scratch.
        run.Submit();
    }
    RecordWindowMean(context, run.Recorder(), gpu.errors, guide, radius, bandwidth,
                     gpu.smoothScratch, gpu.smooth);
}

// Each candidate's method as the index of that method's first candidate.
std::vector<int> MethodIndices(const std::vector<AutoCandidate> &candidates) {
    std::vector<int> first;
    for (const AutoCandidate &c : candidates) {
        int k = 0;
        while (candidates[k].method != c.method) ++k;
        first.push_back(k);
    }
    return first;
}

// Whether a method's variants share one weight: beside the half-buffers, where the
// combination weighs the candidates (select takes one, with no weights to share).
bool SharesVariants(const AutoOptions &options) {
    return options.halvesVariants && options.combination != AutoCombination::Select;
}

// The estimates over the frame and the candidates they leave out, for the plan.
std::vector<std::string> HalvesDropPlan(const std::vector<AutoCandidate> &candidates,
                                        const AutoOptions &options,
                                        const AutoHalvesResult &adjusted) {
    std::string estimates;
    for (size_t k = 0; k < candidates.size(); ++k)
        estimates += fmt::format("{}{} {:.3g}", estimates.empty() ? "" : ", ",
                                 candidates[k].label, adjusted.frameEstimates[k]);
    std::vector<std::string> plan{
        fmt::format("auto: the estimates over the frame: {}; half1's variance {:.3g}",
                    estimates, adjusted.frameNoise)};
    for (size_t k = 0; k < candidates.size(); ++k)
        if (adjusted.dropped[k])
            plan.push_back(
                fmt::format("auto: left out {}: its estimate over the frame is above {} x the "
                            "candidates' median, {:.3g} (--auto-halves-drop)",
                            candidates[k].label, options.halvesDrop, adjusted.median));
    return plan;
}

// The guard of the local means on the adjusted estimates, and its plan line. The variance
// of the pixel mean is the relative combination's, else half half1's.
void GuardLocalMeans(StagedRun &run, Image &smooth, const Image &color,
                     const std::vector<AutoCandidate> &candidates, const AutoEstimateInputs &in,
                     const AutoOptions &options) {
    Image variance = in.meanVariance.Empty() ? in.variance : in.meanVariance;
    const float scale = options.meanGuardVarianceScale * (in.meanVariance.Empty() ? 0.5f : 1.f);
    for (float &v : variance.data) v *= scale;
    std::vector<const Image *> outputs;
    for (const AutoCandidate &c : candidates) outputs.push_back(&c.output);
    AutoMeanGuard guard;
    guard.z = options.meanGuard, guard.radius = options.meanGuardRadius;
    guard.floorError = options.floorError;
    const std::vector<double> raised =
        AutoGuardLocalMeans(smooth, color, outputs, variance, guard);
    std::string shares;
    for (size_t k = 0; k < candidates.size(); ++k)
        shares += fmt::format("{}{} {:.1f}%", shares.empty() ? "" : ", ", candidates[k].label,
                              100 * raised[k]);
    run.Plan(fmt::format(
        "auto: guard of the local means: an estimate times exp((t^2 - {}^2) / 2) where the "
        "candidate's mean over {}x{} tents departs from the colour's by t > {} standard "
        "errors of it, so that a candidate that fades or ghosts an object weighs less there "
        "(--auto-mean-guard); raised in {}",
        options.meanGuard, 2 * options.meanGuardRadius + 1, 2 * options.meanGuardRadius + 1,
        options.meanGuard, shares));
}

// Beside the half-buffers: half1's variance over relMSE's denominator averaged over the
// windows like the estimates (half1 scored as a candidate has its negative for estimate),
// then the final estimates raised to it where they are below and a candidate far above the
// others over the frame left out.
void AdjustHalvesEstimates(StagedRun &run, AutoGpu &gpu, EstimateGpu &est,
                           const std::vector<AutoCandidate> &candidates,
                           const AutoOptions &options, const vk::GpuImage &guide,
                           const Image &color, const AutoEstimateInputs &in) {
    vk::Context &context = run.Context();
    vk::GpuImage rows(context, gpu.width, gpu.height, 2, "auto.halves.rows"),
        noise(context, gpu.width, gpu.height, 1, "auto.halves.noise");
    RecordAutoEstimate(context, run.Recorder(), est.half1, est.variance, est.probe, guide,
                       est.half1, est.half1, est.noOffset, 1.f, options.noiseCap, est.error);
    RecordWindowMean(context, run.Recorder(), est.error, guide, options.radius,
                     options.windowBandwidth, rows, noise);
    run.Submit();
    Image smooth = gpu.smooth.Download(), halfNoise = noise.Download();
    for (float &x : halfNoise.data) x = -x;
    if (options.halvesSums) options.halvesSums->Add(smooth, halfNoise);
    AutoHalvesSettings settings;
    settings.floor = options.halvesFloor, settings.drop = options.halvesDrop;
    settings.floorError = options.floorError, settings.rank = options.halvesRank;
    if (!options.halvesDropped.empty()) settings.dropped = &options.halvesDropped;
    if (!options.halvesFrameEstimates.empty()) {
        settings.frameEstimates = &options.halvesFrameEstimates;
        settings.frameNoise = options.halvesFrameNoise;
    }
    if (SharesVariants(options)) settings.method = MethodIndices(candidates);
    settings.power = options.power;
    AutoHalvesResult adjusted = AutoAdjustHalvesEstimates(smooth, halfNoise, settings);
    if (options.meanGuard > 0) GuardLocalMeans(run, smooth, color, candidates, in, options);
    AutoApplyObjectGuard(smooth, in.objectFactors, options.floorError);
    gpu.smooth.Upload(smooth);
    if (options.halvesFloor > 0)
        run.Plan(fmt::format(
            "auto: each estimate raised to at least half1's variance over its window, at most "
            "{} x the candidates' median there (an estimate below what the noise lets the "
            "window resolve weighs no more than that; --auto-halves-floor){}",
            options.halvesFloor,
            options.halvesRank > 0
                ? fmt::format(", times (its frame-wide estimate / the smallest) ^ {}, so "
                              "that where the noise hides the differences the weights follow "
                              "the frame's ranking (--auto-halves-rank)",
                              options.halvesRank)
                : ""));
    std::string shared;
    for (size_t k = 0; k < candidates.size(); ++k)
        if (adjusted.variants[k] != 1.f)
            shared += fmt::format("{}{} x{:.3g}", shared.empty() ? "" : ", ",
                                  candidates[k].label, adjusted.variants[k]);
    if (!shared.empty())
        run.Plan(fmt::format(
            "auto: a method's variants share one candidate's weight, their errors going "
            "together: each estimate times the number of its method's candidates left in ^ "
            "1/{}: {} (--auto-halves-variants share)",
            options.power, shared));
    // In strips the whole frame's figures are AutoCombine's to print.
    if (options.halvesDropped.empty())
        for (const std::string &line : HalvesDropPlan(candidates, options, adjusted))
            run.Plan(line);
}

// The estimates of the final combination, whose denominator's guide stands in for the
// reference. The candidates' mean stood in for it, but where one candidate overshoots (a
// firefly kept, a blotch) it inflates the mean and so the denominator, which caps that
// candidate's estimated error at about count^2 however far it is off: on relief-abc a few
// pixels carry most of every candidate's error and the mean's denominator there is
// several times the reference's (docs/methods/auto.md). So by default a first pass weighs the
// candidates by their plain squared error (a zero guide: the same denominator everywhere)
// and its combination, where the overshooting candidates already weigh little, is the
// guide. Where the candidates disagree beyond what the estimates resolve it leans dark,
// which suits relMSE: brightening a dark pixel costs without bound, darkening a bright one
// at most 1.
void RecordGuidedEstimates(StagedRun &run, AutoGpu &gpu, const Image &color,
                           const AutoEstimateInputs &in,
                           const std::vector<AutoCandidate> &candidates,
                           const AutoOptions &options, vk::GpuImage &guide) {
    vk::Context &context = run.Context();
    EstimateGpu est(context, gpu, in);
    bool halves = !in.half1.Empty();
    if (options.meanGuide) {
        // Zero estimates weigh the candidates equally: the mean.
        vk::GpuImage zeros = gpu.Planes(context, gpu.count, "auto.zeros",
                                        Image(gpu.width, gpu.height, gpu.count));
        RecordAutoCombine(context, run.Recorder(), gpu.color, gpu.candidates, zeros,
                          AutoMode::Weights, 1.f, 1.f, guide, gpu.weights);
        run.Submit();
    } else {
        vk::GpuImage flat = gpu.Planes(context, gpu.channels, "auto.flat",
                                       Image(gpu.width, gpu.height, gpu.channels));
        RecordEstimates(run, gpu, est, candidates, halves, flat, 0.f, options.radius);
        RecordAutoCombine(context, run.Recorder(), gpu.color, gpu.candidates, gpu.smooth,
                          AutoMode::WeightsMedian, options.power, options.floorError, guide,
                          gpu.weights);
    }
    // The second pass bounds each pixel's weight by its noise: with a guide that can be
    // dark where a candidate is right to be bright (fireflies 4 spp: rhf darkens a light
    // seen by one sample, and so does the first pass), that pixel's estimate, of the order
    // of v / (g^2 + 0.01), would swamp every window around it.
    RecordEstimates(run, gpu, est, candidates, halves, guide, options.noiseCap, options.radius,
                    options.windowBandwidth);
    if (halves && (options.halvesFloor > 0 || options.halvesDrop > 0 ||
                   SharesVariants(options) || options.meanGuard > 0)) {
        AdjustHalvesEstimates(run, gpu, est, candidates, options, guide, color, in);
    } else if (!in.objectFactors.Empty()) {
        run.Submit();
        Image smooth = gpu.smooth.Download();
        AutoApplyObjectGuard(smooth, in.objectFactors, options.floorError);
        gpu.smooth.Upload(smooth);
    }
}

// Without an estimate every method gets the same weight, shared by its variants: a
// constant "error" of the number of its variants among the candidates, weighed at power 1.
Image Shares(const std::vector<AutoCandidate> &candidates, int width, int height) {
    int count = int(candidates.size());
    Image shares(width, height, count);
    // At power 1 the variants' factor is their number.
    const std::vector<float> siblings = AutoVariantFactors(
        MethodIndices(candidates), std::vector<bool>(candidates.size(), false), 1.f);
    for (int k = 0; k < count; ++k)
        std::fill(shares.data.begin() + size_t(k) * width * height,
                  shares.data.begin() + size_t(k + 1) * width * height, siblings[k]);
    return shares;
}

// The final combination. Where every estimate is under the floor they all weigh the same
// and tell nothing: the candidates' median there, not their mean (at a firefly of a frame
// without statistics every SURE estimate is negative, and the mean kept the firefly of the
// candidates that keep it; docs/methods/auto.md). The relative combination takes the
// value of least expected relMSE under the weights, and equal weights there and where the
// pixel's noise outweighs what the windows' estimates resolve: a firefly that the
// candidates that remove it cannot win by their window's estimates.
void RecordCombination(StagedRun &run, AutoGpu &gpu, const AutoEstimateInputs &in,
                       const std::vector<AutoCandidate> &candidates,
                       const AutoOptions &options) {
    vk::Context &context = run.Context();
    vk::GpuImage extra;  // the relative combination's variance, or the mean's shares
    if (options.combination == AutoCombination::Relative) {
        extra = gpu.Planes(context, gpu.channels, "auto.meanvariance", in.meanVariance);
        RecordAutoCombine(context, run.Recorder(), gpu.color, gpu.candidates, gpu.smooth,
                          AutoMode::Relative, options.power, options.floorError, gpu.output,
                          gpu.weights, &extra, options.noiseLimit, options.darkLimit);
    } else if (options.combination == AutoCombination::Mean) {
        extra = gpu.Planes(context, gpu.count, "auto.shares",
                           Shares(candidates, gpu.width, gpu.height));
        RecordAutoCombine(context, run.Recorder(), gpu.color, gpu.candidates, extra,
                          AutoMode::Weights, 1.f, 1e-3f, gpu.output, gpu.weights);
    } else {
        RecordAutoCombine(context, run.Recorder(), gpu.color, gpu.candidates, gpu.smooth,
                          options.combination == AutoCombination::Select
                              ? AutoMode::Select
                              : AutoMode::WeightsMedian,
                          options.power, options.floorError, gpu.output, gpu.weights);
    }
    run.Submit();
}

// Each candidate's share (mean weight, %) and where its weight is the largest (% of the
// pixels); with `map`, the image of each pixel coloured by that candidate.
Image Tally(const Image &weights, const std::vector<AutoCandidate> &candidates, bool map,
            AutoResult &result) {
    size_t pixels = weights.PixelCount();
    int count = weights.channels;
    std::vector<double> share(count, 0);
    std::vector<size_t> won(count, 0);
    Image image = map ? Image(weights.width, weights.height, 3) : Image();
    for (size_t i = 0; i < pixels; ++i) {
        int best = -1;
        for (int k = 0; k < count; ++k) {
            float wk = weights.data[k * pixels + i];
            share[k] += wk;
            if (wk > 0 && (best < 0 || wk > weights.data[best * pixels + i])) best = k;
        }
        if (best < 0) continue;
        ++won[best];
        if (map)
            for (int c = 0; c < 3; ++c) image.data[c * pixels + i] = candidates[best].colour[c];
    }
    for (int k = 0; k < count; ++k) {
        result.sharePercent.push_back(100 * share[k] / pixels);
        result.wonPercent.push_back(100.0 * won[k] / pixels);
    }
    return image;
}

}  // namespace

namespace {

// One window's combination: its output, and the weights in `weights` for the tally.
AutoResult CombineWindow(vk::Context &context, const Image &color,
                         const std::vector<AutoCandidate> &candidates,
                         const AutoEstimateInputs &estimate, const AutoOptions &options,
                         Image &weights) {
    StagedRun run(context, options.keepStages);
    AutoGpu gpu(context, color, candidates);
    bool scored = options.combination != AutoCombination::Mean;
    vk::GpuImage guide;
    if (scored) {
        guide = vk::GpuImage(context, gpu.width, gpu.height, gpu.channels, "auto.guide");
        RecordGuidedEstimates(run, gpu, color, estimate, candidates, options, guide);
        for (const AutoCandidate &c : candidates)
            run.AddStage("auto." + c.label + ".probe", c.probe);
    }
    for (const AutoCandidate &c : candidates) run.AddStage("auto." + c.label, c.output);
    if (scored) {
        run.StageAtEnd("auto.guide", guide);
        run.StageAtEnd("auto.estimates", gpu.errors);
        run.StageAtEnd("auto.errors", gpu.smooth);
    }
    RecordCombination(run, gpu, estimate, candidates, options);
    AutoResult result;
    result.image = gpu.output.Download();
    weights = gpu.weights.Download();
    if (options.keepStages) run.AddStage("auto.weights", weights);
    run.Finish(result);
    return result;
}

// Rows [y0, y1) of an image (an empty one stays empty).
Image Rows(const Image &image, int y0, int y1) {
    if (image.Empty()) return image;
    Image rows(image.width, y1 - y0, image.channels);
    for (int c = 0; c < image.channels; ++c)
        std::copy_n(image.Plane(c) + size_t(y0) * image.width, rows.PixelCount(),
                    rows.Plane(c));
    return rows;
}

// Rows [from, from + count) of `part` into rows [to, to + count) of `whole`.
void PasteRows(const Image &part, int from, int to, int count, Image &whole) {
    for (int c = 0; c < whole.channels; ++c)
        std::copy_n(part.Plane(c) + size_t(from) * part.width, size_t(count) * part.width,
                    whole.Plane(c) + size_t(to) * whole.width);
}

// The interior rows of a strip of the combination: all of them where the whole frame fits
// the device (half its memory, its largest buffer, the candidates' outputs, one binding).
// The strip's GPU buffers are, per pixel, the candidates' outputs and a probe's planes, the
// estimates' planes (raw, window means and their row sums, weights) and the colour-sized ones.
int StripRows(vk::Context &context, int width, int height, int count, int channels, int halo) {
    double perPixel = 4.0 * (2 * count * channels + 6 * count + 8 * channels);
    double budget = double(context.Info().deviceLocalBytes) / 2;
    double binding = double(context.BindingBytes());
    double pixels = std::min(budget / perPixel, binding / (4.0 * count * channels));
    if (pixels >= double(width) * height) return height;
    int rows = int(pixels / width) - 2 * halo;
    if (rows < 1)
        throw Error(fmt::format("auto: a strip of {} rows of {} pixels with a halo of {} does "
                                "not fit the device",
                                1, width, halo),
                    ErrorKind::OutOfMemory);
    return rows;
}

// The candidates' outputs and probes, rows [y0, y1).
std::vector<AutoCandidate> CandidateRows(const std::vector<AutoCandidate> &candidates, int y0,
                                         int y1) {
    std::vector<AutoCandidate> rows;
    for (const AutoCandidate &c : candidates) {
        AutoCandidate r;
        r.label = c.label, r.method = c.method, r.epsilon = c.epsilon, r.split = c.split;
        std::copy_n(c.colour, 3, r.colour);
        r.output = Rows(c.output, y0, y1);
        r.probe = Rows(c.probe, y0, y1);
        rows.push_back(std::move(r));
    }
    return rows;
}

}  // namespace

// A frame too large for one combination runs in strips of whole rows with a halo of twice
// the estimates' window radius (the guide's window mean, then the final one): every kernel of
// the combination is per pixel but the window means, so the strips give the whole frame's bits.
AutoResult AutoCombine(vk::Context &context, const Image &color,
                       const std::vector<AutoCandidate> &candidates,
                       const AutoEstimateInputs &estimate, const AutoOptions &options) {
    CheckAutoInputs(color, candidates, estimate, options);
    const int W = color.width, H = color.height, K = int(candidates.size());
    const int halo = 2 * options.radius;
    const int rows = options.keepStages ? H
                     : options.stripRows > 0
                         ? options.stripRows
                         : StripRows(context, W, H, K, color.channels, halo);
    AutoResult result;
    Image weights;
    if (rows >= H) {
        result = CombineWindow(context, color, candidates, estimate, options, weights);
    } else {
        result.image = Image(W, H, color.channels);
        weights = Image(W, H, K);
        int strips = 0;
        // Each strip's rows of the combination (or, with `sums`, of its estimates).
        auto runStrips = [&](const AutoOptions &stripOptions, AutoHalvesSums *sums) {
            for (int y0 = 0; y0 < H; y0 += rows) {
                const int y1 = std::min(H, y0 + rows);
                const int wy0 = std::max(0, y0 - halo), wy1 = std::min(H, y1 + halo);
                AutoEstimateInputs in{Rows(estimate.variance, wy0, wy1),
                                      Rows(estimate.probe, wy0, wy1),
                                      Rows(estimate.half1, wy0, wy1),
                                      Rows(estimate.offset, wy0, wy1),
                                      Rows(estimate.meanVariance, wy0, wy1),
                                      Rows(estimate.objectFactors, wy0, wy1)};
                if (sums) sums->rowBegin = y0 - wy0, sums->rowEnd = y1 - wy0;
                Image stripWeights;
                AutoResult part = CombineWindow(context, Rows(color, wy0, wy1),
                                                CandidateRows(candidates, wy0, wy1), in,
                                                stripOptions, stripWeights);
                result.timings.insert(result.timings.end(), part.timings.begin(),
                                      part.timings.end());
                if (sums) continue;
                PasteRows(part.image, y0 - wy0, y0, y1 - y0, result.image);
                PasteRows(stripWeights, y0 - wy0, y0, y1 - y0, weights);
                if (y0 == 0) result.plan = part.plan;
                ++strips;
            }
        };
        AutoOptions stripOptions = options;
        std::vector<std::string> dropPlan;
        if (!estimate.half1.Empty() && (options.halvesDrop > 0 || options.halvesRank > 0) &&
            options.combination != AutoCombination::Mean) {
            // The drop reads the estimates over the whole frame: a first pass over the strips
            // sums them, so every strip leaves out what the whole frame would.
            AutoHalvesSums sums;
            stripOptions.halvesSums = &sums;
            runStrips(stripOptions, &sums);
            AutoHalvesResult frame;
            frame.frameEstimates = sums.Means();
            frame.frameNoise = sums.NoiseMean();
            frame.dropped = AutoHalvesDropped(frame.frameEstimates, options.halvesDrop,
                                              frame.frameNoise, &frame.median);
            dropPlan = HalvesDropPlan(candidates, options, frame);
            stripOptions.halvesSums = nullptr;
            stripOptions.halvesDropped = frame.dropped;
            stripOptions.halvesFrameEstimates = frame.frameEstimates;
            stripOptions.halvesFrameNoise = frame.frameNoise;
        }
        runStrips(stripOptions, nullptr);
        result.plan.insert(result.plan.end(), dropPlan.begin(), dropPlan.end());
        result.plan.push_back(fmt::format(
            "auto: the combination ran in {} strips of up to {} rows, each with {} rows above "
            "and below (twice the estimates' window radius){}",
            strips, rows, halo,
            options.meanGuard > 0 && !estimate.half1.Empty()
                ? "; the guard's raised shares above are the first strip's"
                : ""));
    }
    bool map = options.map || options.keepStages;
    Image mapImage = Tally(weights, candidates, map, result);
    if (map) result.stages.emplace_back("auto.map", std::move(mapImage));
    if (options.keepWeights) result.weights = std::move(weights);
    return result;
}

}  // namespace mcd
