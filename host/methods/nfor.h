// Method `nfor`: feature regression on the GPU. Per pixel a weighted first-order
// regression of the colour on the features (albedo, normal, depth, screen position; the
// pivot where the frame has one) over a window, weights from the colour's NL-means patch
// distance and the features' distances, each window's fit averaged at every pixel it
// holds (Bitterli et al. 2016, NFOR), several bandwidths chosen per pixel by SURE; then a
// second pass weighted by the first's output (the pilot) and the clamped colour's local
// means restored. On a frame without a variance layer the colour's noise is estimated from
// the frame, and so is the features' where they are prefiltered; beside one the firefly
// clamp reads that estimate too (unless it takes off much of the light); emitters are left
// out and keep their input.
// The readings of the papers are listed in cpu_reference/nfor.h, the CPU twin.
#pragma once

#include <string>
#include <vector>

#include "host/image.h"
#include "host/methods/nfor_lights.h"
#include "host/methods/nfor_rare.h"
#include "host/methods/staged_run.h"
#include "host/vk/context.h"
#include "nfor/glint.h"

namespace mcd {

// The glint floor's gate and guard (NforOptions::glintNoise), defined once in nfor/glint.h.
using shader::kNforGlintAlbedo;
using shader::kNforGlintGuardReach;
using shader::kNforGlintReach;

struct NforOptions {
    int radius = 5;  // regression window half-size
    // Each pixel averages the fits of the windows centred at most this far (NFOR: all
    // that hold it, the radius); -1: the radius.
    int gatherRadius = 3;
    int patchRadius = 2;                           // colour patch half-size
    std::vector<float> bandwidths = {0.5f, 1.0f};  // k of each candidate (at most 4)
    float alpha = 1;  // variance cancellation of the colour distance
    // Normalise the colour distance by 2 min(v_p, v_q) (a dark pixel does not borrow from
    // a brighter, noisier one) instead of v_p + v_q (Rousselle et al.'s symmetric form).
    bool minVariance = false;
    // The second pass's distance: -1 as the first's, 0 sum, 1 min (as minVariance).
    int pilotMinVariance = -1;
    // Compare the colour itself in the colour distance; by default colour / albedo where
    // the frame has an albedo (the illumination: texture and edge coverage divide out).
    bool noDemodulatedDistance = false;
    // The demodulated distance compares the colours themselves in a pair with an end whose
    // albedo is noise: its relative variance over 3x3 above this, and dividing by it
    // roughens the colour (glossy metal, whose albedo follows the sampled bounce); 0: every
    // pair compares colour / albedo.
    float albedoNoise = 0.02f;
    // On a frame without a variance layer, where the albedo is noise (albedoNoise's trust 0)
    // within kNforGlintReach of a glint: the weights' noise at least this times the clamped
    // colour's variance over 3x3 (the variance SURE's choice and the pilot's distance read
    // too). The frame's robust estimate reads the misses between a
    // reflected light's hits, so the weights keep hits and gaps as signal. Within
    // kNforGlintGuardReach of a raised pixel each output channel is then at least the clamped
    // colour's minimum over 3x3: the fits, weighing a bright neighbour more, would otherwise
    // undershoot a dark pixel beside a highlight. 0: off.
    float glintNoise = 0.1f;
    float ridge = 0.001f;  // lambda: ridge of lambda sum(w) on the non-constant columns
    // Feature weights: s_j = 1 / (featureBandwidth x the group's sigma); 0: no feature term.
    // The albedo's scale is wide: an edge pixel's albedo, a mix of its two sides, still
    // weighs its neighbours, and the fit's albedo columns follow the texture.
    float featureBandwidth = 3;
    float albedoSigma = 0.3f, normalSigma = 0.2f, depthSigma = 0.05f, pivotSigma = 0.1f;
    int noiseRadius = 1;
    // With a variance layer the firefly clamp reads the frame's own estimate, as without
    // one: a pixel whose few samples hold a firefly reports the firefly's own variance in
    // the layer, and a threshold of sigmas of it clamps nothing. true: it reads the layer.
    bool clampLayer = false;
    // Beside a variance layer, where the clamp against the frame's estimate takes off more
    // than this fraction of the colour's sum, the frame's light is in its rare bright
    // samples (caustics seen through few paths), not in fireflies: it reads the layer.
    float clampLoss = 0.02f;
    // Where the clamp reads the layer, an isolated lone sample's value of it capped at its
    // neighbours' (NforCapLoneSamples): a firefly on a quiet ground is clamped; true: off.
    bool noLoneSampleCap = false;
    // Without a variance layer the clamp reads the frame's estimate and the weights one of
    // the clamped colour in which an edge pixel (too few neighbours divided alike) takes
    // its neighbours' pairs; true: both read the first.
    bool noEdgeNoise = false;
    // The colour's own noise estimates take a direction's mean where its median is 0 (most
    // samples exactly 0: a frame of few samples); true: the median alone.
    bool noSparseNoise = false;
    float noiseCalibration = 1.479f;  // the smallest of 4 medians, unbiased on Gaussian noise
    // Clamp above the neighbours' median + t sigma + relative |median|; t = 0: off.
    float fireflyThreshold = 4, fireflyRelative = 0.5f;
    // Compare with the neighbours' median (0) or their k-th largest (k): a pixel with k - 1
    // bright neighbours is a highlight, kept.
    int fireflyRank = 3;
    // A pixel unlike all its neighbours next to an emitter (a light's edge, partly
    // covered): kept (< 0) or clamped against its neighbours' colours with this relative
    // term in place of fireflyRelative.
    float fireflyLightEdge = -1;
    // Clamp each channel on its own; by default a pixel with two channels or more above
    // their limits is scaled as a whole by the sum of its values clamped one by one over
    // the sum of its values (blended in by the second channel's excess, so nothing jumps),
    // so that a highlight whose channels cross their limits unevenly keeps its hue.
    bool fireflyEachChannel = false;
    // Keep a pixel on a line (along an axis or a diagonal, on both sides within 2 steps, a
    // pixel brighter than this times it): a highlight's streak one or two pixels wide, hit
    // by a few of its samples, is not a firefly. 0: off.
    float fireflyLine = 1;
    // Keep an emitter with no emitter among its neighbours, of this albedo or more, whose
    // colour is within NFOR_LONE_LIGHT_RATIO of its albedo in every channel: a light smaller
    // than a pixel that its samples saw directly, whose value is its own emission, not a
    // firefly. Such a light hit by one of its samples reads many times its share of the
    // pixel; clamped, a light the samples hit often is erased. 0: off (clamped).
    float fireflyLoneLight = 8;
    // A pixel the clamp takes down keeps at least this times its line's brightness (over
    // the axes and diagonals, the largest of the dimmer side's brightest pixel within 2
    // steps), its hue kept: a highlight line hit by few samples has a peak at each hit,
    // which the line rule does not keep. Only within kNforLineFloorReach pixels of an albedo
    // above kNforLineFloorLight (a highlight reflecting a light). 0: off.
    float fireflyLineFloor = 1.5f;
    float emitterAlbedo = 1.5f;
    int prefilterRadius = 1;  // 0: features unfiltered
    int prefilterPatch = 1;
    float prefilterBandwidth = 1;
    int sureRadius = 3;
    // A second pass whose colour distance compares the first pass's output (the pilot)
    // instead of the noisy colour, normalised by the colour's variance and cancelled by
    // pilotAlpha times it, with these bandwidths k (at most 4, chosen per pixel by SURE);
    // empty: one pass.
    std::vector<float> pilotBandwidths = {1.0f};
    float pilotAlpha = 0;
    // > radius: the second pass also fits each bandwidth over windows of this half-size
    // (weighted by the pilot's distance over them), and SURE picks per pixel among all its
    // candidates; 0: one window size.
    int pilotWideRadius = 0;
    // > 0 with one pilot bandwidth and pilotWideRadius: the wide window's fit is taken where
    // its disagreement with the narrow one's, relative to the narrow one's magnitude and
    // averaged over the SURE window, is below this; elsewhere the narrow one's (instead of
    // SURE's choice).
    float wideAgreement = 0;
    // Restore the clamped colour's local means over tents of radius 8, then 2 x this (the
    // fits' bias at scales above the window, host/common/local_mean.h); 0: off.
    int meanRadius = 4;
    // Where no variance layer is read (the noise is the frame's own estimate), or beside one
    // where the clamp reads the frame's own estimate (unless noLayerPasses), with the local
    // means restored: a pixel of the fits' output above (1 + speckRelative) x its
    // speckRank-th brightest neighbour + speckFloor (a speck the fits left: a glint no
    // neighbour saw) is scaled down to that before the restore, which gives the pixels
    // around it what of its light the restore holds for certain
    // (host/methods/nfor_specks.h); speckRelative < 0: off.
    float speckRelative = 0.2f, speckFloor = 0.01f;
    int speckRank = 2;  // a pixel with this many bright neighbours (a line's) is kept
    // On a flat ground (the neighbours' median at least speckFlatShare x the speckRank-th
    // brightest) the bound takes speckFlatRelative in place of speckRelative; 0: off.
    float speckFlatShare = 0.8f, speckFlatRelative = 0.1f;
    // With the local means restored and the specks' passes running: a pixel on an exact
    // ground (its 8 neighbours' colours the same bit for bit and lit, the pixel unlike them
    // and left by the clamp: a light in a mirror under a pixel) keeps its input, and its
    // light stays out of the local means (host/methods/nfor_specks.h); true: fitted.
    bool noExactGround = false;
    // On a frame without a variance layer, or beside one where the clamp reads the frame's
    // own estimate (unless noLayerPasses), a pixel the fits left as it came in (it weighed
    // only itself: a partly covered edge unlike all around it) takes the feature-weighted
    // mean of the output over this radius (host/methods/nfor_kept.h); 0: kept.
    int keptRadius = 0;
    // > 0, where the kept pixels' pass runs (keptRadius): emitters whose largest albedo
    // channel is below this (partly covered: a light's edge, a moving light's streak) take
    // the output's feature-weighted mean over keptRadius (kWeakEmitterRadius where that is
    // 0), their albedo not compared; 0: emitters kept.
    float weakEmitterAlbedo = 8;
    // > 0: a weak emitter on a bright line (on both sides, along an axis or a diagonal within
    // 2 steps, a pixel at least this x as bright, channels' positive parts summed: a glossy
    // highlight's streak) weighs its mean's pixels also by their brightness against its own,
    // a Gaussian of weakEmitterRange in the log (host/methods/nfor_kept.h); 0: off.
    float weakEmitterLine = 0.3f;
    float weakEmitterRange = 0.4f;
    // On a frame with an albedo and without a variance layer read as the noise, or beside one
    // where the clamp reads the frame's own estimate (unless noLayerPasses), last: each
    // emitter gives this share of its output (weak ones, of albedo below weakEmitterAlbedo,
    // the first; the rest the second) to each of its 4 neighbours that is no emitter
    // (host/methods/nfor_lights.h); both 0: off.
    float weakLightShare = 0.08f, lightShare = 0.004f;
    // With an albedo, last, after the lights' spread, on the output as written: the light the
    // firefly clamp took from a line's pixels near a light whose albedo exceeds this, shared
    // along the line and capped by the input's light there (host/methods/nfor_line.h); 0: off.
    float lineSpread = 8;
    // On a frame without a variance layer read as the noise, or beside one where the clamp
    // reads the frame's own estimate (unless noLayerPasses), where the coarse pass does not
    // run, after the local means: the colour's own local means (the light the firefly clamp
    // took) restored over tents of radius 2 x clampLightRadius, then 2 x clampLightFine (0:
    // none), each value's difference its own noise times kClampLightNoise; the clamped
    // colour kept within clampLightReach of an emitter or a partly covered pixel (a light's
    // rim, a silhouette). clampLightRadius 0: off.
    int clampLightRadius = 16, clampLightFine = 2, clampLightReach = 4;
    // Where the clamp's light is restored, after it: this share of the light the firefly
    // clamp took from each pixel it cut to under 1 / rareLightRatio with rareLightOthers more
    // such within rareLightPair (rare bright samples) given to the pixels around it as a
    // Gaussian, away from clampLightReach's pixels (host/methods/nfor_rare.h); 0: off. The
    // method's API sets it on frames without a variance layer only.
    float rareLightShare = 0.4f, rareLightRatio = 40;
    int rareLightPair = NforRareLightSettings{}.pair;
    int rareLightOthers = NforRareLightSettings{}.others;
    // On a frame without a variance layer, last: within kNforGlintReach of a glint (an
    // albedo channel above kNforGlintAlbedo) each pixel that is no emitter moves towards the
    // output's mean along its line, over this many samples each side
    // (host/methods/nfor_band.h); 0: off. The method's API sets it on frames without a
    // variance layer only.
    int glintBandRadius = 3;
    // Where the passes of a frame without a variance layer run, with an albedo, last: the rim
    // hits (host/methods/nfor_lights.h), an emitter whose albedo is at most 1 / rimRatio of
    // its light's core's brought down to its ground, its light moved into the core. The
    // method's API sets rimRatio to the frame's samples per pixel over rimHits (the pixels
    // that at most rimHits samples hit), 0 (off) where the frame states no samples per pixel
    // or rimHits is 0.
    int rimHits = kNforRimHits;
    float rimRatio = 0;
    // Denoise the frame again at half the resolution and give the output the coarse
    // output's low frequencies where they differ by under min(coarseRelative x the
    // output's local magnitude, coarseNoise x its local residual) (host/methods/nfor_coarse.h):
    // on every frame with `coarse`, else on a frame whose noise as relMSE weighs it
    // (NforRelativeNoise of the colour's own estimate) is at least coarseGate (0: never).
    bool coarse = false;
    float coarseRelative = 0.3f, coarseNoise = 0.5f, coarseGate = 0.02f;
    // Where the coarse pass runs (a noisy frame, as its gate reads it, or every frame with
    // `coarse`), the fits' windows take this half-size instead of radius, and the second
    // pass's wide windows no wider than it are left out (NforNoisyOptions); at most radius:
    // radius on every frame.
    int noisyRadius = 10;
    // Beside a variance layer read as the noise, where the firefly clamp reads the frame's
    // own estimate (not the layer: clampLayer, clampLoss), the passes of a frame without a
    // layer run too: the specks' clamp, the clamp's light restored, the weak emitters' mean
    // and the lights' spread (they read no noise, and the clamp they follow is the same);
    // true: only without a layer.
    bool noLayerPasses = false;
    // Beside a variance layer the weights, distances and SURE read min(layer, this x the
    // frame's own estimate of the clamped colour's noise, as without a layer): a pixel whose
    // few samples caught a rare bright path reports that path's variance in the layer,
    // far above what its neighbours say, and the pilot's distance then weighs it with
    // anything. 0 (the default: on our renders' layers the cap cost much): the layer as it
    // is.
    float layerNoiseCap = 0;
    // Beside a variance layer, with a second pass: its distance (not the first's, nor SURE)
    // reads min(the weights' noise, this x the frame's own estimate of the clamped colour's
    // noise): a pixel whose few samples caught a rare bright path reports that path's variance
    // in the layer, and the pilot's distance, normalised by it without cancellation, would
    // weigh it with any neighbour and spread its light into a streak. 0 (the default: on our
    // renders' layers it cost): the weights' noise.
    float pilotNoiseCap = 0;
    // Denoise partly covered pixels as the frame holds them, premultiplied by their alpha;
    // by default divided by it and multiplied back after (host/methods/nfor_alpha.h).
    bool premultiplied = false;
    // Keep every stage's output in NforResult::stages (for `mcdenoise diff`).
    bool keepStages = false;
};

// The weight on each value's noise where the clamp's light is restored
// (NforOptions::clampLightRadius): a lone firefly's light stays out, a shared one comes back.
constexpr double kClampLightNoise = 2;

// The radius of the weak emitters' mean when --kept-radius leaves it at 0.
constexpr int kWeakEmitterRadius = 2;

// The radius of the kept pixels' pass (host/methods/nfor_kept.h) where the passes of a frame
// without a variance layer run or not (`plainPasses`: without a layer, or beside one where
// the clamp reads the frame's own estimate) and with or without an albedo: keptRadius, else
// kWeakEmitterRadius where weak emitters are smoothed (they need the albedo); 0: no pass.
inline int NforKeptPassRadius(const NforOptions &o, bool plainPasses, bool albedo) {
    if (!plainPasses) return 0;
    if (o.keptRadius > 0) return o.keptRadius;
    return o.weakEmitterAlbedo > 0 && albedo ? kWeakEmitterRadius : 0;
}

// Whether the lights' spread runs where the passes of a frame without a variance layer run
// or not (NforKeptPassRadius) and with or without an albedo.
inline bool NforSpreadsLights(const NforOptions &o, bool plainPasses, bool albedo) {
    return plainPasses && albedo && (o.weakLightShare > 0 || o.lightShare > 0);
}

// The frame's layers the method reads; color is required, the rest may be absent.
struct NforInputs {
    const Image *color = nullptr;
    const Image *albedo = nullptr, *normal = nullptr, *depth = nullptr, *pivot = nullptr;
    const Image *variance = nullptr;  // of the pixel mean, as color
    // The divisors of depth and pivot (their means over the frame); 0: this frame's. A
    // tile of a larger frame (host/api/tiled_run.h) passes the whole frame's.
    float depthScale = 0, pivotScale = 0;
    // Beside a variance layer, the fraction of the light the clamp against the frame's own
    // estimate takes off, which decides whether the clamp reads the layer instead
    // (NforOptions::clampLoss), and the same of the coarse pass's half-resolution frame;
    // < 0: this frame's. A tile passes the whole frame's (NforFrameClampLoss), so that
    // every tile decides alike.
    double clampLoss = -1, coarseClampLoss = -1;
    // The frame's relative noise that gates the coarse pass (NforCoarseLevel); < 0: this
    // frame's. A tile passes the whole frame's, so that every tile decides alike.
    double coarseLevel = -1;
    // The coverage (one channel): colour and features of a partly covered pixel
    // premultiplied by it, as on a transparent background (host/methods/nfor_alpha.h);
    // nullptr: none.
    const Image *alpha = nullptr;
    // A pilot from outside (as color): the second pass's distances read it in place of the
    // first pass's output, which is not run; nullptr: the first pass's.
    const Image *pilot = nullptr;
};

// With keepStages, the stages of cpu_reference/nfor.h (variance, mask, color, features,
// distance, k<i>.beta, k<i>.hat, k<i>.output, choice with several candidates; with a
// second pass pilot, pilot.distance and pilot.k<i>.beta, .hat, .output, pilot.choice;
// with the local means restored, fit (before) and with specks clamped, specks (after them);
// with the lights spread, lights (after);
// with partly covered pixels divided by their alpha, straight (before they are multiplied
// back); output).
struct NforResult : MethodResult {
    size_t emitters = 0;       // pixels left out as emitters
    size_t clamped = 0;        // pixel-channels clamped as fireflies
    size_t kept = 0;           // pixels the fits left as they came in, then smoothed
    size_t partlyCovered = 0;  // pixels denoised divided by their alpha
    size_t specks = 0;         // pixels of the fits' output scaled down as specks
    size_t loneSamples = 0;    // isolated lone samples whose layer the clamp read capped
    size_t exactGround = 0;    // pixels on an exact ground that kept their input
    size_t lights = 0;         // emitter pixels that gave their neighbours light
    size_t lineGivers = 0;     // line pixels whose clamped light the line spread shared
    double lineMoved = 0, lineDropped = 0;  // the luminance it shared, and the cap dropped
    // Beside a variance layer: the fraction of the light the estimate's clamp took off, and
    // whether the clamp read the layer after all (NforOptions::clampLoss).
    double clampLoss = 0;
    bool clampOnLayer = false;
    std::vector<double> share;  // per candidate, the fraction of pixels that took it
    // The frame's relative noise the coarse pass's gate read (< 0: not measured) and
    // whether the pass ran.
    double coarseLevel = -1;
    bool coarseRan = false;
};

// The feature planes the regression reads (albedo, normal, depth / its mean, pivot / its
// mean, those the frame has) and each plane's weight s_j.
Image NforFeatures(const NforInputs &inputs, const NforOptions &options,
                   std::vector<float> *weights, std::vector<std::string> *names);

// The means NforFeatures divides depth and pivot by (0 without the layer).
float NforDepthScale(const Image *depth);
float NforPivotScale(const Image *pivot);

// Beside a variance layer (and without NforOptions::clampLayer), sets in->clampLoss and,
// with a coarse pass, in->coarseClampLoss to what a run on the whole frame measures, bit
// for bit: the clamp runs on strips of at most stripPixels (whole rows, at least one) with a
// halo of its reach, so a frame too large to run whole is measured too. Otherwise leaves
// them.
void NforFrameClampLoss(vk::Context &context, NforInputs *in, const NforOptions &options,
                        int stripPixels = 1 << 22);

// The frame's noise as relMSE weighs it: NforRelativeNoise (host/methods/nfor_coarse.h) of
// the colour and its own noise estimate (the firefly clamp's, on strips of at most
// stripPixels as NforFrameClampLoss runs them, so the same bits as on the whole frame);
// in.coarseLevel where that is set.
double NforCoarseLevel(vk::Context &context, const NforInputs &in, const NforOptions &options,
                       int stripPixels = 1 << 22);

// Whether the coarse pass runs on this frame (NforOptions::coarse, coarseGate); `level`,
// when given, receives the level the gate read (< 0 where none was measured; strips as
// NforCoarseLevel's).
bool NforCoarseRuns(vk::Context &context, const NforInputs &in, const NforOptions &options,
                    double *level = nullptr, int stripPixels = 1 << 22);

// `options` as a run on a frame the coarse pass runs on takes them: the windows' half-size
// noisyRadius, and the second pass's wide windows left out where they are no wider.
NforOptions NforNoisyOptions(const NforOptions &options);

// Whether the second pass's colour distance is normalised by 2 min(v_p, v_q).
bool NforPilotMinVariance(const NforOptions &o);

// The glint floor's guard (NforOptions::glintNoise): within kNforGlintGuardReach of a pixel
// where `floored` is above 0, each channel of *output at least the clamped colour's minimum
// over its 3x3 window inside the frame (NaN values neither bound nor are raised). Returns the
// pixel-channels raised. NforDenoise's pass on the host, declared for its test.
size_t GuardGlintFloor(const Image &clamped, const Image &floored, Image *output);

class RunMemo;

// Throws mcd::Error naming the layer and pixel when an input holds NaN/Inf (or a negative
// variance), when shapes differ or options are out of range. With a memo
// (host/methods/run_memo.h) the prefiltered features, which depend on the feature layers
// alone, are taken from an earlier run on the same features or left for later ones (auto's
// run and probe differ in the colour alone): the output is the same bit for bit.
NforResult NforDenoise(vk::Context &context, const NforInputs &inputs,
                       const NforOptions &options, RunMemo *memo = nullptr);

}  // namespace mcd
