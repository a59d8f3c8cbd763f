#include "host/kernels/pivot_bilateral.h"

#include <fmt/format.h>

#include <algorithm>

#include "host/error.h"
#include "host/kernels/pivot_ratio.h"
#include "host/vk/context.h"
#include "host/vk/kernel.h"
#include "pivot/bilateral.h"
#include "pivot/bilateral_spv.h"

namespace mcd {

vk::KernelDesc PivotBilateralKernel(bool normals, bool ids) {
    return {"pivot_bilateral",
            k_pivot_bilateral_spv,
            sizeof(k_pivot_bilateral_spv),
            PIVOT_BILATERAL_BINDINGS,
            sizeof(shader::PivotBilateralPush),
            {{PIVOT_SPEC_NORMALS, normals ? 1 : 0}, {PIVOT_SPEC_IDS, ids ? 1 : 0}},
            (1u << PIVOT_BILATERAL_COLOR) | (1u << PIVOT_BILATERAL_PIVOT) |
                (1u << PIVOT_BILATERAL_Z) | (1u << PIVOT_BILATERAL_NU) |
                (1u << PIVOT_BILATERAL_GUIDES),
            1u << PIVOT_BILATERAL_GUIDES};
}

void RecordPivotBilateral(vk::Context &context, vk::Recorder &recorder,
                          const vk::GpuImage &color, const vk::GpuImage &pivot,
                          const vk::GpuImage &z, const vk::GpuImage &nu,
                          const PivotGpuGuides &guides, const PivotBilateralSettings &settings,
                          vk::GpuImage &out) {
    CheckPivotShapes("pivot bilateral", color, {&pivot, &z, &nu, &out});
    CheckPivotGuides("pivot bilateral", color.width, color.height, guides);
    if (settings.radius < 0 || settings.radius > 64)
        throw Error(fmt::format("pivot bilateral: radius {}; 0..64 allowed", settings.radius),
                    ErrorKind::InvalidArgument);
    if (!(settings.sigmaRange > 0))
        throw Error("pivot bilateral: the range sigma must be > 0", ErrorKind::InvalidArgument);
    const vk::Kernel &kernel =
        context.GetKernel(PivotBilateralKernel(guides.normals, guides.ids));
    shader::PivotBilateralPush push{color.width,
                                    color.height,
                                    color.channels,
                                    settings.radius,
                                    std::max(0.5f, settings.radius / 2.f),
                                    settings.sigmaRange,
                                    settings.goodNoise * settings.goodNoise};
    recorder.Dispatch(kernel, "pivot.bilateral",
                      {{PIVOT_BILATERAL_COLOR, &color.buffer, vk::Access::Read},
                       {PIVOT_BILATERAL_PIVOT, &pivot.buffer, vk::Access::Read},
                       {PIVOT_BILATERAL_Z, &z.buffer, vk::Access::Read},
                       {PIVOT_BILATERAL_NU, &nu.buffer, vk::Access::Read},
                       {PIVOT_BILATERAL_GUIDES,
                        guides.image ? &guides.image->buffer : &color.buffer, vk::Access::Read},
                       {PIVOT_BILATERAL_OUT, &out.buffer, vk::Access::Write}},
                      push, uint32_t((color.width + PIVOT_LOCAL_SIZE - 1) / PIVOT_LOCAL_SIZE),
                      uint32_t(color.height), uint32_t(color.channels));
}

}  // namespace mcd
