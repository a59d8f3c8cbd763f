#include "host/kernels/nfor_kernels.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "host/error.h"
#include "host/vk/context.h"
#include "host/vk/kernel.h"
#include "nfor/box_columns_spv.h"
#include "nfor/box_spv.h"
#include "nfor/clamp.h"
#include "nfor/clamp_spv.h"
#include "nfor/distance.h"
#include "nfor/fit.h"
#include "nfor/gather_spv.h"
#include "nfor/glint.h"
#include "nfor/glint_rows_spv.h"
#include "nfor/glint_spv.h"
#include "nfor/illumination_spv.h"
#include "nfor/noise.h"
#include "nfor/noise_spv.h"
#include "nfor/pack_spv.h"
#include "nfor/prefilter.h"
#include "nfor/prefilter_spv.h"
#include "nfor/regress_spv.h"
#include "nfor/select.h"
#include "nfor/select_spv.h"
#include "nfor/term_spv.h"
#include "nfor/trust.h"
#include "nfor/trust_spv.h"

namespace mcd {
namespace {

void CheckSize(const char *what, const vk::GpuImage &a, const vk::GpuImage &b, int channels) {
    if (b.width != a.width || b.height != a.height || (channels > 0 && b.channels != channels))
        throw Error(fmt::format("{}: {} is {}x{}x{}, expected {}x{}x{}", what, b.buffer.Name(),
                                b.width, b.height, b.channels, a.width, a.height,
                                channels > 0 ? channels : b.channels),
                    ErrorKind::InvalidArgument);
}

void CheckColor(const char *what, const vk::GpuImage &color) {
    if (color.channels < 1 || color.channels > NFOR_MAX_CHANNELS)
        throw Error(fmt::format("{}: {} channels; 1 to {} are supported", what, color.channels,
                                NFOR_MAX_CHANNELS),
                    ErrorKind::InvalidArgument);
}

uint32_t Groups(int width) {
    return uint32_t((width + NFOR_LOCAL_SIZE - 1) / NFOR_LOCAL_SIZE);
}

}  // namespace

int NforOffsetCount(int radius) {
    int side = 2 * radius + 1;
    return (side * side - 1) / 2;
}

void RecordNforNoise(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &image,
                     const vk::GpuImage *divisor, int radius, float calibration,
                     vk::GpuImage &variance, bool relaxed, bool sparse) {
    CheckSize("nfor noise", image, variance, image.channels);
    if (divisor) {
        CheckSize("nfor noise", image, *divisor, 0);
        if (divisor->channels != 1 && divisor->channels < image.channels)
            throw Error("nfor noise: the divisor needs 1 channel or as many as the image",
                        ErrorKind::InvalidArgument);
    }
    if (radius < 1 || radius > NFOR_NOISE_MAX_RADIUS)
        throw Error(
            fmt::format("nfor noise: radius {}; 1..{} allowed", radius, NFOR_NOISE_MAX_RADIUS),
            ErrorKind::InvalidArgument);
    const vk::Kernel &kernel =
        context.GetKernel({"nfor_noise",
                           k_nfor_noise_spv,
                           sizeof(k_nfor_noise_spv),
                           NFOR_NOISE_BINDINGS,
                           sizeof(shader::NforNoisePush),
                           {},
                           (1u << NFOR_NOISE_IMAGE) | (1u << NFOR_NOISE_DIVISOR),
                           0});
    shader::NforNoisePush push{image.width,   image.height, divisor ? divisor->channels : 0,
                               radius,        calibration,  relaxed ? 1 : 0,
                               sparse ? 1 : 0};
    recorder.Dispatch(
        kernel, "nfor.noise",
        {{NFOR_NOISE_IMAGE, &image.buffer, vk::Access::Read},
         {NFOR_NOISE_DIVISOR, divisor ? &divisor->buffer : &image.buffer, vk::Access::Read},
         {NFOR_NOISE_OUTPUT, &variance.buffer, vk::Access::Write}},
        push, Groups(image.width), uint32_t(image.height), uint32_t(image.channels));
}

static_assert(kNforLineFloorReach == NFOR_LINE_FLOOR_REACH);
static_assert(kNforIlluminationFloats == NFOR_ILLUMINATION_FLOATS);
// Every window's stored offsets, 2R(R + 1), fill whole invocations of `term`.
static_assert(4 % NFOR_TERM_OFFSETS == 0);

void RecordNforClamp(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &color,
                     const vk::GpuImage &variance, const vk::GpuImage *albedo, float threshold,
                     float relative, float emitterAlbedo, int rank, float lightEdge,
                     bool sumChannels, float line, float loneLight, float lineFloor,
                     vk::GpuImage &out, vk::GpuImage &mask) {
    CheckColor("nfor clamp", color);
    CheckSize("nfor clamp", color, variance, color.channels);
    CheckSize("nfor clamp", color, out, color.channels);
    CheckSize("nfor clamp", color, mask, 1);
    if (albedo) {
        CheckSize("nfor clamp", color, *albedo, 0);
        if (albedo->channels != 1 && albedo->channels < color.channels)
            throw Error("nfor clamp: the albedo needs 1 channel or as many as the colour",
                        ErrorKind::InvalidArgument);
    }
    const vk::Kernel &kernel = context.GetKernel({"nfor_clamp",
                                                  k_nfor_clamp_spv,
                                                  sizeof(k_nfor_clamp_spv),
                                                  NFOR_CLAMP_BINDINGS,
                                                  sizeof(shader::NforClampPush),
                                                  {},
                                                  0,
                                                  0});
    shader::NforClampPush push{color.width,
                               color.height,
                               albedo ? albedo->channels : 0,
                               threshold,
                               relative,
                               emitterAlbedo,
                               rank,
                               lightEdge,
                               color.channels,
                               sumChannels ? 1 : 0,
                               line,
                               loneLight,
                               lineFloor};
    recorder.Dispatch(
        kernel, "nfor.clamp",
        {{NFOR_CLAMP_COLOR, &color.buffer, vk::Access::Read},
         {NFOR_CLAMP_VARIANCE, &variance.buffer, vk::Access::Read},
         {NFOR_CLAMP_ALBEDO, albedo ? &albedo->buffer : &color.buffer, vk::Access::Read},
         {NFOR_CLAMP_OUT, &out.buffer, vk::Access::Write},
         {NFOR_CLAMP_MASK, &mask.buffer, vk::Access::Write}},
        push, Groups(color.width), uint32_t(color.height), 1);
}

void RecordNforPrefilter(vk::Context &context, vk::Recorder &recorder,
                         const vk::GpuImage &features, const vk::GpuImage &variance, int radius,
                         int patch, float bandwidth, vk::GpuImage &out) {
    CheckSize("nfor prefilter", features, variance, features.channels);
    CheckSize("nfor prefilter", features, out, features.channels);
    if (radius < 1 || radius > NFOR_PREFILTER_MAX_RADIUS || patch < 0 ||
        patch > NFOR_PREFILTER_MAX_PATCH || !(bandwidth > 0))
        throw Error(fmt::format("nfor prefilter: radius {} (1..{}), patch {} (0..{}), "
                                "bandwidth {} (> 0)",
                                radius, NFOR_PREFILTER_MAX_RADIUS, patch,
                                NFOR_PREFILTER_MAX_PATCH, bandwidth),
                    ErrorKind::InvalidArgument);
    const vk::Kernel &kernel =
        context.GetKernel({"nfor_prefilter",
                           k_nfor_prefilter_spv,
                           sizeof(k_nfor_prefilter_spv),
                           NFOR_PREFILTER_BINDINGS,
                           sizeof(shader::NforPrefilterPush),
                           {},
                           (1u << NFOR_PREFILTER_FEATURES) | (1u << NFOR_PREFILTER_VARIANCE),
                           0});
    shader::NforPrefilterPush push{features.width, features.height, radius, patch, bandwidth};
    recorder.Dispatch(kernel, "nfor.prefilter",
                      {{NFOR_PREFILTER_FEATURES, &features.buffer, vk::Access::Read},
                       {NFOR_PREFILTER_VARIANCE, &variance.buffer, vk::Access::Read},
                       {NFOR_PREFILTER_OUT, &out.buffer, vk::Access::Write}},
                      push, Groups(features.width), uint32_t(features.height),
                      uint32_t(features.channels));
}

namespace {

const vk::Kernel &TermKernel(vk::Context &context, int channels) {
    return context.GetKernel({"nfor_term",
                              k_nfor_term_spv,
                              sizeof(k_nfor_term_spv),
                              NFOR_TERM_BINDINGS,
                              sizeof(shader::NforDistancePush),
                              {{NFOR_SPEC_CHANNELS, channels}},
                              1u << NFOR_TERM_ILLUMINATION,
                              1u << NFOR_TERM_ILLUMINATION});
}

const vk::Kernel &IlluminationKernel(vk::Context &context, int channels) {
    return context.GetKernel({"nfor_illumination",
                              k_nfor_illumination_spv,
                              sizeof(k_nfor_illumination_spv),
                              NFOR_ILLUMINATION_BINDINGS,
                              sizeof(shader::NforDistancePush),
                              {{NFOR_SPEC_CHANNELS, channels}},
                              0,
                              0});
}

const vk::Kernel &TrustKernel(vk::Context &context, int channels) {
    return context.GetKernel({"nfor_trust",
                              k_nfor_trust_spv,
                              sizeof(k_nfor_trust_spv),
                              NFOR_TRUST_BINDINGS,
                              sizeof(shader::NforTrustPush),
                              {{NFOR_SPEC_CHANNELS, channels}},
                              0,
                              0});
}

// The row pass (box.comp) or the column pass (box_columns.comp); both read vec4 groups.
const vk::Kernel &BoxKernel(vk::Context &context, bool vertical) {
    const char *name = vertical ? "nfor_box_columns" : "nfor_box";
    const uint32_t *spirv = vertical ? k_nfor_box_columns_spv : k_nfor_box_spv;
    size_t bytes = vertical ? sizeof(k_nfor_box_columns_spv) : sizeof(k_nfor_box_spv);
    return context.GetKernel({name,
                              spirv,
                              bytes,
                              NFOR_BOX_BINDINGS,
                              sizeof(shader::NforDistancePush),
                              {},
                              1u << NFOR_BOX_IN,
                              1u << NFOR_BOX_IN});
}

void CheckOffsets(const char *what, int radius, int patch) {
    if (radius < 1 || radius > NFOR_MAX_RADIUS || patch < 0 || patch > NFOR_MAX_PATCH)
        throw Error(fmt::format("{}: radius {} (1..{}), patch {} (0..{})", what, radius,
                                NFOR_MAX_RADIUS, patch, NFOR_MAX_PATCH),
                    ErrorKind::InvalidArgument);
}

}  // namespace

void RecordNforTrust(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &color,
                     const vk::GpuImage &albedo, float noise, vk::GpuImage &trust) {
    CheckColor("nfor trust", color);
    CheckSize("nfor trust", color, albedo, 0);
    CheckSize("nfor trust", color, trust, 1);
    if (albedo.channels != 1 && albedo.channels < color.channels)
        throw Error("nfor trust: the albedo needs 1 channel or as many as the colour",
                    ErrorKind::InvalidArgument);
    if (!(noise >= 0) || !std::isfinite(noise))
        throw Error(fmt::format("nfor trust: noise {} must be finite and >= 0", noise),
                    ErrorKind::InvalidArgument);
    shader::NforTrustPush push{color.width, color.height, albedo.channels, noise};
    recorder.Dispatch(TrustKernel(context, color.channels), "nfor.trust",
                      {{NFOR_TRUST_COLOR, &color.buffer, vk::Access::Read},
                       {NFOR_TRUST_ALBEDO, &albedo.buffer, vk::Access::Read},
                       {NFOR_TRUST_OUT, &trust.buffer, vk::Access::Write}},
                      push, Groups(color.width), uint32_t(color.height));
}

namespace {

void CheckGlintGate(float gate, int reach) {
    if (reach < 0 || reach > NFOR_GLINT_MAX_REACH || !std::isfinite(gate))
        throw Error(fmt::format("nfor glint: reach {} (0..{}) or gate {} (finite) out of range",
                                reach, NFOR_GLINT_MAX_REACH, gate),
                    ErrorKind::InvalidArgument);
}

}  // namespace

void RecordNforGlintRows(vk::Context &context, vk::Recorder &recorder,
                         const vk::GpuImage &albedo, float gate, int reach,
                         vk::GpuImage &near) {
    CheckSize("nfor glint rows", albedo, near, 1);
    CheckGlintGate(gate, reach);
    shader::NforGlintPush push{albedo.width, albedo.height, albedo.channels, reach, gate, 0};
    const vk::Kernel &rows = context.GetKernel({"nfor_glint_rows",
                                                k_nfor_glint_rows_spv,
                                                sizeof(k_nfor_glint_rows_spv),
                                                NFOR_GLINT_ROWS_BINDINGS,
                                                sizeof(shader::NforGlintPush),
                                                {},
                                                0,
                                                0});
    recorder.Dispatch(rows, "nfor.glint.rows",
                      {{NFOR_GLINT_ROWS_ALBEDO, &albedo.buffer, vk::Access::Read},
                       {NFOR_GLINT_ROWS_NEAR, &near.buffer, vk::Access::Write}},
                      push, Groups(albedo.width), uint32_t(albedo.height));
}

void RecordNforGlintNoise(vk::Context &context, vk::Recorder &recorder,
                          const vk::GpuImage &color, const vk::GpuImage &albedo,
                          const vk::GpuImage &trust, float gate, int reach, float scale,
                          vk::GpuImage &near, vk::GpuImage &variance, vk::GpuImage &floored) {
    CheckColor("nfor glint noise", color);
    CheckSize("nfor glint noise", color, albedo, 0);
    CheckSize("nfor glint noise", color, trust, 1);
    CheckSize("nfor glint noise", color, near, 1);
    CheckSize("nfor glint noise", color, variance, color.channels);
    CheckSize("nfor glint noise", color, floored, 1);
    CheckGlintGate(gate, reach);
    if (!(scale >= 0) || !std::isfinite(scale))
        throw Error(fmt::format("nfor glint noise: scale {} must be finite and >= 0", scale),
                    ErrorKind::InvalidArgument);
    RecordNforGlintRows(context, recorder, albedo, gate, reach, near);
    shader::NforGlintPush push{color.width, color.height, albedo.channels, reach, gate, scale};
    const vk::Kernel &floor = context.GetKernel({"nfor_glint",
                                                 k_nfor_glint_spv,
                                                 sizeof(k_nfor_glint_spv),
                                                 NFOR_GLINT_BINDINGS,
                                                 sizeof(shader::NforGlintPush),
                                                 {{NFOR_SPEC_CHANNELS, color.channels}},
                                                 0,
                                                 0});
    recorder.Dispatch(floor, "nfor.glint",
                      {{NFOR_GLINT_NEAR, &near.buffer, vk::Access::Read},
                       {NFOR_GLINT_COLOR, &color.buffer, vk::Access::Read},
                       {NFOR_GLINT_TRUST, &trust.buffer, vk::Access::Read},
                       {NFOR_GLINT_VARIANCE, &variance.buffer, vk::Access::ReadWrite},
                       {NFOR_GLINT_FLOORED, &floored.buffer, vk::Access::Write}},
                      push, Groups(color.width), uint32_t(color.height));
}

void RecordNforIllumination(vk::Context &context, vk::Recorder &recorder,
                            const vk::GpuImage &color, const vk::GpuImage &variance,
                            const vk::GpuImage *albedo, vk::GpuImage &illumination,
                            const vk::GpuImage *trust) {
    CheckColor("nfor illumination", color);
    CheckSize("nfor illumination", color, variance, color.channels);
    CheckSize("nfor illumination", color, illumination, NFOR_ILLUMINATION_FLOATS);
    if (albedo) {
        CheckSize("nfor illumination", color, *albedo, 0);
        if (albedo->channels != 1 && albedo->channels < color.channels)
            throw Error(
                "nfor illumination: the albedo needs 1 channel or as many as the colour",
                ErrorKind::InvalidArgument);
    }
    if (albedo && trust) CheckSize("nfor illumination", color, *trust, 1);
    shader::NforDistancePush push{
        color.width, color.height,           0, 0, 0, 0, albedo ? albedo->channels : 0,
        0,           albedo && trust ? 1 : 0};
    recorder.Dispatch(
        IlluminationKernel(context, color.channels), "nfor.illumination",
        {{NFOR_ILLUMINATION_COLOR, &color.buffer, vk::Access::Read},
         {NFOR_ILLUMINATION_VARIANCE, &variance.buffer, vk::Access::Read},
         {NFOR_ILLUMINATION_ALBEDO, albedo ? &albedo->buffer : &color.buffer, vk::Access::Read},
         {NFOR_ILLUMINATION_OUT, &illumination.buffer, vk::Access::Write},
         {NFOR_ILLUMINATION_TRUST, albedo && trust ? &trust->buffer : &color.buffer,
          vk::Access::Read}},
        push, Groups(color.width), uint32_t(color.height));
}

void RecordNforTerm(vk::Context &context, vk::Recorder &recorder,
                    const vk::GpuImage &illumination, int channels, int radius, float alpha,
                    bool minVariance, vk::GpuImage &terms) {
    if (channels < 1 || channels > NFOR_MAX_CHANNELS)
        throw Error(fmt::format("nfor term: {} channels; 1 to {} are supported", channels,
                                NFOR_MAX_CHANNELS),
                    ErrorKind::InvalidArgument);
    CheckSize("nfor term", illumination, illumination, NFOR_ILLUMINATION_FLOATS);
    CheckSize("nfor term", illumination, terms, NforOffsetCount(radius));
    CheckOffsets("nfor term", radius, 0);
    shader::NforDistancePush push{illumination.width,
                                  illumination.height,
                                  radius,
                                  0,
                                  0,
                                  alpha,
                                  0,
                                  minVariance ? 1 : 0,
                                  0};
    recorder.Dispatch(TermKernel(context, channels), "nfor.term",
                      {{NFOR_TERM_ILLUMINATION, &illumination.buffer, vk::Access::Read},
                       {NFOR_TERM_OUT, &terms.buffer, vk::Access::Write}},
                      push, Groups(illumination.width), uint32_t(illumination.height),
                      uint32_t(terms.channels / NFOR_TERM_OFFSETS));
}

void RecordNforBox(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &in,
                   int radius, int patch, bool vertical, vk::GpuImage &out) {
    CheckSize("nfor box", in, in, NforOffsetCount(radius));
    CheckSize("nfor box", in, out, in.channels);
    CheckOffsets("nfor box", radius, patch);
    shader::NforDistancePush push{in.width, in.height, radius, patch, vertical ? 1 : 0,
                                  0,        0,         0,      0};
    // One invocation per block of NFOR_BOX_BLOCK outputs along the pass's axis and group of
    // NFOR_TERM_OFFSETS planes.
    int blocksX = vertical ? in.width : (in.width + NFOR_BOX_BLOCK - 1) / NFOR_BOX_BLOCK;
    int blocksY = vertical ? (in.height + NFOR_BOX_BLOCK - 1) / NFOR_BOX_BLOCK : in.height;
    recorder.Dispatch(BoxKernel(context, vertical), "nfor.box",
                      {{NFOR_BOX_IN, &in.buffer, vk::Access::Read},
                       {NFOR_BOX_OUT, &out.buffer, vk::Access::Write}},
                      push, Groups(blocksX), uint32_t(blocksY),
                      uint32_t(in.channels / NFOR_TERM_OFFSETS));
}

void RecordNforDistance(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &color,
                        const vk::GpuImage &variance, const vk::GpuImage *albedo, int radius,
                        int patch, float alpha, bool minVariance, vk::GpuImage &illumination,
                        vk::GpuImage &scratch, vk::GpuImage &distance,
                        const vk::GpuImage *trust) {
    CheckSize("nfor distance", color, scratch, NforOffsetCount(radius));
    CheckOffsets("nfor distance", radius, patch);
    RecordNforIllumination(context, recorder, color, variance, albedo, illumination, trust);
    RecordNforDistanceOfIllumination(context, recorder, illumination, color.channels, radius,
                                     patch, alpha, minVariance, scratch, distance);
}

void RecordNforDistanceOfIllumination(vk::Context &context, vk::Recorder &recorder,
                                      const vk::GpuImage &illumination, int channels,
                                      int radius, int patch, float alpha, bool minVariance,
                                      vk::GpuImage &scratch, vk::GpuImage &distance) {
    CheckSize("nfor distance", illumination, scratch, NforOffsetCount(radius));
    CheckOffsets("nfor distance", radius, patch);
    RecordNforTerm(context, recorder, illumination, channels, radius, alpha, minVariance,
                   distance);
    RecordNforBox(context, recorder, distance, radius, patch, false, scratch);
    RecordNforBox(context, recorder, scratch, radius, patch, true, distance);
}

namespace {

void CheckFit(const char *what, const vk::GpuImage &packed, int features, int channels,
              const vk::GpuImage &distance, const NforFitSettings &settings) {
    if (channels < 1 || channels > NFOR_MAX_CHANNELS)
        throw Error(fmt::format("{}: {} channels; 1 to {} are supported", what, channels,
                                NFOR_MAX_CHANNELS),
                    ErrorKind::InvalidArgument);
    // The packed size is the same for several feature counts: check the count itself.
    if (int(settings.featureWeights.size()) != features)
        throw Error(fmt::format("{}: {} feature weights for {} feature planes", what,
                                settings.featureWeights.size(), features),
                    ErrorKind::InvalidArgument);
    if (features < 0 || features > NFOR_MAX_FEATURES)
        throw Error(
            fmt::format("{}: {} features; at most {}", what, features, NFOR_MAX_FEATURES),
            ErrorKind::InvalidArgument);
    CheckSize(what, packed, packed, NforPackedFloats(features));
    if (settings.radius < 1 || settings.radius > NFOR_MAX_RADIUS)
        throw Error(
            fmt::format("{}: radius {}; 1..{} allowed", what, settings.radius, NFOR_MAX_RADIUS),
            ErrorKind::InvalidArgument);
    CheckSize(what, packed, distance, NforOffsetCount(settings.radius));
    if (settings.gatherRadius < 0 || settings.gatherRadius > settings.radius)
        throw Error(fmt::format("{}: gather radius {}; 0..{} allowed", what,
                                settings.gatherRadius, settings.radius),
                    ErrorKind::InvalidArgument);
    if (!(settings.bandwidth > 0) || !(settings.ridge >= 0))
        throw Error(fmt::format("{}: bandwidth {} must be > 0 and ridge {} >= 0", what,
                                settings.bandwidth, settings.ridge),
                    ErrorKind::InvalidArgument);
}

shader::NforFitPush FitPush(const vk::GpuImage &image, const NforFitSettings &settings,
                            int plane) {
    shader::NforFitPush push{
        image.width,           image.height, settings.radius,
        settings.gatherRadius, plane,        1.f / (settings.bandwidth * settings.bandwidth),
        settings.ridge,        {},           0};
    std::copy(settings.featureWeights.begin(), settings.featureWeights.end(),
              push.featureWeight);
    return push;
}

// texel, vec4: the bindings read through texel views (KernelDesc), of them those of vec4s.
const vk::Kernel &FitKernel(vk::Context &context, const char *name, const uint32_t *code,
                            size_t bytes, uint32_t bindings, int channels, int features,
                            uint32_t texel = 0, uint32_t vec4 = 0) {
    return context.GetKernel({name,
                              code,
                              bytes,
                              bindings,
                              sizeof(shader::NforFitPush),
                              {{NFOR_SPEC_CHANNELS, channels}, {NFOR_SPEC_FEATURES, features}},
                              texel,
                              vec4});
}

}  // namespace

int NforPackedFloats(int features) {
    return 4 * NFOR_PACKED_VEC4S(features);
}

int NforBetaStride(int features, int channels) {
    return NFOR_BETA_STRIDE(features, channels);
}

void RecordNforPack(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &color,
                    const vk::GpuImage &features, const vk::GpuImage &mask,
                    vk::GpuImage &packed) {
    CheckColor("nfor pack", color);
    CheckSize("nfor pack", color, features, 0);
    CheckSize("nfor pack", color, mask, 1);
    if (features.channels > NFOR_MAX_FEATURES)
        throw Error(fmt::format("nfor pack: {} feature planes; at most {}", features.channels,
                                NFOR_MAX_FEATURES),
                    ErrorKind::InvalidArgument);
    CheckSize("nfor pack", color, packed, NforPackedFloats(features.channels));
    const vk::Kernel &kernel =
        FitKernel(context, "nfor_pack", k_nfor_pack_spv, sizeof(k_nfor_pack_spv),
                  NFOR_PACK_BINDINGS, color.channels, features.channels);
    shader::NforFitPush push{color.width, color.height, 0, 0, 0, 0, 0, {}, 0};
    recorder.Dispatch(kernel, "nfor.pack",
                      {{NFOR_PACK_COLOR, &color.buffer, vk::Access::Read},
                       {NFOR_PACK_FEATURES, &features.buffer, vk::Access::Read},
                       {NFOR_PACK_MASK, &mask.buffer, vk::Access::Read},
                       {NFOR_PACK_OUT, &packed.buffer, vk::Access::Write}},
                      push, Groups(color.width), uint32_t(color.height));
}

bool NforSameWindow(const NforFitSettings &a, const NforFitSettings &b) {
    return a.radius == b.radius && a.gatherRadius == b.gatherRadius && a.ridge == b.ridge &&
           a.featureWeights == b.featureWeights;
}

void RecordNforRegress(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &packed,
                       int features, int channels, const vk::GpuImage &distance,
                       const NforFitSettings &settings, vk::GpuImage &beta, vk::GpuImage &hat,
                       int hatPlane, const NforFitSettings *second, vk::GpuImage *secondBeta) {
    CheckFit("nfor regress", packed, features, channels, distance, settings);
    CheckSize("nfor regress", packed, beta, NforBetaStride(features, channels));
    CheckSize("nfor regress", packed, hat, 0);
    int candidates = second ? 2 : 1;
    if (hatPlane < 0 || hatPlane + candidates > hat.channels)
        throw Error(fmt::format("nfor regress: planes {}..{} of {}", hatPlane,
                                hatPlane + candidates - 1, hat.channels),
                    ErrorKind::InvalidArgument);
    if (!second != !secondBeta)
        throw Error("nfor regress: a second candidate needs its coefficients and they it",
                    ErrorKind::InvalidArgument);
    if (second) {
        CheckFit("nfor regress", packed, features, channels, distance, *second);
        CheckSize("nfor regress", packed, *secondBeta, NforBetaStride(features, channels));
        if (!NforSameWindow(settings, *second))
            throw Error("nfor regress: the second candidate differs in more than its bandwidth",
                        ErrorKind::InvalidArgument);
    }
    const vk::Kernel &kernel =
        context.GetKernel({"nfor_regress",
                           k_nfor_regress_spv,
                           sizeof(k_nfor_regress_spv),
                           NFOR_REGRESS_BINDINGS,
                           sizeof(shader::NforFitPush),
                           {{NFOR_SPEC_CHANNELS, channels},
                            {NFOR_SPEC_FEATURES, features},
                            {NFOR_SPEC_CANDIDATES, candidates}},
                           (1u << NFOR_FIT_PACKED) | (1u << NFOR_FIT_DISTANCE),
                           1u << NFOR_FIT_PACKED});
    shader::NforFitPush push = FitPush(packed, settings, hatPlane);
    if (second) push.secondInvBandwidth2 = 1.f / (second->bandwidth * second->bandwidth);
    // A single candidate binds its own coefficients in the second's slot too, as read: the
    // variant never writes it, and the recorder sees one writer of the buffer.
    recorder.Dispatch(kernel, "nfor.regress",
                      {{NFOR_FIT_PACKED, &packed.buffer, vk::Access::Read},
                       {NFOR_FIT_DISTANCE, &distance.buffer, vk::Access::Read},
                       {NFOR_FIT_BETA, &beta.buffer, vk::Access::Write},
                       {NFOR_FIT_OUT, &hat.buffer, vk::Access::Write},
                       {NFOR_FIT_SECOND_BETA, second ? &secondBeta->buffer : &beta.buffer,
                        second ? vk::Access::Write : vk::Access::Read}},
                      push, Groups(packed.width), uint32_t(packed.height));
}

void RecordNforGather(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &input,
                      const vk::GpuImage &packed, int features, const vk::GpuImage &distance,
                      const vk::GpuImage &beta, const NforFitSettings &settings,
                      vk::GpuImage &out, int outPlane) {
    CheckFit("nfor gather", packed, features, input.channels, distance, settings);
    CheckSize("nfor gather", packed, input, 0);
    CheckSize("nfor gather", input, beta, NforBetaStride(features, input.channels));
    CheckSize("nfor gather", input, out, 0);
    if (outPlane < 0 || outPlane + input.channels > out.channels)
        throw Error(fmt::format("nfor gather: planes {}.. of {}", outPlane, out.channels),
                    ErrorKind::InvalidArgument);
    const vk::Kernel &kernel =
        FitKernel(context, "nfor_gather", k_nfor_gather_spv, sizeof(k_nfor_gather_spv),
                  NFOR_GATHER_BINDINGS, input.channels, features,
                  (1u << NFOR_FIT_PACKED) | (1u << NFOR_FIT_DISTANCE) | (1u << NFOR_FIT_BETA) |
                      (1u << NFOR_FIT_COLOR),
                  (1u << NFOR_FIT_PACKED) | (1u << NFOR_FIT_BETA));
    recorder.Dispatch(kernel, "nfor.gather",
                      {{NFOR_FIT_PACKED, &packed.buffer, vk::Access::Read},
                       {NFOR_FIT_DISTANCE, &distance.buffer, vk::Access::Read},
                       {NFOR_FIT_BETA, &beta.buffer, vk::Access::Read},
                       {NFOR_FIT_OUT, &out.buffer, vk::Access::Write},
                       {NFOR_FIT_COLOR, &input.buffer, vk::Access::Read}},
                      FitPush(input, settings, outPlane), Groups(input.width),
                      uint32_t(input.height));
}

Image NforPackedOf(const Image &color, const Image &features, const Image &mask) {
    int stride = NforPackedFloats(features.channels), colour = stride - 4;
    Image packed(color.width, color.height, stride);
    for (size_t p = 0; p < packed.PixelCount(); ++p) {
        float *out = packed.data.data() + p * stride;
        out[0] = mask.Plane(0)[p];
        for (int j = 0; j < features.channels; ++j) out[1 + j] = features.Plane(j)[p];
        for (int c = 0; c < color.channels; ++c) out[colour + c] = color.Plane(c)[p];
    }
    return packed;
}

Image NforBetaPlanes(const Image &perPixel, int features, int channels) {
    int stride = NforBetaStride(features, channels), count = (features + 3) * channels;
    if (perPixel.channels != stride)
        throw Error(fmt::format("nfor beta: {} planes, expected {}", perPixel.channels, stride),
                    ErrorKind::Internal);
    Image planes(perPixel.width, perPixel.height, count);
    for (size_t p = 0; p < planes.PixelCount(); ++p)
        for (int k = 0; k < count; ++k) planes.Plane(k)[p] = perPixel.data[p * stride + k];
    return planes;
}

Image NforBetaPerPixel(const Image &planes, int features, int channels) {
    int stride = NforBetaStride(features, channels), count = (features + 3) * channels;
    if (planes.channels != count)
        throw Error(fmt::format("nfor beta: {} planes, expected {}", planes.channels, count),
                    ErrorKind::Internal);
    Image perPixel(planes.width, planes.height, stride);
    for (size_t p = 0; p < planes.PixelCount(); ++p)
        for (int k = 0; k < count; ++k) perPixel.data[p * stride + k] = planes.Plane(k)[p];
    return perPixel;
}

void RecordNforSelect(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &color,
                      const vk::GpuImage &variance, const vk::GpuImage &candidates,
                      const vk::GpuImage &hat, int count, int radius, vk::GpuImage &out,
                      vk::GpuImage &choice, float agreement) {
    CheckColor("nfor select", color);
    CheckSize("nfor select", color, variance, color.channels);
    CheckSize("nfor select", color, out, color.channels);
    CheckSize("nfor select", color, choice, 1);
    if (count < 1 || count > NFOR_MAX_CANDIDATES || radius < 0 ||
        radius > NFOR_SURE_MAX_RADIUS || !(agreement >= 0))
        throw Error(
            fmt::format("nfor select: {} candidates (1..{}), radius {} (0..{}), "
                        "agreement {} (at least 0)",
                        count, NFOR_MAX_CANDIDATES, radius, NFOR_SURE_MAX_RADIUS, agreement),
            ErrorKind::InvalidArgument);
    // The first `count` candidates of buffers sized for a pass with more.
    CheckSize("nfor select", color, candidates, 0);
    CheckSize("nfor select", color, hat, 0);
    if (candidates.channels < count * color.channels || hat.channels < count)
        throw Error(fmt::format("nfor select: {} candidates of {} channels, {} and {} planes "
                                "held",
                                count, color.channels, candidates.channels, hat.channels),
                    ErrorKind::InvalidArgument);
    const vk::Kernel &kernel = context.GetKernel({"nfor_select",
                                                  k_nfor_select_spv,
                                                  sizeof(k_nfor_select_spv),
                                                  NFOR_SELECT_BINDINGS,
                                                  sizeof(shader::NforSelectPush),
                                                  {{NFOR_SPEC_CHANNELS, color.channels}},
                                                  0,
                                                  0});
    shader::NforSelectPush push{color.width, color.height, count, radius, agreement};
    recorder.Dispatch(kernel, "nfor.select",
                      {{NFOR_SELECT_COLOR, &color.buffer, vk::Access::Read},
                       {NFOR_SELECT_VARIANCE, &variance.buffer, vk::Access::Read},
                       {NFOR_SELECT_CANDIDATES, &candidates.buffer, vk::Access::Read},
                       {NFOR_SELECT_HAT, &hat.buffer, vk::Access::Read},
                       {NFOR_SELECT_OUT, &out.buffer, vk::Access::Write},
                       {NFOR_SELECT_CHOICE, &choice.buffer, vk::Access::Write}},
                      push, Groups(color.width), uint32_t(color.height));
}

}  // namespace mcd
