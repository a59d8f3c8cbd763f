// Record the feature-regression kernels (shaders/nfor/): one Record function per kernel.
// Images are planar float buffers; every function checks the shapes it is given.
#pragma once

#include <vector>

#include "host/vk/gpu_image.h"
#include "host/vk/recorder.h"

namespace mcd {

// shaders/nfor/noise.comp: the variance of each pixel's mean of `image` estimated from the
// image, divided by `divisor`'s channel (nullptr: none; 1 or >= image's channels); with
// `relaxed`, a pixel with too few pairs divided alike takes its neighbours' pairs divided
// as it is; with `sparse`, a direction whose median is 0 takes its mean (most samples 0).
void RecordNforNoise(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &image,
                     const vk::GpuImage *divisor, int radius, float calibration,
                     vk::GpuImage &variance, bool relaxed = false, bool sparse = false);

// shaders/nfor/clamp.comp: `out` the colour with fireflies clamped, `mask` 0 at emitters;
// rank 0 compares with the neighbours' median, k > 0 with their k-th largest; lightEdge < 0
// keeps a light's edge pixels, >= 0 clamps them with that relative term; sumChannels
// scales a pixel with two channels or more above their limits as a whole, by the sum of
// its clamped values over the sum of its values; line > 0 keeps a pixel on a line brighter
// than line times it (along an axis or a diagonal, within 2 steps on both sides), 0: off;
// loneLight > 0 keeps an emitter with no emitter beside it, of that albedo or more, whose
// colour is within NFOR_LONE_LIGHT_RATIO of its albedo in every channel (a light smaller
// than a pixel, seen directly), 0: off; lineFloor > 0 lets a pixel clamped within
// kNforLineFloorReach pixels of an emitter keep that times its line's brightness
// (shaders/nfor/clamp.h), 0: off.
constexpr int kNforLineFloorReach = 4;  // NFOR_LINE_FLOOR_REACH
void RecordNforClamp(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &color,
                     const vk::GpuImage &variance, const vk::GpuImage *albedo, float threshold,
                     float relative, float emitterAlbedo, int rank, float lightEdge,
                     bool sumChannels, float line, float loneLight, float lineFloor,
                     vk::GpuImage &out, vk::GpuImage &mask);

// shaders/nfor/prefilter.comp: each plane of `features` NL-means-filtered.
void RecordNforPrefilter(vk::Context &context, vk::Recorder &recorder,
                         const vk::GpuImage &features, const vk::GpuImage &variance, int radius,
                         int patch, float bandwidth, vk::GpuImage &out);

// shaders/nfor/trust.comp: per pixel whether the colour distance trusts the albedo (1) or
// not (0: the albedo is rough, its relative variance over 3x3 above `noise`, and dividing by
// it roughens the colour; nfor/trust.h), into `trust` (1 plane). The albedo has 1 channel or
// at least the colour's.
void RecordNforTrust(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &color,
                     const vk::GpuImage &albedo, float noise, vk::GpuImage &trust);

// shaders/nfor/glint_rows.comp: per pixel 1 where some albedo channel above `gate` lies
// within `reach` in its row, else 0, into `near` (1 plane).
void RecordNforGlintRows(vk::Context &context, vk::Recorder &recorder,
                         const vk::GpuImage &albedo, float gate, int reach, vk::GpuImage &near);

// shaders/nfor/glint_rows.comp (RecordNforGlintRows) and glint.comp: where `trust` is 0 and
// some albedo channel above `gate` lies within `reach` (Chebyshev), raises each channel of
// `variance` (in place) to scale x the colour's variance over the 3x3 window inside the frame
// where that is larger (nfor/glint.h); `floored` (1 plane) is 1 where some channel was raised,
// else 0. `near` (1 plane) is the row pass's scratch. The albedo has any channel count.
void RecordNforGlintNoise(vk::Context &context, vk::Recorder &recorder,
                          const vk::GpuImage &color, const vk::GpuImage &albedo,
                          const vk::GpuImage &trust, float gate, int reach, float scale,
                          vk::GpuImage &near, vk::GpuImage &variance, vk::GpuImage &floored);

// shaders/nfor/illumination.comp: per pixel the colour and its variance, each channel
// divided by the albedo's channel (and its square) where that is above the floor
// (nfor/distance.h), into `illumination` (kNforIlluminationFloats planes' worth, per pixel:
// a vec4 of values, a vec4 of variances, zeros past the channels, a vec4 of the divisors, 1
// where not divided, negated where `trust` (RecordNforTrust's, with an albedo) is 0).
void RecordNforIllumination(vk::Context &context, vk::Recorder &recorder,
                            const vk::GpuImage &color, const vk::GpuImage &variance,
                            const vk::GpuImage *albedo, vk::GpuImage &illumination,
                            const vk::GpuImage *trust = nullptr);

// shaders/nfor/term.comp: on the illumination of a colour of `channels`, per pixel and
// stored offset of the window of half-size `radius`, the channels' mean distance term
// (nfor/distance.h) into `terms` (NforOffsetCount(radius) planes' worth, in groups of
// NFOR_TERM_OFFSETS offsets: offset 4g + k of pixel p at float (g * w * h + p) * 4 + k).
void RecordNforTerm(vk::Context &context, vk::Recorder &recorder,
                    const vk::GpuImage &illumination, int channels, int radius, float alpha,
                    bool minVariance, vk::GpuImage &terms);

// shaders/nfor/box.comp: one pass of the patch sum of every offset of `in` (in groups, as
// RecordNforTerm writes them), along rows into `out` in groups; or (`vertical`,
// box_columns.comp) along columns and divided by the patch positions with both ends inside,
// into `out` one plane per offset.
void RecordNforBox(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &in,
                   int radius, int patch, bool vertical, vk::GpuImage &out);

// Illumination, term and both boxes: the patch distance of every stored offset of the
// window of half-size `radius` into `distance` (NforOffsetCount(radius) planes); `scratch`
// is the same size, `illumination` RecordNforIllumination's.
void RecordNforDistance(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &color,
                        const vk::GpuImage &variance, const vk::GpuImage *albedo, int radius,
                        int patch, float alpha, bool minVariance, vk::GpuImage &illumination,
                        vk::GpuImage &scratch, vk::GpuImage &distance,
                        const vk::GpuImage *trust = nullptr);

// RecordNforDistance after its illumination: term and both boxes on `illumination` (of a
// colour of `channels`), for another window on the same colour, variance and albedo.
void RecordNforDistanceOfIllumination(vk::Context &context, vk::Recorder &recorder,
                                      const vk::GpuImage &illumination, int channels,
                                      int radius, int patch, float alpha, bool minVariance,
                                      vk::GpuImage &scratch, vk::GpuImage &distance);

// One candidate of the fit: the window, the bandwidth k, the ridge and the feature weights
// s_j (one per feature plane).
struct NforFitSettings {
    int radius = 7;
    int gatherRadius = 7;  // gather: windows centred at most this far (<= radius)
    float bandwidth = 1;
    float ridge = 0.1f;
    std::vector<float> featureWeights;
};

// Floats per pixel of RecordNforTerm's `illumination`.
constexpr int kNforIlluminationFloats = 12;  // NFOR_ILLUMINATION_FLOATS

// The fits' packed inputs (shaders/nfor/fit.h): floats per pixel of `pack`'s output for
// `features` feature planes, and of the coefficients for `channels` colour channels.
int NforPackedFloats(int features);
int NforBetaStride(int features, int channels);

// What pack writes, made on the CPU (an image of NforPackedFloats(features.channels)
// planes' worth, laid out per pixel).
Image NforPackedOf(const Image &color, const Image &features, const Image &mask);

// shaders/nfor/pack.comp: per pixel the mask, the features and the colour, vec4-aligned,
// into `packed` (NforPackedFloats(features.channels) planes' worth, laid out per pixel).
void RecordNforPack(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &color,
                    const vk::GpuImage &features, const vk::GpuImage &mask,
                    vk::GpuImage &packed);

// shaders/nfor/regress.comp: on `pack`'s output of `features` feature planes (one weight
// each in `settings`) for a colour of `channels`, the fits' coefficients into `beta`
// (NforBetaStride planes' worth, per pixel: column i, channel c at i * channels + c) and their
// influence into plane `hatPlane` of `hat`. With `second` (and `secondBeta`), a candidate
// differing from `settings` in its bandwidth alone fitted in the same pass, into
// `secondBeta` and plane hatPlane + 1: the same values as a pass of its own. The packed
// colour and features must be finite: a step of weight 0 (outside the frame, an emitter) is
// summed as zeros, not skipped.
void RecordNforRegress(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &packed,
                       int features, int channels, const vk::GpuImage &distance,
                       const NforFitSettings &settings, vk::GpuImage &beta, vk::GpuImage &hat,
                       int hatPlane, const NforFitSettings *second = nullptr,
                       vk::GpuImage *secondBeta = nullptr);

// Whether RecordNforRegress can fit `b` as the second candidate of `a`'s pass.
bool NforSameWindow(const NforFitSettings &a, const NforFitSettings &b);

// shaders/nfor/gather.comp: the collaborative average into planes outPlane.. of `out`, on
// `pack`'s output of `features` feature planes; emitters take `input`.
void RecordNforGather(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &input,
                      const vk::GpuImage &packed, int features, const vk::GpuImage &distance,
                      const vk::GpuImage &beta, const NforFitSettings &settings,
                      vk::GpuImage &out, int outPlane);

// The coefficients as planes (column i, channel c at plane i * channels + c: the CPU
// reference's) from regress's per-pixel layout, downloaded as an image of NforBetaStride
// planes, and back.
Image NforBetaPlanes(const Image &perPixel, int features, int channels);
Image NforBetaPerPixel(const Image &planes, int features, int channels);

// shaders/nfor/select.comp: per pixel the candidate (of the first `count`: planes k x
// channels.. of `candidates`, influence at plane k of `hat`) of the smallest box-averaged SURE;
// agreement > 0: the last k > 0 whose box-averaged disagreement with candidate 0 is below it.
void RecordNforSelect(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &color,
                      const vk::GpuImage &variance, const vk::GpuImage &candidates,
                      const vk::GpuImage &hat, int count, int radius, vk::GpuImage &out,
                      vk::GpuImage &choice, float agreement = 0);

// Stored offsets of a window of half-size `radius` (as ref::NforOffsetCount).
int NforOffsetCount(int radius);

}  // namespace mcd
