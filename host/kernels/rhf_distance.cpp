#include "host/kernels/rhf_distance.h"

#include <fmt/format.h>

#include <algorithm>

#include "host/error.h"
#include "host/vk/context.h"
#include "host/vk/kernel.h"
#include "rhf/distance.h"
#include "rhf/distance_spv.h"

namespace mcd {

// Each lane owns RHF_DISTANCE_PIXELS_PER_LANE centres of a row.
constexpr int kCentresPerGroup = RHF_DISTANCE_LOCAL_SIZE * RHF_DISTANCE_PIXELS_PER_LANE;

vk::KernelDesc RhfDistanceKernel(int searchHalf, int patchHalf) {
    return {"rhf_distance",
            k_rhf_distance_spv,
            sizeof(k_rhf_distance_spv),
            RHF_DISTANCE_BINDINGS,
            sizeof(shader::RhfDistancePush),
            {{RHF_DISTANCE_SPEC_SEARCH_HALF, searchHalf},
             {RHF_DISTANCE_SPEC_PATCH_HALF, patchHalf}},
            (1u << RHF_DISTANCE_SUM) | (1u << RHF_DISTANCE_COUNT)};
}

void RecordRhfDistance(vk::Context &context, vk::Recorder &recorder, int width, int height,
                       int patchHalf, int searchHalf, int termBase, int termRows, int rowBase,
                       int rows, const vk::Buffer &termSum, const vk::Buffer &termCount,
                       vk::Buffer &dist) {
    size_t side = 2 * searchHalf + 1;
    if (rowBase < 0 || rows <= 0 || rowBase + rows > height ||
        termBase > std::max(0, rowBase - patchHalf - searchHalf) ||
        termBase + termRows < std::min(height, rowBase + rows + patchHalf) ||
        termSum.Bytes() < (searchHalf + 1) * side * termRows * width * sizeof(float) ||
        termCount.Bytes() < termSum.Bytes() ||
        dist.Bytes() < side * side * rows * width * sizeof(float))
        throw Error(fmt::format("rhf distance: centre rows {}..{} with term rows {}..{} of a "
                                "{}x{} image do not fit the buffers",
                                rowBase, rowBase + rows - 1, termBase, termBase + termRows - 1,
                                width, height),
                    ErrorKind::Internal);
    const vk::Kernel &kernel = context.GetKernel(RhfDistanceKernel(searchHalf, patchHalf));
    shader::RhfDistancePush push{width,    height,   patchHalf, 0,
                                 termBase, termRows, rowBase,   rows};
    recorder.Dispatch(kernel, "rhf.distance",
                      {{RHF_DISTANCE_SUM, &termSum, vk::Access::Read},
                       {RHF_DISTANCE_COUNT, &termCount, vk::Access::Read},
                       {RHF_DISTANCE_OUT, &dist, vk::Access::Write}},
                      push, uint32_t((width + kCentresPerGroup - 1) / kCentresPerGroup),
                      uint32_t(rows), uint32_t(side * side));
}

}  // namespace mcd
