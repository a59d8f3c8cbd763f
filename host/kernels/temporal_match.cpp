#include "host/kernels/temporal_match.h"

#include <fmt/format.h>

#include <cmath>

#include "host/error.h"
#include "host/vk/context.h"
#include "host/vk/kernel.h"
#include "temporal/match.h"
#include "temporal/match_spv.h"

namespace mcd {

namespace {

void CheckShape(const vk::GpuImage &reference, const vk::GpuImage *image, int channels,
                const char *what) {
    if (!image) return;
    if (image->width != reference.width || image->height != reference.height ||
        image->channels != channels)
        throw Error(fmt::format("temporal match: {} ({}) is {}x{}x{}, {}x{}x{} expected", what,
                                image->buffer.Name(), image->width, image->height,
                                image->channels, reference.width, reference.height, channels));
}

}  // namespace

void RecordTemporalMatch(vk::Context &context, vk::Recorder &recorder,
                         const vk::GpuImage &currentFeatures,
                         const TemporalMatchFrame &neighbour, const vk::GpuImage &previous,
                         const vk::GpuImage &position, bool self, bool first, int direction,
                         const TemporalMatchTest &test, vk::GpuImage &weight,
                         vk::GpuImage &next) {
    if (!neighbour.features || !neighbour.color)
        throw Error("temporal match: the neighbour needs its features and its colour");
    const vk::GpuImage &f = currentFeatures;
    int channels = neighbour.color->channels;
    if (channels < 1 || channels > 4)
        throw Error(
            fmt::format("temporal match: {} colour channels; 1 to 4 are supported", channels),
            ErrorKind::InvalidArgument);
    CheckShape(f, &f, TEMPORAL_FEATURE_PLANES, "the current frame's features");
    CheckShape(f, neighbour.features, TEMPORAL_FEATURE_PLANES, "the neighbour's features");
    CheckShape(f, neighbour.color, channels, "the neighbour's colour");
    CheckShape(f, neighbour.spp, 1, "the neighbour's spp");
    CheckShape(f, neighbour.motion, 4, "the neighbour's motion");
    CheckShape(f, &previous, 2, "the previous positions");
    CheckShape(f, &position, 2, "the positions");
    CheckShape(f, &weight, 1, "the weights");
    CheckShape(f, &next, 2, "the next positions");
    if (direction != -1 && direction != 1)
        throw Error(fmt::format("temporal match: direction {} is neither -1 nor +1", direction),
                    ErrorKind::InvalidArgument);
    if ((test.features & ~(TEMPORAL_HAS_NORMAL | TEMPORAL_HAS_DEPTH | TEMPORAL_HAS_ALBEDO |
                           TEMPORAL_HAS_ID)) != 0)
        throw Error(
            fmt::format("temporal match: feature mask {} has unknown bits", test.features),
            ErrorKind::InvalidArgument);
    for (float t : {test.normalCos, test.depthRel, test.albedoRel, test.motionTol})
        if (!std::isfinite(t))
            throw Error("temporal match: a tolerance is not a finite number",
                        ErrorKind::InvalidArgument);
    const vk::Kernel &kernel = context.GetKernel({"temporal_match",
                                                  k_temporal_match_spv,
                                                  sizeof(k_temporal_match_spv),
                                                  TEMPORAL_MATCH_BINDINGS,
                                                  sizeof(shader::TemporalMatchPush),
                                                  {},
                                                  0});
    int flags = (self ? TEMPORAL_MATCH_SELF : 0) | (first ? TEMPORAL_MATCH_FIRST : 0) |
                (neighbour.spp ? TEMPORAL_MATCH_WITH_SPP : 0) |
                (neighbour.motion ? TEMPORAL_MATCH_WITH_MOTION : 0);
    shader::TemporalMatchPush push{f.width,        f.height,      channels,       test.features,
                                   flags,          direction,     test.normalCos, test.depthRel,
                                   test.albedoRel, test.motionTol};
    // Absent layers are bound to a buffer the kernel then does not read.
    const vk::Buffer &unused = neighbour.color->buffer;
    recorder.Dispatch(
        kernel, "temporal.match",
        {{TEMPORAL_MATCH_PREVIOUS, &previous.buffer, vk::Access::Read},
         {TEMPORAL_MATCH_POSITION, &position.buffer, vk::Access::Read},
         {TEMPORAL_MATCH_CURRENT, &f.buffer, vk::Access::Read},
         {TEMPORAL_MATCH_FEATURES, &neighbour.features->buffer, vk::Access::Read},
         {TEMPORAL_MATCH_COLOR, &neighbour.color->buffer, vk::Access::Read},
         {TEMPORAL_MATCH_SPP, neighbour.spp ? &neighbour.spp->buffer : &unused,
          vk::Access::Read},
         {TEMPORAL_MATCH_MOTION, neighbour.motion ? &neighbour.motion->buffer : &unused,
          vk::Access::Read},
         {TEMPORAL_MATCH_WEIGHT, &weight.buffer, vk::Access::Write},
         {TEMPORAL_MATCH_NEXT, &next.buffer, vk::Access::Write}},
        push, uint32_t((f.width + TEMPORAL_LOCAL_SIZE - 1) / TEMPORAL_LOCAL_SIZE),
        uint32_t(f.height));
}

}  // namespace mcd
