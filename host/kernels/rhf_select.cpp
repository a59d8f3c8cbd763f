#include "host/kernels/rhf_select.h"

#include <fmt/format.h>

#include "host/error.h"
#include "host/vk/context.h"
#include "host/vk/kernel.h"
#include "rhf/select.h"
#include "rhf/select_spv.h"

namespace mcd {

int RhfMaskWords(int searchHalf) {
    int side = 2 * searchHalf + 1;
    return (side * side + 31) / 32;
}

vk::KernelDesc RhfSelectKernel(int searchHalf, bool pooled) {
    return {"rhf_select",
            k_rhf_select_spv,
            sizeof(k_rhf_select_spv),
            RHF_SELECT_BINDINGS,
            sizeof(shader::RhfSelectPush),
            {{RHF_SELECT_SPEC_SEARCH_HALF, searchHalf}, {RHF_SELECT_SPEC_POOL, pooled ? 1 : 0}},
            (1u << RHF_SELECT_DISTANCE) | (1u << RHF_SELECT_POOL)};
}

void RecordRhfSelect(vk::Context &context, vk::Recorder &recorder, int width, int height,
                     int searchHalf, int rowBase, int rows, int nearest, float threshold,
                     const vk::Buffer &dist, const vk::Buffer &pool, float poolBound,
                     int patchHalf, vk::Buffer &mask) {
    size_t side = 2 * searchHalf + 1, words = RhfMaskWords(searchHalf);
    if (rowBase < 0 || rows <= 0 || rowBase + rows > height ||
        dist.Bytes() < side * side * rows * width * sizeof(float) ||
        mask.Bytes() < words * height * width * sizeof(uint32_t) ||
        (poolBound > 0 && pool.Bytes() < size_t(height) * width * sizeof(float)))
        throw Error(fmt::format("rhf select: rows {}..{} of a {}x{} image do not fit the "
                                "buffers",
                                rowBase, rowBase + rows - 1, width, height),
                    ErrorKind::Internal);
    const vk::Kernel &kernel = context.GetKernel(RhfSelectKernel(searchHalf, poolBound > 0));
    shader::RhfSelectPush push{width,   height,    searchHalf, rowBase,  rows,
                               nearest, poolBound, threshold,  patchHalf};
    recorder.Dispatch(kernel, "rhf.select",
                      {{RHF_SELECT_DISTANCE, &dist, vk::Access::Read},
                       {RHF_SELECT_POOL, &pool, vk::Access::Read},
                       {RHF_SELECT_MASK, &mask, vk::Access::Write}},
                      push,
                      uint32_t((width + RHF_SELECT_LOCAL_SIZE - 1) / RHF_SELECT_LOCAL_SIZE),
                      uint32_t(rows));
}

}  // namespace mcd
