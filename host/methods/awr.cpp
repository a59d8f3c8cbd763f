#include "host/methods/awr.h"

#include <fmt/format.h>

#include <cmath>

#include "host/common/cycle_spin.h"
#include "host/error.h"
#include "host/kernels/awr_shrink.h"
#include "host/methods/checks.h"
#include "host/methods/staged_run.h"
#include "host/vk/gpu_image.h"
#include "host/wavelet/transform.h"

namespace mcd {

Image AwrVarianceFromRange(const Image &min, const Image &max, const Image &spp) {
    if (!min.SameShape(max) || spp.width != min.width || spp.height != min.height)
        throw Error("awr: the min, max and spp layers differ in size",
                    ErrorKind::InvalidArgument);
    Image variance(min.width, min.height, min.channels);
    for (int c = 0; c < min.channels; ++c)
        for (int y = 0; y < min.height; ++y)
            for (int x = 0; x < min.width; ++x) {
                double range = double(max.At(c, y, x)) - min.At(c, y, x);
                double n = spp.At(0, y, x);
                // A pixel without samples has nothing to trust: infinite variance would
                // erase its details, which is what it deserves, but keep it finite.
                variance.At(c, y, x) = float(n > 0 ? range * range / n : range * range);
            }
    return variance;
}

namespace {

// Throw on bad shapes, values or options; return the levels to run.
int CheckAwrInputs(const Image &color, const Image &variance, const AwrParams &options) {
    if (!color.SameShape(variance))
        throw Error(fmt::format("awr: color is {}x{}x{} but variance is {}x{}x{}", color.width,
                                color.height, color.channels, variance.width, variance.height,
                                variance.channels),
                    ErrorKind::InvalidArgument);
    if (!std::isfinite(options.cs) || options.cs < 0)
        throw Error(fmt::format("awr: cs must be a finite number >= 0, not {}", options.cs),
                    ErrorKind::InvalidArgument);
    if (!std::isfinite(options.renorm))
        throw Error("awr: the renormalisation sum must be a finite number",
                    ErrorKind::InvalidArgument);
    CheckFinite("awr", color, "color", false);
    CheckFinite("awr", variance, "variance", true);
    int maxLevels = MaxWaveletLevels(color.width, color.height);
    int levels = options.levels < 0 ? maxLevels : options.levels;
    if (levels > maxLevels)
        throw Error(fmt::format("awr: {} levels requested; a {}x{} image allows 0..{}", levels,
                                color.width, color.height, maxLevels),
                    ErrorKind::InvalidArgument);
    return levels;
}

// Why the reconstruction would give the input back, or nullptr when it would not:
// shrinking by zero keeps every coefficient, and the transform would undo itself.
const char *IdleReason(const Image &variance, const AwrParams &options, int levels) {
    bool anyVariance = false;
    for (float v : variance.data) anyVariance |= v > 0;
    if (!anyVariance) return "the variance is zero everywhere";
    if (options.cs == 0) return "cs is 0";
    if (levels == 0) return "0 levels";
    return nullptr;
}

void PlanAwr(StagedRun &run, const Image &color, int levels, const AwrParams &options) {
    run.Plan(fmt::format("{}-level {} DWT of color ({}x{}x{})", levels,
                         WaveletName(options.basis), color.width, color.height,
                         color.channels));
    run.Plan(fmt::format(
        "squared-filter DWT of the variance (eq. 10), squared 1D filters summing to {:.4g} "
        "(low) and {:.4g} (high)",
        options.renorm, options.renorm));
    run.Plan(fmt::format(
        "soft shrinkage of the details by cs = {} standard "
        "deviations (eq. 11); the coarsest low band is kept{}",
        options.cs, run.KeepsStages() ? "" : "; fused into the synthesis's columns passes"));
    run.Plan("synthesis");
}

// Analysis of both images in place, shrinkage, synthesis into `coef`. With keepStages each
// stage is submitted and downloaded; else it is all one submission.
void RecordAwr(StagedRun &run, WaveletTransform &transform, vk::GpuImage &coef,
               vk::GpuImage &coefVariance, int levels, const AwrParams &options) {
    vk::Recorder &recorder = run.Recorder();
    transform.RecordAnalysis(recorder, options.basis, levels, coef, coef);
    transform.RecordSqAnalysis(recorder, options.basis, levels, coefVariance, coefVariance,
                               options.renorm, options.renorm);
    run.Stage("analysis", coef);
    run.Stage("variance analysis", coefVariance);
    if (run.KeepsStages()) {
        // The shrunk coefficients are a stage of their own: shrink, then synthesise.
        RecordAwrShrink(run.Context(), recorder, coef, coefVariance,
                        LevelExtent(coef.width, levels), LevelExtent(coef.height, levels),
                        options.cs);
        run.Stage("shrinkage", coef);
        transform.RecordSynthesis(recorder, options.basis, levels, coef, coef);
    } else {
        // Shrink each detail coefficient as the synthesis reads it: no pass over the
        // coefficients of its own, the same result (tests/methods/awr_test.cpp).
        transform.RecordShrinkSynthesis(recorder, options.basis, levels, coef, coefVariance,
                                        options.cs, coef);
    }
}

AwrResult AwrReconstructOnce(vk::Context &context, const Image &color, const Image &variance,
                             const AwrParams &options, bool keepStages) {
    int levels = CheckAwrInputs(color, variance, options);
    AwrResult result;
    if (const char *idle = IdleReason(variance, options, levels)) {
        result.image = color;
        result.plan.push_back(fmt::format(
            "left out: the whole reconstruction ({}): the output is the input", idle));
        return result;
    }
    StagedRun run(context, keepStages);
    PlanAwr(run, color, levels, options);
    // Two images and the transform's temporary: every transform runs in place, the color's
    // buffer holding its coefficients and then the output, the variance's buffer the
    // coefficient variances. Fresh memory is paid for on first touch (page faults on a
    // CPU device), so fewer buffers are faster as well as smaller.
    vk::GpuImage coef(context, color.width, color.height, color.channels, "awr.color");
    vk::GpuImage coefVariance(context, color.width, color.height, color.channels,
                              "awr.variance");
    coef.Upload(color);
    coefVariance.Upload(variance);
    WaveletTransform transform(context, color.width, color.height, color.channels);
    RecordAwr(run, transform, coef, coefVariance, levels, options);
    run.Submit();
    result.image = coef.Download();
    run.AddStage("synthesis", result.image);
    run.Finish(result);
    return result;
}

}  // namespace

AwrResult AwrReconstruct(vk::Context &context, const Image &color, const Image &variance,
                         const AwrParams &options, const RunSetup &setup) {
    if (options.spins < 1 || options.spins > 8)
        throw Error(fmt::format("awr: spins must be in [1, 8], not {}", options.spins),
                    ErrorKind::InvalidArgument);
    if (options.spins == 1)
        return AwrReconstructOnce(context, color, variance, options, setup.keepStages);
    // The unshifted run checks the inputs and decides the levels; every shift uses them.
    AwrParams once = options;
    once.spins = 1;
    AwrResult result = AwrReconstructOnce(context, color, variance, once, setup.keepStages);
    if (result.timings.empty()) return result;  // nothing ran: the output is the input
    if (once.levels < 0) once.levels = MaxWaveletLevels(color.width, color.height);
    Image unshifted = std::move(result.image);
    result.image = CycleSpin(
        color.width, color.height, color.channels, options.spins, [&](int dx, int dy) {
            if (dx == 0 && dy == 0) return unshifted;
            AwrResult one = AwrReconstructOnce(context, MirrorPad(color, dx, dy),
                                               MirrorPad(variance, dx, dy), once, false);
            for (const vk::DispatchTiming &t : one.timings) result.timings.push_back(t);
            return std::move(one.image);
        });
    result.plan.insert(result.plan.begin(),
                       fmt::format("cycle spinning: the average over {} x {} shifts (mirrored "
                                   "padding), each with the levels of the unshifted frame",
                                   options.spins, options.spins));
    if (setup.keepStages) result.stages.push_back({"cycle spinning", result.image});
    return result;
}

}  // namespace mcd
