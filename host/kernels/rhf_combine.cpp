#include "host/kernels/rhf_combine.h"

#include <fmt/format.h>

#include "host/error.h"
#include "host/vk/context.h"
#include "host/vk/kernel.h"
#include "rhf/combine.h"
#include "rhf/combine_spv.h"

namespace mcd {

vk::KernelDesc RhfCombineKernel() {
    return {
        "rhf_combine",
        k_rhf_combine_spv,
        sizeof(k_rhf_combine_spv),
        RHF_COMBINE_BINDINGS,
        sizeof(shader::RhfCombinePush),
        {},
        (1u << RHF_COMBINE_FILTERED) | (1u << RHF_COMBINE_LOW) | (1u << RHF_COMBINE_COARSE)};
}

void RecordRhfCombine(vk::Context &context, vk::Recorder &recorder,
                      const vk::GpuImage &filtered, const vk::GpuImage &low,
                      const vk::GpuImage &coarse, vk::GpuImage &out,
                      const RhfCombineWindow &window) {
    if (!(filtered.width == out.width && filtered.height == out.height &&
          low.width == coarse.width && low.height == coarse.height &&
          low.width == (filtered.width + 1) / 2 && low.height == (filtered.height + 1) / 2 &&
          filtered.channels == 3 && out.channels == 3 && low.channels == 3 &&
          coarse.channels == 3))
        throw Error(fmt::format("rhf combine: filtered {}x{}, low {}x{}, coarse {}x{} do not "
                                "fit",
                                filtered.width, filtered.height, low.width, low.height,
                                coarse.width, coarse.height),
                    ErrorKind::Internal);
    const vk::Kernel &kernel = context.GetKernel(RhfCombineKernel());
    RhfCombineWindow w = window;
    if (w.frameWidth <= 0 || w.frameHeight <= 0) w = {0, 0, filtered.width, filtered.height};
    if (w.originX < 0 || w.originY < 0 || w.originX % 2 || w.originY % 2 ||
        w.originX + filtered.width > w.frameWidth ||
        w.originY + filtered.height > w.frameHeight)
        throw Error(fmt::format("rhf combine: a {}x{} window at ({}, {}) does not lie on the "
                                "even grid of its {}x{} frame",
                                filtered.width, filtered.height, w.originX, w.originY,
                                w.frameWidth, w.frameHeight),
                    ErrorKind::Internal);
    shader::RhfCombinePush push{filtered.width,
                                filtered.height,
                                low.width,
                                low.height,
                                w.originX,
                                w.originY,
                                w.frameWidth,
                                w.frameHeight,
                                (w.frameWidth + 1) / 2,
                                (w.frameHeight + 1) / 2};
    recorder.Dispatch(
        kernel, "rhf.combine",
        {{RHF_COMBINE_FILTERED, &filtered.buffer, vk::Access::Read},
         {RHF_COMBINE_LOW, &low.buffer, vk::Access::Read},
         {RHF_COMBINE_COARSE, &coarse.buffer, vk::Access::Read},
         {RHF_COMBINE_OUT, &out.buffer, vk::Access::Write}},
        push, uint32_t((filtered.width + RHF_COMBINE_LOCAL_SIZE - 1) / RHF_COMBINE_LOCAL_SIZE),
        uint32_t(filtered.height), 3u);
}

}  // namespace mcd
