#include "host/kernels/auto_noise.h"

#include <fmt/format.h>

#include "auto/noise.h"
#include "auto/noise_spv.h"
#include "host/error.h"
#include "host/kernels/auto_estimate.h"
#include "host/vk/context.h"
#include "host/vk/kernel.h"

namespace mcd {

vk::KernelDesc AutoNoiseKernel() {
    return {"auto_noise",
            k_auto_noise_spv,
            sizeof(k_auto_noise_spv),
            AUTO_NOISE_BINDINGS,
            sizeof(shader::AutoNoisePush),
            {},
            0};
}

void RecordAutoNoise(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &color,
                     const vk::GpuImage *albedo, int radius, vk::GpuImage &output) {
    if (color.channels < 1 || color.channels > 4)
        throw Error(
            fmt::format("auto noise: {} channels; 1 to 4 are supported", color.channels),
            ErrorKind::InvalidArgument);
    CheckAutoShapes("auto noise", color, color.channels, {&output});
    if (albedo) {
        if (albedo->channels != 1 && albedo->channels < color.channels)
            throw Error(fmt::format("auto noise: {} has {} channels; 1 or {} expected",
                                    albedo->buffer.Name(), albedo->channels, color.channels),
                        ErrorKind::InvalidArgument);
        CheckAutoShapes("auto noise", color, albedo->channels, {albedo});
    }
    if (radius < 1 || radius > AUTO_NOISE_MAX_RADIUS)
        throw Error(
            fmt::format("auto noise: radius {} outside [1, {}]", radius, AUTO_NOISE_MAX_RADIUS),
            ErrorKind::InvalidArgument);
    const vk::Kernel &kernel = context.GetKernel(AutoNoiseKernel());
    shader::AutoNoisePush push{color.width, color.height, color.channels,
                               albedo ? albedo->channels : 0, radius};
    // Without an albedo the colour is bound in its place (not read).
    recorder.Dispatch(
        kernel, "auto.noise",
        {{AUTO_NOISE_COLOR, &color.buffer, vk::Access::Read},
         {AUTO_NOISE_ALBEDO, albedo ? &albedo->buffer : &color.buffer, vk::Access::Read},
         {AUTO_NOISE_OUTPUT, &output.buffer, vk::Access::Write}},
        push, uint32_t((color.width + AUTO_LOCAL_SIZE - 1) / AUTO_LOCAL_SIZE),
        uint32_t(color.height), uint32_t(color.channels));
}

}  // namespace mcd
