#include "host/kernels/pivot_gather.h"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <utility>
#include <vector>

#include "host/common/parallel.h"
#include "host/error.h"
#include "host/kernels/pivot_ratio.h"
#include "host/vk/context.h"
#include "host/vk/kernel.h"
#include "pivot/gather.h"
#include "pivot/gather_spv.h"

namespace mcd {

static_assert(PIVOT_GATHER_NEAR >= 2, "radii start at 2");
// The gather reads a centre's planes as two vec4 texels per fit buffer.
static_assert(PIVOT_PLANES_PER_BUFFER == 8 && PIVOT_PLANES == 16);

int PivotLatticeStepOf(float radius) {
    int step = 1;
    while (step < PIVOT_LATTICE_MAX_STEP && float(2 * step) <= radius / 2.f) step *= 2;
    return step;
}

Image PivotTileOrder(const Image &radii, int *reach) {
    const int t = PIVOT_GATHER_TILE;
    int tilesX = (radii.width + t - 1) / t, tilesY = (radii.height + t - 1) / t;
    int channels = radii.channels;
    Image order(t * t, tilesX * tilesY, 3 * channels, -1.f);
    // Rows of tiles sorted on threads, each with its own list; the reach is a maximum.
    std::atomic<int> largestRadius{0};
    ParallelFor(channels * tilesY, radii.data.size() * 8, [&](int begin, int end) {
        std::vector<std::pair<float, int>> tile;
        int partReach = 0;
        for (int tileRow = begin; tileRow < end; ++tileRow) {
            const int c = tileRow / tilesY, ty = tileRow % tilesY;
            for (int tx = 0; tx < tilesX; ++tx) {
                tile.clear();
                for (int v = 0; v < t && ty * t + v < radii.height; ++v)
                    for (int u = 0; u < t && tx * t + u < radii.width; ++u) {
                        int x = tx * t + u, y = ty * t + v;
                        float r = radii.At(c, y, x);
                        if (r >= 0) partReach = std::max(partReach, int(r));
                        // Off its lattice a centre takes no part, and the gather reads the
                        // centres of step 1 directly: both listed as without fit.
                        int step = PivotLatticeStepOf(r);
                        bool listed = x % step == 0 && y % step == 0 && r > PIVOT_GATHER_NEAR;
                        tile.push_back({listed ? r : -1.f, v * t + u});
                    }
                // Largest radius first; stable: ties keep raster order.
                std::stable_sort(tile.begin(), tile.end(), [](const auto &a, const auto &b) {
                    return a.first > b.first;
                });
                int row = ty * tilesX + tx;
                for (size_t j = 0; j < tile.size(); ++j) {
                    order.At(c, row, int(j)) = float(tile[j].second);
                    order.At(channels + c, row, int(j)) = std::max(tile[j].first, -1.f);
                }
            }
        }
        int seen = largestRadius.load();
        while (partReach > seen && !largestRadius.compare_exchange_weak(seen, partReach)) {
        }
    });
    *reach = largestRadius.load();
    // Each tile's local reach: the largest radius listed in a tile that may hold one of its
    // pixels (Chebyshev gap between the tiles <= that tile's largest radius).
    auto gap = [t](int a, int b) { return a == b ? 0 : (std::abs(a - b) - 1) * t + 1; };
    for (int c = 0; c < channels; ++c)
        for (int sy = 0; sy < tilesY; ++sy)
            for (int sx = 0; sx < tilesX; ++sx) {
                int largest = int(order.At(channels + c, sy * tilesX + sx, 0));
                if (largest < 0) continue;
                int span = largest / t + 1;
                for (int ty = std::max(0, sy - span); ty <= std::min(tilesY - 1, sy + span);
                     ++ty)
                    for (int tx = std::max(0, sx - span); tx <= std::min(tilesX - 1, sx + span);
                         ++tx) {
                        if (std::max(gap(sx, tx), gap(sy, ty)) > largest) continue;
                        float &local = order.At(2 * channels + c, ty * tilesX + tx, 0);
                        local = std::max(local, float(largest));
                    }
            }
    return order;
}

vk::KernelDesc PivotGatherKernel(bool normals, bool ids, int zsnTexels) {
    return {"pivot_gather",
            k_pivot_gather_spv,
            sizeof(k_pivot_gather_spv),
            PIVOT_GATHER_BINDINGS,
            sizeof(shader::PivotGatherPush),
            {{PIVOT_SPEC_NORMALS, normals ? 1 : 0},
             {PIVOT_SPEC_IDS, ids ? 1 : 0},
             {PIVOT_SPEC_ZSN_TEXELS, zsnTexels}},
            (1u << PIVOT_GATHER_COLOR) | (1u << PIVOT_GATHER_PIVOT) | (1u << PIVOT_GATHER_ZSN) |
                (1u << PIVOT_GATHER_FIT_LO) | (1u << PIVOT_GATHER_FIT_HI) |
                (1u << PIVOT_GATHER_GUIDES) | (1u << PIVOT_GATHER_TILES),
            (1u << PIVOT_GATHER_GUIDES) | (1u << PIVOT_GATHER_FIT_LO) |
                (1u << PIVOT_GATHER_FIT_HI) | (1u << PIVOT_GATHER_ZSN)};
}

void RecordPivotGather(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &color,
                       const vk::GpuImage &pivot, const std::vector<vk::GpuImage> &zsn,
                       const PivotFitBuffers &fits, const PivotGpuGuides &guides,
                       const vk::GpuImage &tiles, int reach, float edge, vk::GpuImage &out,
                       int rowBase, int rows) {
    if (rowBase < 0 || rows < 1 || rowBase + rows > color.height)
        throw Error(fmt::format("pivot gather: rows {}..{} of a {}-row image", rowBase,
                                rowBase + rows - 1, color.height),
                    ErrorKind::Internal);
    const int t = PIVOT_GATHER_TILE;
    int tilesX = (color.width + t - 1) / t, tilesY = (color.height + t - 1) / t;
    if (tiles.width != t * t || tiles.height != tilesX * tilesY ||
        tiles.channels != 3 * color.channels)
        throw Error(fmt::format("pivot gather: the tile order is {}x{}x{}, expected {}x{}x{}",
                                tiles.width, tiles.height, tiles.channels, t * t,
                                tilesX * tilesY, 3 * color.channels),
                    ErrorKind::Internal);
    CheckPivotShapes("pivot gather", color, {&pivot, &out});
    int zsnTexels = CheckPivotZsn("pivot gather", color, zsn);
    CheckPivotZsnHoldsEdge("pivot gather", zsnTexels, edge);
    CheckPivotGuides("pivot gather", color.width, color.height, guides);
    CheckPivotFitBuffers("pivot gather", color.width, color.height, color.channels, fits);
    const vk::Kernel &kernel =
        context.GetKernel(PivotGatherKernel(guides.normals, guides.ids, zsnTexels));
    for (int c = 0; c < color.channels; ++c) {
        shader::PivotGatherPush push{
            color.width, color.height, color.channels, reach < 0 ? 0 : reach,
            tilesX,      tilesY,       rowBase,        c,
            edge};
        recorder.Dispatch(
            kernel, "pivot.gather",
            {{PIVOT_GATHER_COLOR, &color.buffer, vk::Access::Read},
             {PIVOT_GATHER_PIVOT, &pivot.buffer, vk::Access::Read},
             {PIVOT_GATHER_ZSN, &zsn[size_t(c)].buffer, vk::Access::Read},
             {PIVOT_GATHER_FIT_LO, &fits.lo[c].buffer, vk::Access::Read},
             {PIVOT_GATHER_FIT_HI, &fits.hi[c].buffer, vk::Access::Read},
             {PIVOT_GATHER_GUIDES, guides.image ? &guides.image->buffer : &color.buffer,
              vk::Access::Read},
             {PIVOT_GATHER_OUT, &out.buffer, vk::Access::Write},
             {PIVOT_GATHER_TILES, &tiles.buffer, vk::Access::Read}},
            push, uint32_t((color.width + PIVOT_LOCAL_SIZE - 1) / PIVOT_LOCAL_SIZE),
            uint32_t(rows), 1);
    }
}

}  // namespace mcd
