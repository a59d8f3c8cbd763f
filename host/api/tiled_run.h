// A method run on a frame too large for the device, in tiles: each tile's window is the
// tile and a halo of the method's reach (FrontEnd::Tiling), cropped from the frame's
// layers, and only the tile's interior is kept. Frame-wide quantities are fixed from the
// whole frame first (FrontEnd::ForTiles), so a tile-local method gives the untiled result
// bit for bit.
#pragma once

#include "host/api/front_end.h"
#include "host/wavelet.h"

namespace mcd::api {

// How a W x H frame is cut: interior tiles of tileWidth x tileHeight pixels (0: the frame
// is run whole).
struct TilePlan {
    int tileWidth = 0, tileHeight = 0;
    std::string why;  // why it is tiled, for the plan
};

// The device memory a run of `needs` may take whole: three quarters of the device's for a
// method that tiles reproduce bit for bit (a tile's halo is work done again), all of it
// for one that they do not (needs.notLocal: tiles change its output).
double TileMemoryBudget(const vk::Context &context, const TileNeeds &needs);

// Tiles for `needs` on a W x H frame on this device: whole when its memory fits the budget
// (TileMemoryBudget) and its largest buffer one binding; else the grid of tiles
// whose windows fit both with the fewest pixels in all (halos included). `forced` > 0
// forces square tiles of that size.
TilePlan PlanTiles(const vk::Context &context, const TileNeeds &needs, int width, int height,
                   int forced);

// How far one level's analysis or synthesis filter reads, in that level's samples: the
// half-length of the longest tap set (Haar 2 taps, LeGall 5/3 five, CDF 9/7 nine).
inline int WaveletHalfSupport(WaveletBasis basis) {
    return basis == WaveletBasis::Haar ? 1 : basis == WaveletBasis::LeGall53 ? 2 : 4;
}

// `needs` widened to hold `other`'s too: the larger halo and memory, the coarser grid, the
// narrower window. Two runs planned with the same widened needs cut a frame alike.
TileNeeds WidestNeeds(TileNeeds needs, const TileNeeds &other);

// Run `method` on `inputs`, whole or in tiles by PlanTiles (run.tileSize forces a size).
// Tiled, the result has only the stages asked for by name (RunOptions::stages; keepStages
// runs whole), put together from the tiles', and the plan is the first tile's, after a line
// that says how the frame was cut. `shared` (if given, for a method whose tiles give the
// untiled bits) widens the method's needs (WidestNeeds): runs of methods that share work in
// the run memo by their windows' content (rhf at one and at two scales) then make the same
// windows.
Result RunTiled(vk::Context &context, const FrontEnd &method, Inputs &inputs,
                const RunOptions &run, const TileNeeds *shared = nullptr);

// Makes ahead the kernels `method` will record on `inputs` (FrontEnd::PrepareKernels) where
// RunTiled (with no tile size forced) runs it whole; a tiled run's windows make theirs as
// they record them. An error the run would meet (a frame it refuses) is left for it to say.
void PrepareKernels(vk::Context &context, const FrontEnd &method, Inputs &inputs,
                    const TileNeeds *shared = nullptr);

}  // namespace mcd::api
