#include "host/kernels/auto_combine.h"

#include <fmt/format.h>

#include <cmath>

#include "auto/combine.h"
#include "auto/combine_spv.h"
#include "host/error.h"
#include "host/kernels/auto_estimate.h"
#include "host/vk/context.h"
#include "host/vk/kernel.h"

namespace mcd {

void RecordAutoCombine(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &color,
                       const vk::GpuImage &candidates, const vk::GpuImage &errors,
                       AutoMode mode, float power, float floorError, vk::GpuImage &output,
                       vk::GpuImage &weights, const vk::GpuImage *variance, float noiseLimit,
                       float darkLimit) {
    int channels = color.channels, count = errors.channels;
    if (channels < 1 || channels > 4)
        throw Error(fmt::format("auto combine: {} channels; 1 to 4 are supported", channels),
                    ErrorKind::InvalidArgument);
    if (count < 1 || count > AUTO_MAX_CANDIDATES)
        throw Error(fmt::format("auto combine: {} candidates; 1 to {} are supported", count,
                                AUTO_MAX_CANDIDATES),
                    ErrorKind::Internal);
    CheckAutoShapes("auto combine", color, count * channels, {&candidates});
    CheckAutoShapes("auto combine", color, channels, {&output});
    CheckAutoShapes("auto combine", color, count, {&weights});
    if (!(floorError > 0) || !std::isfinite(floorError) || !(power > 0) ||
        !std::isfinite(power))
        throw Error(fmt::format("auto combine: floor {} and power {} must be positive",
                                floorError, power),
                    ErrorKind::InvalidArgument);
    if (mode == AutoMode::Relative) {
        if (!variance)
            throw Error("auto combine: the relative mode needs the variance",
                        ErrorKind::Internal);
        CheckAutoShapes("auto combine", color, channels, {variance});
        if (!(noiseLimit > 0) || !std::isfinite(noiseLimit) || !(darkLimit > 0) ||
            !std::isfinite(darkLimit))
            throw Error(fmt::format("auto combine: noise limit {} and dark limit {} must be "
                                    "positive",
                                    noiseLimit, darkLimit),
                        ErrorKind::InvalidArgument);
    }
    const vk::Kernel &kernel = context.GetKernel({"auto_combine",
                                                  k_auto_combine_spv,
                                                  sizeof(k_auto_combine_spv),
                                                  AUTO_COMBINE_BINDINGS,
                                                  sizeof(shader::AutoCombinePush),
                                                  {},
                                                  0});
    shader::AutoCombinePush push{color.width,
                                 color.height,
                                 channels,
                                 count,
                                 mode == AutoMode::Select          ? AUTO_MODE_SELECT
                                 : mode == AutoMode::WeightsMedian ? AUTO_MODE_WEIGHTS_MEDIAN
                                 : mode == AutoMode::Relative      ? AUTO_MODE_RELATIVE
                                                                   : AUTO_MODE_WEIGHTS,
                                 power,
                                 floorError,
                                 noiseLimit,
                                 darkLimit};
    recorder.Dispatch(kernel, "auto.combine",
                      {{AUTO_COMBINE_COLOR, &color.buffer, vk::Access::Read},
                       {AUTO_COMBINE_CANDIDATES, &candidates.buffer, vk::Access::Read},
                       {AUTO_COMBINE_ERRORS, &errors.buffer, vk::Access::Read},
                       {AUTO_COMBINE_OUTPUT, &output.buffer, vk::Access::Write},
                       {AUTO_COMBINE_WEIGHTS, &weights.buffer, vk::Access::Write},
                       // Not read outside the relative mode.
                       {AUTO_COMBINE_VARIANCE, variance ? &variance->buffer : &color.buffer,
                        vk::Access::Read}},
                      push, uint32_t((color.width + AUTO_LOCAL_SIZE - 1) / AUTO_LOCAL_SIZE),
                      uint32_t(color.height));
}

}  // namespace mcd
