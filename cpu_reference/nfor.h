// Feature regression (method nfor), the CPU reference: per pixel a weighted first-order
// regression of the colour on the features (Bitterli et al. 2016, "Nonlinearly Weighted
// First-order Regression for Denoising Monte Carlo Renderings", NFOR; Moon, Carr and Yoon
// 2014), weights from the colour's NL-means patch distance (Rousselle, Manzi and Zwicker
// 2013) and the features' distances, the collaborative average of every window's fit at
// a pixel (NFOR 4.3), several bandwidths chosen per pixel by SURE. Written loop by loop in
// double, each stage from its definition (the GPU computes the patch distance with box
// sums and the fits in float).
//
// Readings and departures, shared with the GPU path (host/methods/nfor.h states them too):
// - Frame noise: without a variance layer, the variance of the pixel mean is estimated
//   from the frame (NforNoise): per channel z = colour / albedo where the albedo is above
//   kNoiseAlbedoFloor (else z = colour: the pixel is not divided), per direction d of 4
//   the half squared differences (z_u - z_u+d)^2 / 2 over the (2r+1)^2 window, both pixels
//   divided alike to the pixel (both not, or both by albedos within kNoiseDivisorRatio of
//   its), their median over the median of chi^2_1, the smallest over the directions (the
//   one along an edge) with at least kNforNoiseMinPairs pairs, times the calibration, times
//   the pixel's albedo squared. Where no direction has them (an edge pixel, its albedo a
//   mix unlike all around it), the same over its neighbours' pairs (the pixel in neither:
//   it may be a firefly) both divided where it is (both not where it is not), whatever
//   their albedos, at least kNforNoiseMinRelaxedPairs: the coverage divides out of
//   colour / albedo, so they share the illumination's noise. A median,
//   not a mean: a firefly in the window does not raise its neighbours' estimate, so the
//   colour distance keeps it apart. Only pixels divided alike: a black background next to
//   a wall has no noise to lend it.
// - Fireflies (NforClamp): per channel z = colour / divisor above the median of the z of
//   the pixel's 8 neighbours divided alike + t sqrt(v) / divisor + rho |median| is clamped
//   to it (rho keeps the smooth peaks of noise-free regions, where v = 0). A pixel with no
//   neighbour divided alike (its albedo unlike all around it: a sample that hit a small
//   bright object, or a sub-pixel light) compares its colour with the neighbours' colours,
//   unless a neighbour is an emitter: then it is a light's edge, partly covered, and kept
//   (lightEdge < 0) or compared the same way with lightEdge in place of rho. A pixel on
//   a bright line (line > 0: along an axis or a diagonal, on both sides within 2 steps, a
//   pixel whose channels' mean is above line times its own) is kept whole: a highlight's
//   streak one or two pixels wide, of which the samples hit a few pixels. Beside a
//   variance layer the clamp reads the frame's own estimate too (a pixel whose few samples
//   hold a firefly reports the firefly's variance in the layer), unless that clamp takes off
//   more than clampLoss of the frame's light from at least kNforClampLossMinShare of its
//   values: then the light is in rare bright samples (caustics), and it reads the layer.
// - Emitters: max albedo channel > emitterAlbedo (a reflectance is at most about 1;
//   renderers write a light's emission as its albedo); they are left out of every window
//   and keep their colour as clamped (the issue asks for the input; a lone light pixel hit
//   by a few of its samples kept as it came in made most of a frame's relMSE); with
//   fireflyLoneLight > 0 a lone one whose colour is its albedo's (seen directly) is kept.
// - Features are prefiltered (NFOR 5.1) plane by plane with NL-means on themselves, their
//   variance estimated like the colour's (no divisor).
// - Colour distance (Rousselle et al. 2012/2013, symmetric), of the colour divided by the
//   albedo where that is above the floor (the illumination: texture and the coverage of
//   edge pixels divide out, so that an edge pixel finds its like along the edge): per channel
//   ((C_u - C_u+o)^2 - alpha (v_u + v_u+o)) / (v_u + v_u+o + kRelEps (C_u^2 + C_u+o^2) +
//   kTiny), clamped to at most kTermMax, averaged over the channels and over the patch
//   positions t with both p+t and p+t+o inside; a pair with an end whose albedo is noise
//   (NforAlbedoTrust) compares the colours themselves (the same units at both ends).
//   D(p, o) = D(p+o, -o): the weight of q in
//   p's window is that of p in q's, which the collaborative average needs.
// - Weight of q in p's window: exp(-max(0, D) / k^2 - sum_j (s_j (F_q,j - F_p,j))^2), 1 at
//   q = p, 0 for emitters and where the exponent exceeds kExpCut. NFOR weighs by the colour
//   alone; the feature term with wide bandwidths (s_j small) is Rousselle et al.'s.
// - Regression: columns (1, dx / R, dy / R, F_q - F_p) (prefiltered features), ridge
//   lambda sum(w) on every column but the constant (NFOR uses a pivoted QR instead), the
//   normal equations solved by Cholesky. The fit's value at q, weighted by q's weight in
//   the window, is averaged over every window holding q (NFOR's collaborative filtering).
// - Bandwidth choice: SURE of each candidate, (y - C)^2 - v + 2 v h per channel with h
//   the fit's own influence at its centre ((A^-1)_00), box-averaged over (2 r_s + 1)^2;
//   the candidate with the smallest is taken (ties: the first).
// - Second pass (BM3D's second step; Rousselle et al. 2013 weigh by a prefiltered colour):
//   the first pass's output is the pilot; the colour distance is computed on it as above,
//   with the colour's variance (its own noise is far smaller: alpha pilotAlpha, 0 by
//   default), and the fits run again on the clamped colour with the pilot bandwidths,
//   chosen per pixel by SURE like the first pass's.
// - Local means (beyond the papers; cpu_reference/local_mean.h): the output scaled to the
//   clamped colour's means over tents of radius 8, then 2 meanRadius: the fits' bias at
//   scales above the window goes, the fireflies' energy stays out. The values kept (out of
//   the means, not scaled) are the emitters' (the fits copy them), not those that come out
//   equal to the input.
#pragma once

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "host/image.h"
#include "nfor/glint.h"

namespace mcd::ref {

// The reference's own copies of the numerical constants (shaders/nfor/nfor.h has the GPU's).
constexpr double kNforNoiseAlbedoFloor = 0.02;
constexpr double kNforNoiseDivisorRatio = 1.25;
constexpr double kNforChi2Median = 0.454936423119572;
constexpr size_t kNforNoiseMinPairs = 3;
constexpr size_t kNforNoiseMinRelaxedPairs = 2;
constexpr double kNforRelEps = 1e-4;
constexpr double kNforTiny = 1e-30;
constexpr double kNforTermMax = 25;
constexpr double kNforExpCut = 30;
// The magnitude floor of the select's disagreement (dark pixels compare absolutely).
constexpr double kNforAgreementFloor = 1e-3;
// The albedo trust's margin: colour / albedo rougher than the colour by more than this
// (a window whose colour holds one non-zero value is a tie).
constexpr double kNforTrustTie = 1e-3;
// The glint floor's gate and guard: one definition with the kernels' (nfor/glint.h).
using shader::kNforGlintAlbedo;
using shader::kNforGlintGuardReach;
using shader::kNforGlintReach;
// The clamp's loss counts only where it clamped at least this share of the pixel-channels.
constexpr double kNforClampLossMinShare = 1e-3;

struct NforParams {
    int radius = 5;        // regression window half-size R
    int gatherRadius = 3;  // a pixel averages the fits of windows centred this close
    int patchRadius = 2;   // colour patch half-size
    std::vector<double> bandwidths = {0.5, 1.0};  // k per candidate
    double alpha = 1;                // variance cancellation in the colour distance
    bool minVariance = false;        // the distance normalised by 2 min(v_p, v_q)
    bool pilotMinVariance = false;   // the same for the second pass's distance
    bool demodulateDistance = true;  // the distance of colour / albedo
    // The distance's pairs with an end whose albedo is noise (NforAlbedoTrust with this
    // bound) compare colours; 0: every pair compares colour / albedo.
    double albedoNoise = 0.02;
    // Without a variance layer (edgeNoise), where the trust is 0 within kNforGlintReach of an
    // albedo channel above kNforGlintAlbedo: the variance floored at this times the clamped
    // colour's 3x3 variance (NforGlintNoise), for every later step that reads it; 0: off.
    double glintNoise = 0.1;
    double ridge = 0.001;  // lambda
    // Feature weight per feature plane (s_j); empty: no feature term.
    std::vector<double> featureWeights;
    int noiseRadius = 1;
    double noiseMinCalibration = 1;  // E-correction of the smallest of 4 medians
    // Without a variance layer: the clamp reads the estimate above, the rest the one of
    // the clamped colour with edge pixels relaxed (NforNoise's relaxed).
    bool edgeNoise = true;
    // The colour's estimates: a direction whose median is 0 takes its mean (NforNoise's
    // sparse).
    bool sparseNoise = true;
    // With a variance layer: the clamp reads the frame's estimate above (the layer's
    // fireflies report their own variance), the rest the layer; false: all the layer.
    bool clampEstimate = true;
    // ... unless that clamp takes off more than this fraction of the colour's sum (over
    // every pixel and channel), clamping at least kNforClampLossMinShare of the values:
    // then the layer's.
    double clampLoss = 0.02;
    // Where the clamp reads the layer: its lone samples capped (NforCapLoneSamples,
    // cpu_reference/nfor_specks.h) with these settings; loneReach 0: off.
    double loneHits = 2, loneRatio = 4;
    int loneReach = 0;
    double fireflyThreshold = 4;   // t; 0: no clamp
    double fireflyRelative = 0.5;  // rho
    int fireflyRank = 3;           // 0: the neighbours' lower median; k: their k-th largest
    double fireflyLightEdge = -1;  // a light's edge pixels: kept (< 0) or this rho
    // A pixel with two channels or more above their limits clamped as a whole (each scaled
    // by the clamped channels' sum over the values' sum: the hue stays), blended with the
    // channels clamped alone by the second channel's excess; false: each on its own.
    bool fireflySum = true;
    // > 0: a pixel on a line (a pixel above this times its brightness on both sides along
    // an axis or a diagonal, within 2 steps) is not clamped; 0: off.
    double fireflyLine = 1;
    // > 0: an emitter with no emitter among its 8 neighbours, its largest albedo channel at
    // least this and each colour channel within kNforLoneLightRatio of its albedo's, is not
    // clamped (a light smaller than a pixel seen directly); 0: off.
    double fireflyLoneLight = 0;
    // > 0: a pixel clamped keeps at least this times its line's brightness (the dimmer
    // side's brightest within 2 steps, in the direction where that is largest); 0: off.
    double fireflyLineFloor = 1.5;
    double emitterAlbedo = 1.5;
    int prefilterRadius = 1;  // 0: features as they are
    int prefilterPatch = 1;
    double prefilterBandwidth = 1;
    int sureRadius = 3;
    // Second pass: bandwidths k of the fits weighted by the distance of the first pass's
    // output (the pilot) over the colour's variance, cancelled by pilotAlpha, chosen per
    // pixel by SURE as the first's; empty: none.
    std::vector<double> pilotBandwidths = {1.0};
    double pilotAlpha = 0;
    // > radius: the second pass also fits each pilot bandwidth over windows of this
    // half-size, its distance over them, and SURE picks among all; 0: off.
    int pilotWideRadius = 0;
    // > 0 with one pilot bandwidth and pilotWideRadius: the wide window's fit is taken where
    // its box-averaged disagreement with the narrow one is below this (NforSelect), not by
    // SURE.
    double wideAgreement = 0;
    int meanRadius = 4;  // restore the clamped colour's local means (tent 2r); 0: off
    // With meanRadius and no variance layer, before the restore: specks of the fits' output
    // clamped (NforClampSpecks, cpu_reference/nfor_specks.h); speckRelative < 0: off.
    double speckRelative = -1, speckFloor = 0.01;
    // With the specks: pixels on an exact ground (NforExactGround) keep their clamped colour
    // (their input) and count in no local mean.
    bool exactGround = false;
    int speckRank = 2;
    double speckFlatShare = 0, speckFlatRelative = 0.1;  // NforOptions' speckFlat*
    // Pixels the fits left as they came in: the output's feature-weighted mean over this
    // radius (NforSmoothKept, cpu_reference/nfor_kept.h); 0: kept.
    int keptRadius = 0;
    // > 0: emitters whose largest albedo channel is below it smoothed over keptRadius (2
    // where that is 0), without the albedo's planes.
    double weakEmitterAlbedo = 0;
    // > 0: a weak emitter with, on both sides along an axis or a diagonal within 2 steps, a
    // pixel whose channels' positive parts sum to at least this x its own weighs each q also
    // by exp(-ln((b_q + 0.01) / (b_p + 0.01))^2 / (2 weakEmitterRange^2)), b the channels'
    // positive parts' mean, all on the output before the pass.
    double weakEmitterLine = 0, weakEmitterRange = 0.4;
    // Without a variance layer, with an albedo, last: each emitter gives this share of its
    // output (weak ones, below weakEmitterAlbedo, the first) to each of its 4 neighbours that
    // is no emitter (NforSpreadLights, cpu_reference/nfor_lights.h); both 0: off.
    double weakLightShare = 0, lightShare = 0;
    // With an albedo, last, after the lights' spread, on the output as written: the clamp's
    // light shared along the line near a light of albedo above this (NforSpreadLine,
    // cpu_reference/nfor_line.h, gate reach 4, ratio 3, radius 4); 0: off.
    double lineSpread = 0;
    // Without a variance layer, where the coarse pass does not run, after the restore: the
    // colour's own local means restored at s = clampLightRadius, then clampLightFine (0:
    // none), by RestoreLocalMeanAt (cpu_reference/local_mean.h) with noise weight
    // clampLightNoise, the colour replaced by the clamped one within clampLightReach
    // (Chebyshev) of an emitter or a partly covered pixel; clampLightRadius 0: off.
    int clampLightRadius = 0, clampLightFine = 0, clampLightReach = 4;
    double clampLightNoise = 2;
    // After the clamp's light, where it runs: this share of the light the clamp took from
    // each pixel it cut to under 1 / rareLightRatio with rareLightOthers more within
    // rareLightPair, scattered as a Gaussian of rareLightSigma pixels over rareLightRadius
    // (NforSpreadRareLight, cpu_reference/nfor_rare.h), away from clampLightReach's pixels;
    // 0: off.
    double rareLightShare = 0, rareLightRatio = 40, rareLightSigma = 2;
    int rareLightRadius = 6, rareLightPair = 6, rareLightOthers = 2;
    // Last, on a frame without a variance layer: within kNforGlintReach of a glint, each pixel
    // that is no emitter towards the output's mean along its line, glintBandRadius samples
    // each side, a Gaussian of glintBandSigma, the tensor's of glintBandTensorSigma, samples
    // held within glintBandBound (NforSmoothGlintBands, cpu_reference/nfor_band.h); 0: off.
    int glintBandRadius = 0;
    double glintBandSigma = 1.5, glintBandTensorSigma = 1.5, glintBandBound = 2;
    // Last, where the lights' spread may run (a frame without a variance layer, with an
    // albedo): the rim hits (NforFoldRimHits, cpu_reference/nfor_lights.h), core ratio this,
    // radius 2; 0: off.
    double rimRatio = 0;
    // Beside a variance layer, the specks' clamp, the clamp's light, the weak emitters' mean
    // and the lights' spread run as without one; false: only without one.
    bool layerPasses = true;
    // > 0: beside a variance layer the weights, distances and SURE read min(layer, this x
    // the clamped colour's own estimate, edge pixels relaxed, as without a layer).
    double layerNoiseCap = 0;
    // > 0: beside a variance layer the second pass's distances read min(the weights' noise,
    // this x the clamped colour's own estimate as layerNoiseCap's).
    double pilotNoiseCap = 0;
    // The frame's alpha is not divided by (the values as written); the lights' spread still
    // reads it (its zeros take no part).
    bool premultiplied = false;
    // The frame denoised again at half the resolution (NforHalf of colour, albedo, features
    // and variance), its low frequencies added (NforAddCoarse, cpu_reference/nfor_coarse.h):
    // with `coarse` always, else where NforRelativeNoise of the colour and its own noise
    // estimate is at least coarseGate (> 0).
    bool coarse = false;
    double coarseRelative = 0.3, coarseNoise = 0.5, coarseGate = 0.02;
    // Where the coarse pass runs and noisyRadius exceeds radius: the whole run with radius
    // noisyRadius, gatherRadius noisyGatherRadius, pilotWideRadius 0 where it is no larger.
    int noisyRadius = 0, noisyGatherRadius = 0;
};

// The frame's layers; color and features are required, variance optional (estimated).
struct NforInputs {
    const Image *color = nullptr;
    const Image *albedo = nullptr;    // divisor for the noise and clamp; emitter test
    const Image *features = nullptr;  // the regression's feature planes, scaled
    const Image *variance = nullptr;  // of the pixel mean, as color
    // Coverage: each pixel of alpha in [1e-3, 1) has colour, albedo, features divided by it
    // (variance by its square) before the rest, the output multiplied by it after
    // (cpu_reference/nfor_alpha.h); nullptr: none.
    const Image *alpha = nullptr;
    // With pilot bandwidths, the second pass's pilot (as color) in place of the first
    // pass's output, which is then not run; nullptr: the first pass's.
    const Image *pilot = nullptr;
};

// Variance of the pixel mean estimated from `image` (divisor: albedo or nullptr).
// relaxed: a pixel with too few pairs divided alike takes its neighbours' pairs divided as
// it is. sparse: a direction whose median half squared difference is 0 (at least half its
// pairs equal: most samples exactly 0) takes the mean of its half squared differences.
Image NforNoise(const Image &image, const Image *divisor, int radius, double calibration,
                bool relaxed = false, bool sparse = false);

// 1 for pixels that take part, 0 for emitters.
Image NforMask(const Image *albedo, int width, int height, double emitterAlbedo);

// The colour with fireflies clamped; with sumChannels a pixel whose channels are clamped
// to r_c = clamped / value takes t = 1 - (the second smallest r_c) of itself scaled by the
// sum of its values clamped one by one over the sum of its values, 1 - t of each channel
// clamped alone. With loneLight > 0 a lone light seen directly (kNforLoneLightRatio) is kept.
// With lineFloor > 0 a pixel not kept keeps at least min(1, lineFloor x S / B) of each
// positive channel (B its line brightness, S the brightest line through it: LineSupport).
constexpr double kNforLoneLightRatio = 1.25;
// The line's floor holds within this many pixels of an albedo channel above the light's.
constexpr int kNforLineFloorReach = 4;
constexpr double kNforLineFloorLight = 8;
Image NforClamp(const Image &color, const Image &variance, const Image *divisor,
                const Image &mask, double threshold, double relative, int rank = 0,
                double lightEdge = -1, bool sumChannels = false, double line = 0,
                double loneLight = 0, double lineFloor = 0);

// Each feature plane NL-means-filtered with its own variance.
Image NforPrefilter(const Image &features, const Image &variance, int radius, int patch,
                    double bandwidth);

// Where the colour distance trusts the albedo (1) or not (0), per pixel: over the pixel's
// 3x3 window inside the frame, albedos taken at least kNforNoiseAlbedoFloor and colour
// channel c read against albedo channel min(c, its channels - 1), the relative roughness (the
// channels' sum of the window's variance over the sum of its squared means) of the albedo,
// of the colour and of colour / albedo; not trusted where the albedo's is above `noise` and
// colour / albedo is rougher than the colour by more than kNforTrustTie (the albedo is noise,
// as on glossy metal whose albedo follows the sampled bounce, not texture the colour follows).
Image NforAlbedoTrust(const Image &color, const Image &albedo, double noise);

// The weights' noise floored near a glint, per pixel: where `trust` is 0 and some albedo
// channel above `gate` lies within `reach` (Chebyshev, inside the frame), each channel of
// `variance` becomes scale x the colour's variance over the 3x3 window inside the frame
// (mean squared deviation from the window's mean, in float) where that is larger; a NaN on
// either side keeps the variance. Returns 1 where some channel was raised, else 0.
Image NforGlintNoise(const Image &color, const Image &albedo, const Image &trust, double gate,
                     int reach, double scale, Image *variance);

// The glint floor's guard: each pixel with a pixel of `raised` above 0 in its square of
// half-side kNforGlintGuardReach (inside the frame) has each channel of *out at least the
// minimum of the clamped colour's 3x3 window inside the frame (a NaN neither bounds nor is
// raised; an infinite minimum raises nothing).
void GuardGlint(const Image &clamped, const Image &raised, Image *out);

// The floor's row marks, per pixel: 1 where some albedo channel above `gate` lies within
// `reach` pixels in the same row (inside the frame), else 0.
Image NforGlintRows(const Image &albedo, double gate, int reach);

// Patch distance D(p, o) for the stored offsets (NforOffset), one plane each, of the colour
// (divisor nullptr) or of colour / divisor where the divisor is above the floor; with a trust
// image (NforAlbedoTrust), a pair with an end not trusted compares the colours themselves.
Image NforDistance(const Image &color, const Image &variance, const Image *divisor, int radius,
                   int patch, double alpha, bool minVariance, const Image *trust = nullptr);

// The distance's two steps as the GPU takes them (for the kernels' own tests): per pixel u
// and stored offset o, the channels' mean term of u and u + o (0 where u + o is outside);
// and one pass of the patch sum over those, along rows, or along columns divided by the
// number of patch positions with both ends inside (`vertical`).
Image NforTerms(const Image &color, const Image &variance, const Image *divisor, int radius,
                double alpha, bool minVariance, const Image *trust = nullptr);
Image NforBoxPass(const Image &terms, int radius, int patch, bool vertical);

// Stored offset j of the window of radius R: (ox, oy) with oy > 0, or oy = 0 and ox > 0,
// in raster order; NforOffsetCount(R) of them.
int NforOffsetCount(int radius);
void NforOffset(int radius, int j, int *ox, int *oy);

// One candidate's fits: beta planes (column i, channel c at plane i * channels + c) and
// the centre's influence h.
struct NforFit {
    Image beta, hat;
};

struct NforCandidate {
    double bandwidth;
    const std::vector<double> *featureWeights;
    double ridge;
    int radius;
    int gatherRadius;  // NforGather: windows centred at most this far
};

NforFit NforRegress(const Image &color, const Image &features, const Image &mask,
                    const Image &distance, const NforCandidate &candidate);

// The collaborative average of the fits; emitters take `input` (the clamped colour).
Image NforGather(const Image &input, const Image &features, const Image &mask,
                 const Image &distance, const NforFit &fit, const NforCandidate &candidate);

// Per pixel the candidate of smallest box-averaged SURE; also the index chosen (1 plane).
// With agreement > 0 instead the last candidate k > 0 whose box-averaged disagreement with
// candidate 0 (the channels' mean of (y_k - y_0)^2 over (the channels' mean of y_0)^2 +
// a floor) is below agreement, else candidate 0.
Image NforSelect(const std::vector<Image> &outputs, const std::vector<Image> &hats,
                 const Image &color, const Image &variance, int sureRadius, Image *choice,
                 double agreement = 0);

// The whole method with its named stages (mask, color, clamp.variance where estimated
// with edgeNoise, variance, features, distance,
// k<i>.beta, k<i>.hat, k<i>.output, choice with several bandwidths; with a second pass
// pilot, pilot.distance, pilot.k<i>.beta, .hat, .output, pilot.choice; with meanRadius,
// fit; with speckRelative >= 0, specks; with keptRadius, unkept; with coarse, coarse; with
// the lights spread, lights; with partly covered pixels, straight; output).
Image Nfor(const NforInputs &inputs, const NforParams &params,
           std::vector<std::pair<std::string, Image>> *stages);

}  // namespace mcd::ref
