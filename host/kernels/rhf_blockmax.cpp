#include "host/kernels/rhf_blockmax.h"

#include <fmt/format.h>

#include <algorithm>

#include "host/error.h"
#include "host/vk/context.h"
#include "host/vk/kernel.h"
#include "rhf/blockmax.h"
#include "rhf/blockmax_spv.h"

namespace mcd {

int RhfBlocks(int width) {
    return (width + RHF_BLOCKMAX_WIDTH - 1) / RHF_BLOCKMAX_WIDTH;
}

vk::KernelDesc RhfBlockMaxKernel() {
    return {"rhf_blockmax",
            k_rhf_blockmax_spv,
            sizeof(k_rhf_blockmax_spv),
            RHF_BLOCKMAX_BINDINGS,
            sizeof(shader::RhfBlockMaxPush),
            {},
            (1u << RHF_BLOCKMAX_HIST) | (1u << RHF_BLOCKMAX_COUNT)};
}

void RecordRhfBlockMax(vk::Context &context, vk::Recorder &recorder, const RhfHistogram &hist,
                       float histScale, vk::Buffer &blockMax) {
    const int n3 = hist.planes - 1, blocks = RhfBlocks(hist.width);
    if (hist.slots.empty() || hist.planesPerSlot <= 0 ||
        (hist.planes + hist.planesPerSlot - 1) / hist.planesPerSlot != int(hist.slots.size()))
        throw Error(
            fmt::format("rhf block maxima: {} histogram planes in {} buffers of {} planes",
                        hist.planes, hist.slots.size(), hist.planesPerSlot),
            ErrorKind::Internal);
    if (blockMax.Bytes() < size_t(n3) * hist.height * blocks * sizeof(float))
        throw Error(fmt::format("rhf block maxima: a {}x{} image's {} planes do not fit '{}'",
                                hist.width, hist.height, n3, blockMax.Name()),
                    ErrorKind::Internal);
    const vk::Kernel &kernel = context.GetKernel(RhfBlockMaxKernel());
    const vk::Buffer &counts = hist.slots[n3 / hist.planesPerSlot];
    for (size_t slot = 0; slot < hist.slots.size(); ++slot) {
        int first = int(slot) * hist.planesPerSlot;
        int planes = std::min(hist.planesPerSlot, n3 - first);
        if (planes <= 0) continue;  // only the count plane
        shader::RhfBlockMaxPush push{hist.width,
                                     hist.height,
                                     first,
                                     planes,
                                     n3 - (n3 / hist.planesPerSlot) * hist.planesPerSlot,
                                     histScale,
                                     0,
                                     0};
        recorder.Dispatch(
            kernel, "rhf.blockmax",
            {{RHF_BLOCKMAX_HIST, &hist.slots[slot], vk::Access::Read},
             {RHF_BLOCKMAX_COUNT, &counts, vk::Access::Read},
             {RHF_BLOCKMAX_OUT, &blockMax, vk::Access::Write}},
            push, uint32_t((blocks + RHF_BLOCKMAX_LOCAL_SIZE - 1) / RHF_BLOCKMAX_LOCAL_SIZE),
            uint32_t(hist.height), uint32_t(planes));
    }
}

}  // namespace mcd
