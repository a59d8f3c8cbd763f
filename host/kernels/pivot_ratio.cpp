#include "host/kernels/pivot_ratio.h"

#include <fmt/format.h>

#include "host/error.h"
#include "host/vk/context.h"
#include "host/vk/kernel.h"
#include "pivot/ratio.h"
#include "pivot/ratio_spv.h"

namespace mcd {

void CheckPivotShapes(const char *what, const vk::GpuImage &a,
                      std::initializer_list<const vk::GpuImage *> others) {
    for (const vk::GpuImage *b : others)
        if (b->width != a.width || b->height != a.height || b->channels != a.channels)
            throw Error(fmt::format("{}: {} is {}x{}x{} but {} is {}x{}x{}", what,
                                    a.buffer.Name(), a.width, a.height, a.channels,
                                    b->buffer.Name(), b->width, b->height, b->channels),
                        ErrorKind::Internal);
    if (a.channels < 1 || a.channels > 4)
        throw Error(fmt::format("{}: {} channels; 1 to 4 are supported", what, a.channels),
                    ErrorKind::InvalidArgument);
}

int CheckPivotZsn(const char *what, int width, int height, int channels,
                  const std::vector<vk::GpuImage> &zsn) {
    if (int(zsn.size()) != channels || zsn.empty())
        throw Error(fmt::format("{}: {} packed z, s, nu images for {} channels", what,
                                zsn.size(), channels),
                    ErrorKind::Internal);
    int planes = zsn.front().channels;
    if (planes != PIVOT_ZSN_PLANES && planes != PIVOT_ZSN_EDGE_PLANES) planes = -1;
    for (const vk::GpuImage &one : zsn)
        if (one.width != width || one.height != height || one.channels != planes)
            throw Error(
                fmt::format("{}: {} is {}x{}x{}, expected {}x{}x{} (z, s, nu, level, "
                            "noise) or x{} (z, s, nu) for every channel",
                            what, one.buffer.Name(), one.width, one.height, one.channels, width,
                            height, PIVOT_ZSN_EDGE_PLANES, PIVOT_ZSN_PLANES),
                ErrorKind::Internal);
    return planes / 4;
}

int CheckPivotZsn(const char *what, const vk::GpuImage &a,
                  const std::vector<vk::GpuImage> &zsn) {
    return CheckPivotZsn(what, a.width, a.height, a.channels, zsn);
}

void CheckPivotZsnHoldsEdge(const char *what, int zsnTexels, float edge) {
    if (edge > 0 && zsnTexels != 2)
        throw Error(fmt::format("{}: the shading-edge test reads zsn's level and noise, which "
                                "this one lacks",
                                what),
                    ErrorKind::Internal);
}

vk::KernelDesc PivotRatioKernel(bool variance, bool ids, int zsnTexels) {
    return {"pivot_ratio",
            k_pivot_ratio_spv,
            sizeof(k_pivot_ratio_spv),
            PIVOT_RATIO_BINDINGS,
            sizeof(shader::PivotRatioPush),
            {{PIVOT_SPEC_VARIANCE, variance ? 1 : 0},
             {PIVOT_SPEC_IDS, ids ? 1 : 0},
             {PIVOT_SPEC_ZSN_TEXELS, zsnTexels}},
            (1u << PIVOT_RATIO_COLOR) | (1u << PIVOT_RATIO_PIVOT) |
                (1u << PIVOT_RATIO_VARIANCE) | (1u << PIVOT_RATIO_GUIDES),
            1u << PIVOT_RATIO_GUIDES};
}

void RecordPivotRatio(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &color,
                      const vk::GpuImage &pivot, const vk::GpuImage *variance,
                      const std::vector<float> &thresholds, const PivotGpuGuides &guides,
                      vk::GpuImage &z, vk::GpuImage &s, vk::GpuImage &nu,
                      std::vector<vk::GpuImage> &zsn, const vk::Buffer &unusedSlot) {
    CheckPivotShapes("pivot ratio", color, {&pivot, &z, &s, &nu});
    int zsnTexels = CheckPivotZsn("pivot ratio", color, zsn);
    if (variance) CheckPivotShapes("pivot ratio", color, {variance});
    CheckPivotGuides("pivot ratio", color.width, color.height, guides);
    if (int(thresholds.size()) != color.channels)
        throw Error(fmt::format("pivot ratio: {} thresholds for {} channels", thresholds.size(),
                                color.channels),
                    ErrorKind::Internal);
    if (unusedSlot.Bytes() > kPivotUnusedSlotBytes)
        throw Error(fmt::format("pivot ratio: the stand-in {} is {} bytes, above {}",
                                unusedSlot.Name(), unusedSlot.Bytes(), kPivotUnusedSlotBytes),
                    ErrorKind::Internal);
    const vk::Kernel &kernel =
        context.GetKernel(PivotRatioKernel(variance != nullptr, guides.ids, zsnTexels));
    float t[4] = {};
    for (size_t c = 0; c < thresholds.size(); ++c) t[c] = thresholds[c];
    shader::PivotRatioPush push{color.width, color.height, t[0], t[1], t[2], t[3]};
    // Without a variance layer the kernel reads none: the color stands in for the binding.
    std::vector<vk::Binding> bindings{
        {PIVOT_RATIO_COLOR, &color.buffer, vk::Access::Read},
        {PIVOT_RATIO_PIVOT, &pivot.buffer, vk::Access::Read},
        {PIVOT_RATIO_VARIANCE, variance ? &variance->buffer : &color.buffer, vk::Access::Read},
        {PIVOT_RATIO_Z, &z.buffer, vk::Access::Write},
        {PIVOT_RATIO_S, &s.buffer, vk::Access::Write},
        {PIVOT_RATIO_NU, &nu.buffer, vk::Access::Write},
        {PIVOT_RATIO_GUIDES, guides.image ? &guides.image->buffer : &color.buffer,
         vk::Access::Read}};
    // Each channel's packed z, s, nu in its own slot; the tiny stand-in fills the slots of
    // channels the frame lacks (the kernel does not touch them), so that they add next to
    // nothing to the dispatch's counted traffic.
    for (int c = 0; c < PIVOT_MAX_CHANNELS; ++c)
        bindings.push_back({uint32_t(PIVOT_RATIO_ZSN + c),
                            c < color.channels ? &zsn[size_t(c)].buffer : &unusedSlot,
                            c < color.channels ? vk::Access::Write : vk::Access::Read});
    recorder.Dispatch(kernel, "pivot.ratio", bindings, push,
                      uint32_t((color.width + PIVOT_LOCAL_SIZE - 1) / PIVOT_LOCAL_SIZE),
                      uint32_t(color.height), uint32_t(color.channels));
}

}  // namespace mcd
