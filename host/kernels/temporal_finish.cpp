#include "host/kernels/temporal_finish.h"

#include <fmt/format.h>

#include "host/error.h"
#include "host/vk/context.h"
#include "host/vk/kernel.h"
#include "temporal/finish.h"
#include "temporal/finish_spv.h"

namespace mcd {

void RecordTemporalFinish(vk::Context &context, vk::Recorder &recorder,
                          const TemporalFinishInputs &in, int fillRadius,
                          vk::GpuImage &output) {
    if (!in.moments || !in.counts || !in.raw)
        throw Error("temporal finish: the moments, the counts and the raw layer are needed");
    bool halves = in.sum0 && in.counts0 && in.sum1 && in.counts1;
    if (!halves && (in.sum0 || in.counts0 || in.sum1 || in.counts1))
        throw Error("temporal finish: the halves need both sums and both counts");
    int channels = in.raw->channels, w = in.raw->width, h = in.raw->height;
    if (channels < 1) throw Error("temporal finish: the layer has no channel");
    auto check = [&](const vk::GpuImage *image, int planes, const char *what) {
        if (image && (image->width != w || image->height != h || image->channels != planes))
            throw Error(fmt::format("temporal finish: {} ({}) is {}x{}x{}, {}x{}x{} expected",
                                    what, image->buffer.Name(), image->width, image->height,
                                    image->channels, w, h, planes));
    };
    check(in.moments, 2 * channels, "the moments");
    check(in.counts, 2, "the counts");
    check(in.pooled, channels, "the pooled variances");
    check(in.sum0, channels, "half 0's sums");
    check(in.counts0, 2, "half 0's counts");
    check(in.sum1, channels, "half 1's sums");
    check(in.counts1, 2, "half 1's counts");
    check(&output, (halves ? 4 : 2) * channels, "the output");
    if (fillRadius < 0 || fillRadius > TEMPORAL_FINISH_MAX_RADIUS)
        throw Error(fmt::format("temporal finish: fill radius {} outside [0, {}]", fillRadius,
                                TEMPORAL_FINISH_MAX_RADIUS),
                    ErrorKind::InvalidArgument);
    const vk::Kernel &kernel = context.GetKernel({"temporal_finish",
                                                  k_temporal_finish_spv,
                                                  sizeof(k_temporal_finish_spv),
                                                  TEMPORAL_FINISH_BINDINGS,
                                                  sizeof(shader::TemporalFinishPush),
                                                  {},
                                                  0});
    int flags = (in.pooled ? TEMPORAL_FINISH_WITH_POOLED : 0) |
                (halves ? TEMPORAL_FINISH_WITH_HALVES : 0);
    shader::TemporalFinishPush push{w, h, channels, flags, fillRadius};
    // Absent inputs are bound to a buffer the kernel then does not read.
    const vk::Buffer *unused = &in.raw->buffer;
    auto or_ = [&](const vk::GpuImage *image) { return image ? &image->buffer : unused; };
    recorder.Dispatch(kernel, "temporal.finish",
                      {{TEMPORAL_FINISH_MOMENTS, &in.moments->buffer, vk::Access::Read},
                       {TEMPORAL_FINISH_COUNTS, &in.counts->buffer, vk::Access::Read},
                       {TEMPORAL_FINISH_POOLED, or_(in.pooled), vk::Access::Read},
                       {TEMPORAL_FINISH_RAW, &in.raw->buffer, vk::Access::Read},
                       {TEMPORAL_FINISH_SUM0, or_(in.sum0), vk::Access::Read},
                       {TEMPORAL_FINISH_COUNTS0, or_(in.counts0), vk::Access::Read},
                       {TEMPORAL_FINISH_SUM1, or_(in.sum1), vk::Access::Read},
                       {TEMPORAL_FINISH_COUNTS1, or_(in.counts1), vk::Access::Read},
                       {TEMPORAL_FINISH_OUTPUT, &output.buffer, vk::Access::Write}},
                      push, uint32_t((w + TEMPORAL_LOCAL_SIZE - 1) / TEMPORAL_LOCAL_SIZE),
                      uint32_t(h), uint32_t(channels));
}

}  // namespace mcd
