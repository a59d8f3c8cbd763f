#include "host/kernels/rhf_terms.h"

#include <fmt/format.h>

#include "host/error.h"
#include "host/kernels/rhf_blockmax.h"
#include "host/vk/context.h"
#include "host/vk/kernel.h"
#include "rhf/blockmax.h"
#include "rhf/terms.h"
#include "rhf/terms_spv.h"

namespace mcd {

static_assert(RHF_BLOCKMAX_WIDTH == RHF_TERMS_PIXELS_PER_LANE,
              "a lane's pixels must be one block of the bin maxima");

// Each lane owns RHF_TERMS_PIXELS_PER_LANE pixels of a row.
constexpr int kPixelsPerGroup = RHF_TERMS_LOCAL_SIZE * RHF_TERMS_PIXELS_PER_LANE;

vk::KernelDesc RhfTermsKernel(int searchHalf, int slots) {
    return {"rhf_terms",
            k_rhf_terms_spv,
            sizeof(k_rhf_terms_spv),
            RHF_TERMS_BINDINGS,
            sizeof(shader::RhfTermsPush),
            {{RHF_TERMS_SPEC_SEARCH_HALF, searchHalf}, {RHF_TERMS_SPEC_SLOTS, slots}},
            (1u << RHF_HIST_SLOTS) - 1};
}

void RecordRhfTerms(vk::Context &context, vk::Recorder &recorder, const RhfHistogram &hist,
                    int searchHalf, int rowBase, int rows, float histScale, float brightVeto,
                    const vk::Buffer &blockMax, vk::Buffer &termSum, vk::Buffer &termCount) {
    int side = 2 * searchHalf + 1;
    size_t need = size_t(searchHalf + 1) * side * rows * hist.width * sizeof(float);
    if (hist.slots.empty() || hist.slots.size() > RHF_HIST_SLOTS || hist.planesPerSlot <= 0 ||
        (hist.planes + hist.planesPerSlot - 1) / hist.planesPerSlot != int(hist.slots.size()))
        throw Error(fmt::format("rhf terms: {} histogram planes in {} buffers of {} planes",
                                hist.planes, hist.slots.size(), hist.planesPerSlot),
                    ErrorKind::Internal);
    if (rowBase < 0 || rows <= 0 || rowBase + rows > hist.height || termSum.Bytes() < need ||
        termCount.Bytes() < need)
        throw Error(fmt::format("rhf terms: rows {}..{} of {} need {} bytes per term buffer",
                                rowBase, rowBase + rows - 1, hist.height, need),
                    ErrorKind::Internal);
    const vk::Kernel &kernel =
        context.GetKernel(RhfTermsKernel(searchHalf, int(hist.slots.size())));
    shader::RhfTermsPush push{hist.width, hist.height, hist.planes - 1,    brightVeto,
                              rowBase,    rows,        hist.planesPerSlot, histScale};
    std::vector<vk::Binding> bindings;
    // Unused slots repeat the first buffer: the shader never reads them.
    for (int slot = 0; slot < RHF_HIST_SLOTS; ++slot)
        bindings.push_back({uint32_t(RHF_TERMS_HIST + slot),
                            &hist.slots[slot < int(hist.slots.size()) ? slot : 0],
                            vk::Access::Read});
    if (blockMax.Bytes() <
        size_t(hist.planes - 1) * hist.height * RhfBlocks(hist.width) * sizeof(float))
        throw Error(fmt::format("rhf terms: '{}' is too small for a {}x{} image's bin maxima",
                                blockMax.Name(), hist.width, hist.height),
                    ErrorKind::Internal);
    bindings.push_back({RHF_TERMS_BLOCKMAX, &blockMax, vk::Access::Read});
    bindings.push_back({RHF_TERMS_SUM, &termSum, vk::Access::Write});
    bindings.push_back({RHF_TERMS_COUNT, &termCount, vk::Access::Write});
    recorder.Dispatch(kernel, "rhf.terms", bindings, push,
                      uint32_t((hist.width + kPixelsPerGroup - 1) / kPixelsPerGroup),
                      uint32_t(rows), uint32_t(searchHalf + 1));
}

}  // namespace mcd
