#include "host/kernels/temporal_fold.h"

#include <fmt/format.h>

#include "host/error.h"
#include "host/vk/context.h"
#include "host/vk/kernel.h"
#include "temporal/fold.h"
#include "temporal/fold_spv.h"

namespace mcd {

void RecordTemporalFold(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &value,
                        const vk::GpuImage &position, const vk::GpuImage &weight,
                        const vk::GpuImage &total, const TemporalFoldStep &step,
                        vk::GpuImage &state) {
    int mode = 0, channels = value.channels;
    switch (step.mode) {
        case TemporalFoldMode::Moments:
            mode = TEMPORAL_FOLD_MOMENTS;
            break;
        case TemporalFoldMode::Sum:
            mode = TEMPORAL_FOLD_SUM;
            break;
        case TemporalFoldMode::Min:
            mode = TEMPORAL_FOLD_MIN;
            break;
        case TemporalFoldMode::Max:
            mode = TEMPORAL_FOLD_MAX;
            break;
        case TemporalFoldMode::Count:
            mode = TEMPORAL_FOLD_COUNT, channels = 1;
            break;
    }
    bool twoStates =
        step.mode == TemporalFoldMode::Moments || step.mode == TemporalFoldMode::Count;
    int w = weight.width, h = weight.height;
    auto check = [&](const vk::GpuImage &image, int planes, const char *what) {
        if (image.width != w || image.height != h || image.channels != planes)
            throw Error(fmt::format("temporal fold: {} ({}) is {}x{}x{}, {}x{}x{} expected",
                                    what, image.buffer.Name(), image.width, image.height,
                                    image.channels, w, h, planes));
    };
    check(weight, 1, "the weights");
    check(position, 2, "the positions");
    check(total, 2, "the totals");
    check(state, twoStates ? 2 * channels : channels, "the state");
    if (step.mode != TemporalFoldMode::Count) check(value, channels, "the value");
    if (value.width != w || value.height != h)
        throw Error(fmt::format("temporal fold: the value ({}) is {}x{}, {}x{} expected",
                                value.buffer.Name(), value.width, value.height, w, h));
    if (channels < 1) throw Error("temporal fold: the value has no channel");
    if (step.mode == TemporalFoldMode::Sum && (step.power < 0 || step.power > 2))
        throw Error(fmt::format("temporal fold: power {} is not 0, 1 or 2", step.power),
                    ErrorKind::InvalidArgument);
    const vk::Kernel &kernel = context.GetKernel({"temporal_fold",
                                                  k_temporal_fold_spv,
                                                  sizeof(k_temporal_fold_spv),
                                                  TEMPORAL_FOLD_BINDINGS,
                                                  sizeof(shader::TemporalFoldPush),
                                                  {},
                                                  0});
    int flags =
        (step.first ? TEMPORAL_FOLD_FIRST : 0) | (step.centres ? TEMPORAL_FOLD_CENTRES : 0);
    shader::TemporalFoldPush push{w, h, channels, mode, step.power, flags};
    recorder.Dispatch(kernel, "temporal.fold",
                      {{TEMPORAL_FOLD_VALUE, &value.buffer, vk::Access::Read},
                       {TEMPORAL_FOLD_POSITION, &position.buffer, vk::Access::Read},
                       {TEMPORAL_FOLD_WEIGHT, &weight.buffer, vk::Access::Read},
                       {TEMPORAL_FOLD_TOTAL, &total.buffer, vk::Access::Read},
                       {TEMPORAL_FOLD_STATE, &state.buffer,
                        step.first ? vk::Access::Write : vk::Access::ReadWrite}},
                      push, uint32_t((w + TEMPORAL_LOCAL_SIZE - 1) / TEMPORAL_LOCAL_SIZE),
                      uint32_t(h), uint32_t(channels));
}

}  // namespace mcd
