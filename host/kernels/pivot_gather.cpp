#include "host/kernels/pivot_gather.h"

#include <fmt/format.h>

#include <algorithm>

#include "host/error.h"
#include "host/kernels/pivot_ratio.h"
#include "host/vk/context.h"
#include "host/vk/kernel.h"
#include "pivot/gather.h"
#include "pivot/gather_spv.h"

namespace mcd {

Image PivotTileRadii(const Image &radii, int *reach) {
    const int t = PIVOT_GATHER_TILE;
    Image tiles((radii.width + t - 1) / t, (radii.height + t - 1) / t, radii.channels, -1.f);
    *reach = 0;
    for (int c = 0; c < radii.channels; ++c)
        for (int y = 0; y < radii.height; ++y)
            for (int x = 0; x < radii.width; ++x) {
                float r = radii.At(c, y, x);
                float &tile = tiles.At(c, y / t, x / t);
                tile = std::max(tile, r);
                if (r >= 0) *reach = std::max(*reach, int(r));
            }
    return tiles;
}

void RecordPivotGather(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &color,
                       const vk::GpuImage &pivot, const vk::GpuImage &nu,
                       const vk::GpuImage &fitLo, const vk::GpuImage &fitHi,
                       const PivotGpuGuides &guides, const vk::GpuImage &tiles, int reach,
                       vk::GpuImage &out, int rowBase, int rows) {
    if (rowBase < 0 || rows < 1 || rowBase + rows > color.height)
        throw Error(fmt::format("pivot gather: rows {}..{} of a {}-row image", rowBase,
                                rowBase + rows - 1, color.height));
    const int t = PIVOT_GATHER_TILE;
    int tilesX = (color.width + t - 1) / t, tilesY = (color.height + t - 1) / t;
    if (tiles.width != tilesX || tiles.height != tilesY || tiles.channels != color.channels)
        throw Error(fmt::format("pivot gather: the tile radii are {}x{}x{}, expected {}x{}x{}",
                                tiles.width, tiles.height, tiles.channels, tilesX, tilesY,
                                color.channels));
    CheckPivotShapes("pivot gather", color, {&pivot, &nu, &out});
    CheckPivotGuides("pivot gather", color.width, color.height, guides);
    for (const vk::GpuImage *fit : {&fitLo, &fitHi})
        if (fit->width != color.width || fit->height != color.height ||
            fit->channels != PIVOT_PLANES_PER_BUFFER * color.channels)
            throw Error(
                fmt::format("pivot gather: {} has the wrong shape", fit->buffer.Name()));
    const vk::Kernel &kernel = context.GetKernel(
        {"pivot_gather",
         k_pivot_gather_spv,
         sizeof(k_pivot_gather_spv),
         PIVOT_GATHER_BINDINGS,
         sizeof(shader::PivotGatherPush),
         {{PIVOT_SPEC_NORMALS, guides.normals ? 1 : 0}, {PIVOT_SPEC_IDS, guides.ids ? 1 : 0}},
         (1u << PIVOT_GATHER_COLOR) | (1u << PIVOT_GATHER_PIVOT) | (1u << PIVOT_GATHER_NU) |
             (1u << PIVOT_GATHER_FIT_LO) | (1u << PIVOT_GATHER_FIT_HI) |
             (1u << PIVOT_GATHER_GUIDES) | (1u << PIVOT_GATHER_TILES)});
    shader::PivotGatherPush push{
        color.width, color.height, color.channels, reach < 0 ? 0 : reach,
        tilesX,      tilesY,       rowBase};
    recorder.Dispatch(kernel, "pivot.gather",
                      {{PIVOT_GATHER_COLOR, &color.buffer, vk::Access::Read},
                       {PIVOT_GATHER_PIVOT, &pivot.buffer, vk::Access::Read},
                       {PIVOT_GATHER_NU, &nu.buffer, vk::Access::Read},
                       {PIVOT_GATHER_FIT_LO, &fitLo.buffer, vk::Access::Read},
                       {PIVOT_GATHER_FIT_HI, &fitHi.buffer, vk::Access::Read},
                       {PIVOT_GATHER_GUIDES,
                        guides.image ? &guides.image->buffer : &color.buffer, vk::Access::Read},
                       {PIVOT_GATHER_OUT, &out.buffer, vk::Access::Write},
                       {PIVOT_GATHER_TILES, &tiles.buffer, vk::Access::Read}},
                      push, uint32_t((color.width + PIVOT_LOCAL_SIZE - 1) / PIVOT_LOCAL_SIZE),
                      uint32_t(rows), uint32_t(color.channels));
}

}  // namespace mcd
