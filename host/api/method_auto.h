// Method `auto`: every candidate method (and variant, host/api/registry.h) the frame's
// layers allow, within a time budget, each with a per-pixel error estimate that needs no
// reference (SURE from the variance of the mean, or from the half-buffers), combined per
// pixel by those estimates (the pipeline host/methods/auto.h). With keepStages, or
// RunOptions::stages naming it, the result has stage "auto.map": each pixel coloured by the
// candidate of the largest weight (the plan names the colours).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "host/api/front_end.h"
#include "host/methods/nfor_lights.h"

namespace mcd::api {

class AutoFrontEnd : public FrontEnd {
  public:
    AutoFrontEnd();
    AutoFrontEnd(const AutoFrontEnd &other);
    std::unique_ptr<FrontEnd> Clone() const override;
    const std::string &Name() const override { return name; }
    std::string Summary() const override;
    const std::vector<ParamInfo> &Params() const override { return infos; }
    void Set(const std::string &param, const ParamValue &value) override;
    ParamValue Get(const std::string &param) const override;
    std::vector<std::string> Uses() const override;
    std::string Missing(const Frame &frame) const override;

    // One method for the paths that run one (--demodulate, the CPU reference): the first
    // by the order of the candidates that the frame allows, with the plan lines that say
    // why.
    const FrontEnd &Pick(const Frame &frame, const std::string &demodulate,
                         std::vector<std::string> *plan) const;
    // nfor alone on a frame without statistics (--auto-plain nfor, the default), with the
    // plan lines that say why and, where the frame lacks albedo or normals, how to get them;
    // null where auto combines its candidates.
    const FrontEnd *PickWithoutStatistics(const Frame &frame,
                                          std::vector<std::string> *plan) const;
    // Why PickWithoutStatistics does not pick nfor alone on the frame (an option, the
    // frame's statistics, what nfor lacks); "" where it does.
    std::string WhyNotNforAlone(const Frame &frame) const;

    Result Run(vk::Context &context, Inputs &inputs, const RunOptions &run) const override;
    // The widest reach and the largest memory of the candidates the frame allows, plus the
    // combination's: a frame too large for them runs in tiles (not bit for bit: each tile
    // fixes its candidates' frame-wide quantities and its own guide for the estimates).
    TileNeeds Tiling(vk::Context &context, Inputs &inputs) const override;
    std::vector<Stage> Reference(vk::Context &, Inputs &) const override;

    // auto's own parameters (the candidates' are the methods').
    struct Options {
        float budget = 3600;  // seconds
        std::string combine = "relative", noise = "auto", guide = "combined";
        // Measured on the bench frames: power 2 and a 25x25 window; a wider one let one
        // firefly's estimate spoil a wide area of `fireflies`.
        int radius = 12;
        std::string window = "tent";
        float windowBandwidth = 0.2f;
        // The frame's own noise estimate's window, 3x3 (measured: wider ones follow the
        // real variance layers less closely).
        int noiseRadius = 1;
        float power = 2, epsilon = 0.5f, floorError = 1e-5f;
        // bayes's divergence at epsilon 0.5 came out low against smaller steps
        // (docs/methods/auto.md); the other candidates measured best at 0.5.
        float bayesEpsilon = 0.05f;
        // Measured over the bench frames (docs/methods/auto.md): a wide range does alike.
        float noiseLimit = 30;
        // Measured (README): without it a light's edge lost to one dark candidate's small
        // weight (our cornell 4 and 16 spp); 2 to 8 did alike.
        float darkLimit = 4;
        // Where the noise is the frame's own estimate (measured on frames without
        // statistics, docs/methods/auto.md; wider windows and power 2 did worse).
        int frameRadius = 4;
        float framePower = 1;
        // Measured (docs/methods/auto.md): too low lets relief-abc's overshoots hide again,
        // too high lets a light's pixel swamp fireflies.
        float noiseCap = 100;
        // Beside the half-buffers (docs/methods/auto.md, measured on the six accumulated
        // Cycles frames and held out on our scenes with halves): each estimate raised to
        // half1's variance, at most this times their median, and a candidate above
        // halvesDrop times the median over the frame left out.
        float halvesFloor = 0.5f, halvesDrop = 3.5f;
        // Each floor times (the candidate's estimate over the frame / the smallest) ^ this;
        // off: it helped glossy_lights' accumulated frame and cost our interior with halves
        // (docs/methods/auto.md).
        float halvesRank = 0;
        // Beside the half-buffers a method's variants share one candidate's weight (share)
        // or each weighs alone (each): docs/methods/auto.md, the variants round.
        std::string halvesVariants = "share";
        // --auto-power beside the half-buffers (docs/methods/auto.md: 1 and 1.5 helped the
        // accumulated Cycles frames and cost our cornell with halves).
        float halvesPower = 2;
        // The input's local means restored over tents of 8x, then 2x this radius (0: off;
        // host/common/local_mean.h): the relative combination leans dark where the
        // candidates disagree, and relMSE rewards that (issue 29).
        int meanRadius = 16;
        // Beside the half-buffers, the restore kept per window as far as half1 says it
        // lowers the error ("halves"), or whole ("off"; host/common/local_mean.h).
        std::string meanCheck = "halves";
        // Half the radius of the check's tents (at most half --auto-radius).
        int meanCheckRadius = 1;
        // The largest gain that brings the checked restore towards 0.99 of the input's
        // mean before more of the restore does (1: the restore alone). A gain moves no
        // light between pixels; kept within the brightness bound auto is held to.
        float meanGain = 1.02f;
        // Beside the half-buffers, the guard of the local means: standard errors of the
        // colour's mean over tents of meanGuardRadius a candidate's may depart by before it
        // weighs less there (0: off): candidates that blur a small object into its
        // surroundings faded it (issue 29, docs/methods/auto.md).
        float meanGuard = 2;
        int meanGuardRadius = 2;
        // On a frame without statistics, nfor alone or the combination (docs/methods/
        // auto.md: nfor alone beat the combination on the real Cycles frames, with and
        // without albedo and normals).
        std::string plain = "nfor";
        // Where nfor alone moved the frame's mean luminance by over 1% (its firefly clamp
        // took the light of rare bright samples): its output scaled back to the input's
        // mean ("gain") or the candidates combined instead ("combine").
        std::string plainMean = "gain";
        // The candidates' labels, comma-separated, or all.
        std::string candidates = "all";
        // Beside the relative combination on a frame with an objectId layer: each object
        // whose luminance sum fell below objectFloorLevel times the darkest candidate's is
        // brought to that level,
        // "after" or "before" the local-mean restore, or "off" (issue 29,
        // host/methods/auto_object_floor.h).
        std::string objectFloor = "after";
        // The share of the darkest candidate's sum the floor holds an object to.
        float objectFloorLevel = 0.98f;
        // With objectFloor "after": the share of the way from the weighted mean's value to
        // the input's the floor's target takes.
        float objectFloorInput = 0.5f;
        // On a frame with an objectId layer and a variance layer or half-buffers: each
        // object whose output luminance sum is below the input's by more than this many
        // standard errors of the input's sum is scaled up to that bound (0: off; issue 29,
        // host/methods/auto_object_floor.h).
        float objectLift = 3;
        // Beside the half-buffers (objectGuardFrames "halves") or also on a frame with a
        // variance layer alone ("all"), with an objectId layer: before the combination, a
        // candidate whose luminance sum over an object is below the input's by more than
        // this many standard errors of the input's sum (objectGuardSign "dark"; "both":
        // departs from it) weighs less on the object (0: off; issue 29,
        // host/methods/auto_object_floor.h).
        float objectGuard = 3.5f;
        std::string objectGuardSign = "dark";
        std::string objectGuardFrames = "halves";
        // Last, on a frame with an albedo layer: each emitter gives this share of nfor's
        // lights' spread (host/methods/nfor_lights.h) to its 4 neighbours that are no
        // emitter. The combination leans to the candidates that leave a light's rim dark,
        // which few samples hit (0: off; docs/methods/auto.md).
        float lightShare = 0.5f;
        // Beside the half-buffers, with albedo and normals: where the frame is flat and nfor's
        // output is within this share of the combination's, nfor's output, if it holds
        // the combination's light there (0: off; host/methods/auto_flat.h).
        float flatNfor = 0.1f;
        // Last, beside the half-buffers, on a frame with a glint (an albedo channel above
        // kNforGlintAlbedo): nfor's glint bands' pass (host/methods/nfor_band.h) with this
        // many samples each side along each pixel's line. The combination, like nfor's
        // fits, leaves a highlight's band broken (0: off; issue 30, docs/methods/auto.md).
        int glintBandRadius = 3;
        // Last, on a frame with an albedo layer and a known number of samples per pixel:
        // nfor's rim hits (host/methods/nfor_lights.h) on the output, a light's rim pixels
        // that at most this many samples hit brought down to their ground and their light
        // moved into the light's core (0: off; docs/methods/auto.md).
        int rimHits = kNforRimHits;
        // The parameters the user set (not a parameter): auto's settings for the
        // candidates' (MethodEntry::autoSettings) give way; an option that needs another
        // is refused without it.
        std::vector<std::string> given;
    };

  private:
    // The front end of the registry's method `method`, with the user's parameters.
    const FrontEnd &Base(const std::string &method) const;

    std::string name = "auto";
    std::vector<std::unique_ptr<FrontEnd>> methods;  // the registry's, in its order
    std::vector<ParamInfo> infos;
    Options options;
};

// The frame's sample statistics as auto counts them (a variance layer, half-buffers, awr's
// min/max/spp, rhf's histograms): the first found, said ("the frame has variance"), or ""
// where it has none. `awr` and `rhf`: their front ends, which say what a frame lacks.
std::string SampleStatistics(const Frame &frame, const FrontEnd &awr, const FrontEnd &rhf);

}  // namespace mcd::api
