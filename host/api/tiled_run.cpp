#include "host/api/tiled_run.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace mcd::api {

namespace {

int RoundDown(int v, int step) {
    return v / step * step;
}

// The tile [x0, x1) x [y0, y1) of `part`, a window whose corner is (wx0, wy0), into the
// W x H image `whole` (made on first use).
void Paste(const Image &part, int wx0, int wy0, int x0, int y0, int x1, int y1, int W, int H,
           Image &whole) {
    if (whole.Empty()) whole = Image(W, H, part.channels);
    for (int c = 0; c < part.channels; ++c)
        for (int y = y0; y < y1; ++y)
            std::copy_n(part.Plane(c) + size_t(y - wy0) * part.width + (x0 - wx0), x1 - x0,
                        &whole.At(c, y, x0));
}

}  // namespace

TileNeeds WidestNeeds(TileNeeds needs, const TileNeeds &other) {
    // The halos (without each one's last step, made on the whole frame) and the grids.
    const int halo = std::max(needs.reach - needs.finishReach, other.reach - other.finishReach);
    needs.reach = halo + needs.finishReach;
    needs.align = std::lcm(std::max(needs.align, 1), std::max(other.align, 1));
    needs.bytesPerPixel = std::max(needs.bytesPerPixel, other.bytesPerPixel);
    needs.bindingBytesPerPixel =
        std::max(needs.bindingBytesPerPixel, other.bindingBytesPerPixel);
    needs.fixedBytes = std::max(needs.fixedBytes, other.fixedBytes);
    if (other.maxWidth > 0)
        needs.maxWidth =
            needs.maxWidth > 0 ? std::min(needs.maxWidth, other.maxWidth) : other.maxWidth;
    return needs;
}

double TileMemoryBudget(const vk::Context &context, const TileNeeds &needs) {
    const double device = double(context.Info().deviceLocalBytes);
    return needs.notLocal.empty() ? device * 3 / 4 : device;
}

TilePlan PlanTiles(const vk::Context &context, const TileNeeds &needs, int width, int height,
                   int forced) {
    const int align = std::max(needs.align, 1);
    TilePlan plan;
    if (forced > 0) {
        plan.tileWidth = plan.tileHeight = (forced + align - 1) / align * align;
        plan.why = "tile size forced";
        return plan;
    }
    const double budget = TileMemoryBudget(context, needs);
    double binding = double(context.BindingBytes());
    auto fits = [&](double windowWidth, double pixels) {
        return needs.fixedBytes + needs.bytesPerPixel * pixels <= budget &&
               needs.bindingBytesPerPixel * pixels <= binding &&
               (needs.maxWidth <= 0 || windowWidth <= needs.maxWidth);
    };
    double pixels = double(width) * height;
    if (fits(width, pixels)) return plan;
    // The grid whose windows (tile and halo, clipped to the frame) fit, fewest pixels in all.
    const int R = needs.reach;
    double best = 0;
    for (int ny = 1; ny <= height; ++ny) {
        int th = (height + ny - 1) / ny;
        th = (th + align - 1) / align * align;
        // A window starts on the alignment grid: up to align - 1 more pixels.
        double wh = std::min(height, th + (ny > 1 ? 2 * R + align - 1 : 0));
        for (int nx = 1; nx <= width; ++nx) {
            int tw = (width + nx - 1) / nx;
            tw = (tw + align - 1) / align * align;
            double ww = std::min(width, tw + (nx > 1 ? 2 * R + align - 1 : 0));
            if (!fits(ww, ww * wh)) continue;
            double total = double(nx) * ny * ww * wh;
            if (best == 0 || total < best) {
                best = total;
                plan.tileWidth = tw;
                plan.tileHeight = th;
            }
            break;  // more columns only add halos
        }
    }
    plan.why = fmt::format(
        "the whole frame needs about {:.0f} MB of GPU memory ({:.0f} MB in its largest "
        "buffer); this device allows {:.0f} MB per run and {:.0f} MB per binding",
        (needs.fixedBytes + needs.bytesPerPixel * pixels) / 1e6,
        needs.bindingBytesPerPixel * pixels / 1e6, budget / 1e6, binding / 1e6);
    if (needs.maxWidth > 0 && width > needs.maxWidth)
        plan.why += fmt::format(", and windows of at most {} pixels across", needs.maxWidth);
    // Nothing fits, not even a tile of a few pixels with its halo: say so rather than run
    // a tile per pixel.
    if (best == 0)
        throw Error(
            fmt::format("the frame does not fit this device even in tiles: {}", plan.why),
            ErrorKind::OutOfMemory);
    return plan;
}

namespace {

// The method's needs on these inputs, widened by `shared`, its last step left to the whole.
TileNeeds NeedsOf(vk::Context &context, const FrontEnd &method, Inputs &inputs,
                  const TileNeeds *shared) {
    TileNeeds needs = method.Tiling(context, inputs);
    if (shared && needs.notLocal.empty()) needs = WidestNeeds(needs, *shared);
    // The last step is made once on the assembled frame (FrontEnd::Finish): a halo need not
    // hold it.
    needs.reach -= needs.finishReach;
    return needs;
}

bool Whole(const TilePlan &plan, int width, int height) {
    return plan.tileWidth == 0 || (plan.tileWidth >= width && plan.tileHeight >= height);
}

}  // namespace

void PrepareKernels(vk::Context &context, const FrontEnd &method, Inputs &inputs,
                    const TileNeeds *shared) {
    try {
        const int W = inputs.Width(), H = inputs.Height();
        if (!Whole(PlanTiles(context, NeedsOf(context, method, inputs, shared), W, H, 0), W, H))
            return;
        method.PrepareKernels(context, inputs);
    } catch (const Error &e) {
        if (e.Kind() == ErrorKind::Cancelled) throw;
    }
}

Result RunTiled(vk::Context &context, const FrontEnd &method, Inputs &inputs,
                const RunOptions &run, const TileNeeds *shared) {
    const int W = inputs.Width(), H = inputs.Height();
    TileNeeds needs = NeedsOf(context, method, inputs, shared);
    TilePlan plan = PlanTiles(context, needs, W, H, run.keepStages ? 0 : run.tileSize);
    const int TW = plan.tileWidth, TH = plan.tileHeight;
    if (Whole(plan, W, H)) return method.Run(context, inputs, run);
    // A tiled run has no whole-frame stages to keep (what `diff` compares).
    if (run.keepStages)
        throw Error(fmt::format("{}: the frame runs in tiles ({}), so its stages cannot be "
                                "kept; diff a crop of it",
                                method.Name(), plan.why),
                    ErrorKind::InvalidArgument);

    const int R = needs.reach, align = std::max(needs.align, 1);
    const int tilesX = (W + TW - 1) / TW, tilesY = (H + TH - 1) / TH, count = tilesX * tilesY;
    std::unique_ptr<FrontEnd> tiled = method.ForTiles(context, inputs);
    if (needs.finishReach > 0) tiled->LeaveFinishToWhole();
    RunOptions tileRun = run;
    Result result;
    std::vector<std::string> seen;
    int done = 0;
    for (int y0 = 0; y0 < H; y0 += TH)
        for (int x0 = 0; x0 < W; x0 += TW) {
            const int x1 = std::min(W, x0 + TW), y1 = std::min(H, y0 + TH);
            // The window: the tile and its halo, started on the alignment grid.
            const int wx0 = RoundDown(std::max(0, x0 - R), align);
            const int wy0 = RoundDown(std::max(0, y0 - R), align);
            const int wx1 = std::min(W, x1 + R), wy1 = std::min(H, y1 + R);
            if (run.progress)
                tileRun.progress = [&, done](const std::string &stage, int d, int total) {
                    run.progress(fmt::format("tile {}/{} {}", done + 1, count, stage), d,
                                 total);
                };
            Inputs window(inputs, wx0, wy0, wx1, wy1);
            Result part = tiled->Run(context, window, tileRun);
            Paste(part.image, wx0, wy0, x0, y0, x1, y1, W, H, result.image);
            // The stages asked for by name (RunOptions::stages), each a window's image.
            for (const Stage &stage : part.stages) {
                if (stage.image.width != wx1 - wx0 || stage.image.height != wy1 - wy0) continue;
                auto kept = std::find_if(result.stages.begin(), result.stages.end(),
                                         [&](const Stage &s) { return s.name == stage.name; });
                if (kept == result.stages.end())
                    kept = result.stages.insert(kept, {stage.name, Image()});
                Paste(stage.image, wx0, wy0, x0, y0, x1, y1, W, H, kept->image);
            }
            if (done == 0)
                for (const std::string &line : part.plan)
                    result.plan.push_back("first tile: " + line);
            // A warning each tile repeats is said once; counts and pixels are the window's.
            for (std::string &warning : part.warnings)
                if (std::find(seen.begin(), seen.end(), warning) == seen.end()) {
                    seen.push_back(warning);
                    result.warnings.push_back(
                        fmt::format("window [{}, {}) x [{}, {}) (a tile and its halo; pixels "
                                    "counted from the window's corner): {}",
                                    wx0, wx1, wy0, wy1, warning));
                }
            for (std::string &name : part.candidates)
                if (std::find(result.candidates.begin(), result.candidates.end(), name) ==
                    result.candidates.end())
                    result.candidates.push_back(std::move(name));
            for (Timing &t : part.timings) result.timings.push_back(std::move(t));
            ++done;
            if (run.progress) run.progress("tiles", done, count);
        }
    if (tiled->FinishesWhole()) tiled->Finish(context, inputs, &result);
    result.plan.insert(
        result.plan.begin(),
        fmt::format("tiled: {} tile(s) of up to {}x{} pixels ({} x {}), each run on a window "
                    "of the tile and a halo of {} pixels ({}{}), windows starting on "
                    "multiples of {}; {}; {}",
                    count, TW, TH, tilesX, tilesY, R, needs.reachText,
                    needs.finishReach > 0
                        ? fmt::format("; less the last step's {}, made once on the whole "
                                      "frame after the tiles",
                                      needs.finishReach)
                        : "",
                    align, plan.why,
                    needs.notLocal.empty()
                        ? "the result is the untiled one bit for bit"
                        : "the result differs from the untiled one: " + needs.notLocal));
    return result;
}

}  // namespace mcd::api
