#include "host/kernels/rhf_aggregate.h"

#include <fmt/format.h>

#include "host/error.h"
#include "host/kernels/rhf_select.h"
#include "host/vk/context.h"
#include "host/vk/kernel.h"
#include "rhf/aggregate.h"
#include "rhf/aggregate_spv.h"

namespace mcd {

vk::KernelDesc RhfAggregateKernel(int searchHalf, int patchHalf) {
    return {"rhf_aggregate",
            k_rhf_aggregate_spv,
            sizeof(k_rhf_aggregate_spv),
            RHF_AGGREGATE_BINDINGS,
            sizeof(shader::RhfAggregatePush),
            {{RHF_AGGREGATE_SPEC_SEARCH_HALF, searchHalf},
             {RHF_AGGREGATE_SPEC_PATCH_HALF, patchHalf}},
            1u << RHF_AGGREGATE_COLOR};
}

void RecordRhfAggregate(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &color,
                        const vk::Buffer &mask, int patchHalf, int searchHalf,
                        vk::GpuImage &out) {
    int words = RhfMaskWords(searchHalf);
    if (color.channels != 3 || out.channels != 3 || color.width != out.width ||
        color.height != out.height ||
        mask.Bytes() < size_t(words) * color.width * color.height * sizeof(uint32_t))
        throw Error(fmt::format("rhf aggregate: color {}x{}x{}, out {}x{}x{} and a {}-byte "
                                "mask do not fit",
                                color.width, color.height, color.channels, out.width,
                                out.height, out.channels, mask.Bytes()),
                    ErrorKind::Internal);
    const vk::Kernel &kernel = context.GetKernel(RhfAggregateKernel(searchHalf, patchHalf));
    shader::RhfAggregatePush push{color.width, color.height, patchHalf, searchHalf, words};
    recorder.Dispatch(
        kernel, "rhf.aggregate",
        {{RHF_AGGREGATE_COLOR, &color.buffer, vk::Access::Read},
         {RHF_AGGREGATE_MASK, &mask, vk::Access::Read},
         {RHF_AGGREGATE_OUT, &out.buffer, vk::Access::Write}},
        push, uint32_t((color.width + RHF_AGGREGATE_LOCAL_SIZE - 1) / RHF_AGGREGATE_LOCAL_SIZE),
        uint32_t(color.height));
}

}  // namespace mcd
