#include "host/methods/rhf.h"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <deque>
#include <memory>
#include <optional>

#include "host/common/parallel.h"
#include "host/error.h"
#include "host/kernels/rhf_aggregate.h"
#include "host/kernels/rhf_blockmax.h"
#include "host/kernels/rhf_combine.h"
#include "host/kernels/rhf_distance.h"
#include "host/kernels/rhf_downsample.h"
#include "host/kernels/rhf_select.h"
#include "host/kernels/rhf_terms.h"
#include "host/methods/run_memo.h"
#include "host/methods/staged_run.h"
#include "host/vk/gpu_image.h"
#include "rhf/terms.h"

namespace mcd {
namespace {

constexpr int kMaxSearchHalf = 20;
constexpr int kMaxScales = 8;

double SigmaOfScale(int s) {
    return 0.55 * std::sqrt(std::pow(4.0, s) - 1);
}

int Shrunk(int extent, int s) {
    return (extent + (1 << s) - 1) >> s;
}

// How much each full-resolution column (or row) weighs in the sum of D_s's output: the
// taps that land on it, mirrored edges included. The downsampled count channel's total is
// then the full-resolution one weighted by column times row weights, known without
// reading anything back from the GPU.
std::vector<double> ColumnWeights(int extent, int s, const std::vector<float> &taps) {
    int radius = int(taps.size() / 2), step = 1 << s;
    std::vector<double> weights(extent, 0.0);
    for (int x = 0; x < Shrunk(extent, s); ++x)
        for (int i = 0; i <= 2 * radius; ++i) {
            int j = (step * x + step / 2 - radius + i) % (2 * extent);
            if (j < 0) j += 2 * extent;
            weights[j < extent ? j : 2 * extent - 1 - j] += taps[i];
        }
    return weights;
}

// What the filter cannot use: pixels whose colour is NaN/Inf, pixels whose colour is
// finite but a bin or the count is NaN/Inf/negative, and pixels without samples (the count
// or the bins' total 0 once those are 0).
struct Unusable {
    size_t badColor = 0, badHist = 0, empty = 0;
};

// Whether the pixel's three colour channels are all finite.
bool ColorFinite(const Image &color, int y, int x) {
    for (int c = 0; c < 3; ++c)
        if (!std::isfinite(color.At(c, y, x))) return false;
    return true;
}

// Counts what Sanitize replaces, reading only.
Unusable CountUnusable(const Image &color, const Image &hist) {
    const int W = color.width, H = color.height, n3 = hist.channels - 1;
    std::atomic<size_t> badColor{0}, badHist{0}, empty{0};
    ParallelFor(H, size_t(W) * H * size_t(n3 + 4), [&](int yBegin, int yEnd) {
        size_t rowsBadColor = 0, rowsBadHist = 0, rowsEmpty = 0;
        for (int y = yBegin; y < yEnd; ++y)
            for (int x = 0; x < W; ++x) {
                const bool colorOk = ColorFinite(color, y, x);
                bool histOk = true;
                double total = 0;
                float count = 0;
                for (int i = 0; i <= n3; ++i) {
                    float v = hist.At(i, y, x);
                    if (!std::isfinite(v) || v < 0) {
                        histOk = false;
                        v = 0;
                    }
                    if (i < n3)
                        total += v;
                    else
                        count = v;
                }
                rowsBadColor += !colorOk;
                rowsBadHist += colorOk && !histOk;
                rowsEmpty += colorOk && (count == 0 || total == 0);
            }
        badColor += rowsBadColor;
        badHist += rowsBadHist;
        empty += rowsEmpty;
    });
    return {badColor.load(), badHist.load(), empty.load()};
}

// CountUnusable's counts kept for later runs on the same histograms with a finite colour.
struct RhfUnusableMemo {
    Unusable found;
};

// CountUnusable, or with a memo (the colour finite) the counts an earlier run made of the
// same histograms.
Unusable CountUnusableShared(const Image &color, const Image &hist, RunMemo *memo,
                             const std::string &histId) {
    if (!memo) return CountUnusable(color, hist);
    const std::string key = "rhf.unusable " + histId;
    if (const RhfUnusableMemo *kept = memo->Find<RhfUnusableMemo>(key)) return kept->found;
    Unusable found = CountUnusable(color, hist);
    memo->Add(key, std::make_shared<RhfUnusableMemo>(RhfUnusableMemo{found}));
    return found;
}

// Replace what the filter cannot use: a NaN/Inf/negative bin or count by 0, and a pixel
// whose colour is NaN/Inf by a black pixel whose histogram matches nothing.
void Sanitize(Image &color, Image &hist) {
    const int W = color.width, H = color.height, n3 = hist.channels - 1;
    ParallelFor(H, size_t(W) * H * size_t(n3 + 4), [&](int yBegin, int yEnd) {
        for (int y = yBegin; y < yEnd; ++y)
            for (int x = 0; x < W; ++x) {
                const bool colorOk = ColorFinite(color, y, x);
                for (int i = 0; i <= n3; ++i) {
                    float &v = hist.At(i, y, x);
                    if (!std::isfinite(v) || v < 0 || !colorOk) v = 0;
                }
                if (!colorOk)
                    for (int c = 0; c < 3; ++c) color.At(c, y, x) = 0;
            }
    });
}

// What Sanitize replaced, or found without samples, as warnings.
std::vector<std::string> UnusableWarnings(const Unusable &found) {
    std::vector<std::string> warnings;
    if (found.badColor)
        warnings.push_back(fmt::format(
            "rhf: {} pixel(s) have a NaN/Inf colour; they were taken as black pixels without "
            "samples",
            found.badColor));
    if (found.badHist)
        warnings.push_back(fmt::format(
            "rhf: {} pixel(s) have NaN/Inf/negative histogram bins or counts; those were set "
            "to 0",
            found.badHist));
    if (found.empty)
        warnings.push_back(fmt::format(
            "rhf: {} pixel(s) have no samples (count 0 or an empty histogram); their patches "
            "are compared on their other pixels only",
            found.empty));
    return warnings;
}

void CheckRhfInputs(const Image &color, const Image &hist, const RhfParams &o) {
    if (color.channels != 3)
        throw Error(fmt::format("rhf: the color layer has {} channels; expected 3 (R, G, B)",
                                color.channels),
                    ErrorKind::InvalidArgument);
    if (hist.channels < 4 || (hist.channels - 1) % 3 != 0)
        throw Error(fmt::format("rhf: the histogram layer has {} channels; expected 3n+1 (n "
                                "bins for each of R, G, B, then the sample count)",
                                hist.channels),
                    ErrorKind::InvalidArgument);
    if (hist.width != color.width || hist.height != color.height)
        throw Error(fmt::format("rhf: the color layer is {}x{} but the histograms are {}x{}",
                                color.width, color.height, hist.width, hist.height),
                    ErrorKind::InvalidArgument);
    if (color.width <= 0 || color.height <= 0)
        throw Error("rhf: the image is empty", ErrorKind::InvalidArgument);
    if (o.patchHalf < 0 || o.patchHalf > kMaxSearchHalf)
        throw Error(fmt::format("rhf: patch half-size must be in 0..{}, not {}", kMaxSearchHalf,
                                o.patchHalf),
                    ErrorKind::InvalidArgument);
    if (o.searchHalf < 0 || o.searchHalf > kMaxSearchHalf)
        throw Error(fmt::format("rhf: search half-window must be in 0..{}, not {}",
                                kMaxSearchHalf, o.searchHalf),
                    ErrorKind::InvalidArgument);
    int side = 2 * o.searchHalf + 1, offsets = side * side;
    if (o.knn < 0 || o.knn > offsets)
        throw Error(fmt::format("rhf: kNN must be in 0..{} (the search window), not {}",
                                offsets, o.knn),
                    ErrorKind::InvalidArgument);
    if (!std::isfinite(o.threshold) || o.threshold < 0)
        throw Error(
            fmt::format("rhf: the threshold must be a finite number >= 0, not {}", o.threshold),
            ErrorKind::InvalidArgument);
    if (!std::isfinite(o.brightVeto) || o.brightVeto < 0)
        throw Error(fmt::format("rhf: the bright veto must be a finite number >= 0, not {}",
                                o.brightVeto),
                    ErrorKind::InvalidArgument);
    if (!std::isfinite(o.brightPool) || o.brightPool < 0)
        throw Error(fmt::format("rhf: the pooled bright veto must be a finite number >= 0, "
                                "not {}",
                                o.brightPool),
                    ErrorKind::InvalidArgument);
    if (o.scales < 1 || o.scales > kMaxScales)
        throw Error(fmt::format("rhf: scales must be in 1..{}, not {}", kMaxScales, o.scales),
                    ErrorKind::InvalidArgument);
}

// How the frame is split to fit the device's bindings.
struct RhfLayout {
    int perSlot = 0;           // histogram planes per buffer
    int stripRows = 0;         // centre rows per distance strip
    int termRowsMax = 0;       // rows of terms a strip needs, at most
    size_t rowFloats = 0;      // distances per centre row
    size_t termRowFloats = 0;  // terms per row
};

RhfLayout RhfLayoutFor(vk::Context &context, int W, int H, int planes, const RhfParams &o,
                       const RunSetup &setup) {
    const size_t pixels = size_t(W) * H;
    const size_t maxFloats = std::min<size_t>(context.BindingBytes() / sizeof(float), 1u << 25);
    int side = 2 * o.searchHalf + 1, offsets = side * side;
    // The selection mask is one binding: refuse, before any work, a frame it cannot hold.
    size_t maskBytes = size_t(RhfMaskWords(o.searchHalf)) * pixels * sizeof(uint32_t);
    if (maskBytes > context.Limits().maxStorageBufferRange)
        throw Error(fmt::format("rhf: a {}x{} frame with search half-window {} needs a {:.0f} "
                                "MB selection mask, "
                                "above this device's {:.0f} MB per binding; crop the frame or "
                                "shrink the window",
                                W, H, o.searchHalf, maskBytes / 1e6,
                                context.Limits().maxStorageBufferRange / 1e6),
                    ErrorKind::OutOfMemory);

    RhfLayout layout;
    layout.perSlot = setup.planesPerSlot > 0
                         ? setup.planesPerSlot
                         : int(std::min<size_t>(planes, maxFloats / pixels));
    if (layout.perSlot < 1 || (planes + layout.perSlot - 1) / layout.perSlot > RHF_HIST_SLOTS)
        throw Error(fmt::format("rhf: a {}x{} frame's {} histogram planes do not fit in {} "
                                "buffers of {} floats",
                                W, H, planes, RHF_HIST_SLOTS, maxFloats),
                    ErrorKind::OutOfMemory);
    // A strip's distances take offsets x rows x W floats, its terms (b+1)(2b+1) x (rows +
    // 2w + b) x W: both within one binding.
    layout.rowFloats = size_t(offsets) * W;
    layout.termRowFloats = size_t(o.searchHalf + 1) * side * W;
    int apron = 2 * o.patchHalf + o.searchHalf;
    int stripRows = setup.stripRows > 0
                        ? setup.stripRows
                        : int(std::min<size_t>(maxFloats / layout.rowFloats,
                                               maxFloats / layout.termRowFloats - apron));
    stripRows = std::min(stripRows, H);
    if (stripRows < 1 || maxFloats / layout.termRowFloats <= size_t(apron))
        throw Error(fmt::format("rhf: a {}-pixel-wide image needs more than {} floats per "
                                "distance strip; reduce the search window",
                                W, maxFloats),
                    ErrorKind::OutOfMemory);
    layout.stripRows = stripRows;
    layout.termRowsMax = std::min(H, stripRows + apron);
    return layout;
}

// The total of the count channel, kept at every scale as the tool keeps it, and per pixel.
struct HistogramTotals {
    double total = 0;
    std::vector<double> pixel;
};

HistogramTotals TotalsOf(const Image &hist) {
    HistogramTotals totals;
    totals.pixel.assign(hist.PixelCount(), 0.0);
    const float *count = hist.Plane(hist.channels - 1);
    for (size_t p = 0; p < hist.PixelCount(); ++p) totals.pixel[p] = count[p];
    for (double v : totals.pixel) totals.total += v;
    return totals;
}

// The count-preserving rescale of scale s: the full-resolution total over D_s's, whose
// total is known from the tap weights.
float HistScaleOf(const HistogramTotals &totals, int W, int H, int s) {
    std::vector<float> g = RhfGaussianTaps(SigmaOfScale(s), 1 << s);
    std::vector<double> wx = ColumnWeights(W, s, g), wy = ColumnWeights(H, s, g);
    double coarseTotal = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
            coarseTotal += totals.pixel[size_t(y) * W + x] * wx[x] * wy[y];
    return coarseTotal > 0 ? float(totals.total / coarseTotal) : 1.f;
}

RhfHistogram UploadHistogram(vk::Context &context, const Image &hist, int perSlot) {
    RhfHistogram full;
    full.width = hist.width;
    full.height = hist.height;
    full.planes = hist.channels;
    full.planesPerSlot = perSlot;
    size_t pixels = hist.PixelCount();
    for (int first = 0; first < full.planes; first += perSlot) {
        int count = std::min(perSlot, full.planes - first);
        vk::Buffer &slot =
            full.slots.emplace_back(context, size_t(count) * pixels * sizeof(float),
                                    fmt::format("rhf.hist{}", first / perSlot));
        slot.Upload(hist.Plane(first), size_t(count) * pixels * sizeof(float));
    }
    return full;
}

// Work buffers, sized for the finest scale and reused by every scale. The pooled veto's
// counts only when it is on (the kernel does not read them otherwise: one float to bind).
struct RhfWork {
    RhfWork(vk::Context &context, const RhfLayout &layout, int searchHalf, int width,
            int height, int planes, bool pooled)
        : pool(context, (pooled ? size_t(width) * height : 1) * sizeof(float), "rhf.pool"),
          termSum(context, layout.termRowFloats * layout.termRowsMax * sizeof(float),
                  "rhf.termSum"),
          termCount(context, layout.termRowFloats * layout.termRowsMax * sizeof(float),
                    "rhf.termCount"),
          dist(context, layout.rowFloats * layout.stripRows * sizeof(float), "rhf.distance"),
          mask(context, size_t(RhfMaskWords(searchHalf)) * width * height * sizeof(uint32_t),
               "rhf.mask"),
          blockMax(context, size_t(planes - 1) * height * RhfBlocks(width) * sizeof(float),
                   "rhf.blockMax") {}
    vk::Buffer pool, termSum, termCount, dist, mask, blockMax;
};

// What the scales make while recording, kept until the submission (deques: references
// stay valid).
struct RhfScratch {
    std::deque<vk::GpuImage> images;
    std::deque<vk::Buffer> buffers;
    std::deque<RhfHistogram> histograms;
};

// The downsampler's row pass of `count` planes of a srcW x srcH buffer at scale s.
vk::Buffer &DownsampleScratch(StagedRun &run, RhfScratch &scratch, int srcW, int srcH,
                              int count, int s) {
    return scratch.buffers.emplace_back(
        run.Context(), size_t(count) * srcH * Shrunk(srcW, s) * sizeof(float), "rhf.scratch");
}

// D_s of `count` planes of a srcW x srcH buffer into dst, through `temporary` (at least
// DownsampleScratch's size).
void RecordDownsample(StagedRun &run, RhfScratch &scratch, const vk::Buffer &src, int srcW,
                      int srcH, int count, int s, double sigma, vk::Buffer &temporary,
                      vk::Buffer &dst) {
    std::vector<float> g = RhfGaussianTaps(sigma, 1 << s);
    vk::Buffer &weights =
        scratch.buffers.emplace_back(run.Context(), g.size() * sizeof(float), "rhf.taps");
    weights.UploadFloats(g);
    RecordRhfDownsample(run.Context(), run.Recorder(), src, srcW, srcH, count, 1 << s, weights,
                        int(g.size() / 2), temporary, dst);
}

// What one scale filters: its colour, its histograms and their count-preserving scale.
struct ScaleInputs {
    const vk::GpuImage *color = nullptr;
    const RhfHistogram *hist = nullptr;
    float histScale = 1.f;
};

// Scale s >= 1: D_s of the colour and, where the scale selects anew, of the histograms,
// rescaled by histScale to keep the sample total.
ScaleInputs RecordCoarseInputs(StagedRun &run, RhfScratch &scratch, const vk::GpuImage &color,
                               const RhfHistogram &full, int planes, int s, float histScale,
                               bool selects) {
    const int W = color.width, H = color.height, Ws = Shrunk(W, s), Hs = Shrunk(H, s);
    double sigma = SigmaOfScale(s);
    ScaleInputs in;
    vk::GpuImage &u =
        scratch.images.emplace_back(run.Context(), Ws, Hs, 3, fmt::format("rhf.color{}", s));
    RecordDownsample(run, scratch, color.buffer, W, H, 3, s, sigma,
                     DownsampleScratch(run, scratch, W, H, 3, s), u.buffer);
    run.StageAtEnd(fmt::format("color s{}", s), u);
    in.color = &u;
    in.histScale = histScale;
    if (!selects) {
        // The selection is an earlier run's: the histograms are not read at this scale.
        run.Plan(
            fmt::format("scale {}: Gaussian downsampling by {} (sigma {:.4g}) of color "
                        "to {}x{}; its selection is an earlier run's (histograms rescaled "
                        "by {:.9g})",
                        s, 1 << s, sigma, Ws, Hs, histScale));
        return in;
    }
    const int perSlot = full.planesPerSlot;
    RhfHistogram &coarse = scratch.histograms.emplace_back();
    coarse.width = Ws;
    coarse.height = Hs;
    coarse.planes = planes;
    coarse.planesPerSlot = perSlot;
    // One row pass's scratch for every buffer of planes, each in turn: half a buffer's
    // memory, not half the histograms'.
    vk::Buffer &rows = DownsampleScratch(run, scratch, W, H, std::min(perSlot, planes), s);
    for (size_t slot = 0; slot < full.slots.size(); ++slot) {
        int count = std::min(perSlot, planes - int(slot) * perSlot);
        vk::Buffer &to =
            coarse.slots.emplace_back(run.Context(), size_t(count) * Ws * Hs * sizeof(float),
                                      fmt::format("rhf.hist{}.{}", slot, s));
        RecordDownsample(run, scratch, full.slots[slot], W, H, count, s, sigma, rows, to);
    }
    in.hist = &coarse;
    run.Plan(fmt::format(
        "scale {}: Gaussian downsampling by {} (sigma {:.4g}) of color and {} "
        "histogram planes to {}x{}; histograms rescaled by {:.9g} to keep the sample "
        "total",
        s, 1 << s, sigma, planes, Ws, Hs, in.histScale));
    return in;
}

// The pooled bright veto's bound at scale s: the finest scale's alone (the coarse
// histograms stay on the GPU).
float PoolBoundOf(int s, const RhfParams &o) {
    return s == 0 ? o.brightPool : 0.f;
}

// A selection mask kept for later runs on the same histograms (RunSetup::memo).
struct RhfMaskMemo {
    vk::Buffer mask;
};

// The memo's key of scale s's selection: everything it depends on, the colour apart (the
// histograms, the scale, its histogram scale and the parameters that select).
std::string MaskKey(const std::string &histId, float histScale, int s, int nearest,
                    const RhfParams &o) {
    return fmt::format(
        "rhf.mask {} s{} scale {:a} patch {} search {} nearest {} threshold {:a} veto {:a} "
        "pool "
        "{:a}",
        histId, s, histScale, o.patchHalf, o.searchHalf, nearest, o.threshold, o.brightVeto,
        PoolBoundOf(s, o));
}

// Scale 0's aggregation kept for later runs with the same colour and selection (rhf at one
// scale and at two filter scale 0 alike).
struct RhfFilteredMemo {
    vk::GpuImage image;
};

// The memo's key of scale 0's aggregation: its selection's key and the colour's identity.
std::string FilteredKey(const std::string &maskKey, const std::string &colorId) {
    return fmt::format("rhf.filtered0 {} colour {}", maskKey, colorId);
}

// The patches scale s selects: itself and its k_NN neighbours at scale 0 (the tool counts
// the patch itself apart from them), by distance alone at coarser scales.
int NearestOf(int s, const RhfParams &o) {
    int knn = s == 0 ? o.knn : 0;
    return knn > 0 ? knn + 1 : 0;
}

// Per strip, the chi-square terms, patch distances and selection into work.mask.
int RecordSelection(StagedRun &run, RhfWork &work, const RhfLayout &layout,
                    const ScaleInputs &in, int nearest, float poolBound, const RhfParams &o) {
    vk::Context &context = run.Context();
    vk::Recorder &recorder = run.Recorder();
    const int Ws = in.color->width, Hs = in.color->height;
    int strips = 0;
    RecordRhfBlockMax(context, recorder, *in.hist, in.histScale, work.blockMax);
    for (int y0 = 0; y0 < Hs; y0 += layout.stripRows, ++strips) {
        int rows = std::min(layout.stripRows, Hs - y0);
        int termBase = std::max(0, y0 - o.patchHalf - o.searchHalf);
        int termRows = std::min(Hs, y0 + rows + o.patchHalf) - termBase;
        RecordRhfTerms(context, recorder, *in.hist, o.searchHalf, termBase, termRows,
                       in.histScale, o.brightVeto / in.histScale, work.blockMax, work.termSum,
                       work.termCount);
        RecordRhfDistance(context, recorder, Ws, Hs, o.patchHalf, o.searchHalf, termBase,
                          termRows, y0, rows, work.termSum, work.termCount, work.dist);
        RecordRhfSelect(context, recorder, Ws, Hs, o.searchHalf, y0, rows, nearest, o.threshold,
                        work.dist, work.pool, poolBound, o.patchHalf, work.mask);
    }
    return strips;
}

// RHF at scale s: the selection (per strip: chi-square terms, patch distances, selection),
// left in `made` for later runs, or `kept`, the one an earlier run on the same histograms
// made (it depends on them alone); then the aggregation of the colour into a new image, or
// at scale 0 `keptFiltered`, an earlier run's of the same colour with the same selection.
// `made` (null without a memo) holds this run's entries until the GPU has filled them.
const vk::GpuImage &RecordFilter(StagedRun &run, RhfScratch &scratch, RhfWork *work,
                                 const RhfLayout &layout, const ScaleInputs &in, int s,
                                 int planes, const RhfParams &o, RunMemo *made,
                                 const std::string &memoKey, const RhfMaskMemo *kept,
                                 const RhfFilteredMemo *keptFiltered,
                                 const std::string &colorId) {
    vk::Context &context = run.Context();
    vk::Recorder &recorder = run.Recorder();
    const int Ws = in.color->width, Hs = in.color->height, n3 = planes - 1;
    const int side = 2 * o.searchHalf + 1, offsets = side * side;
    const int nearest = NearestOf(s, o);
    const size_t maskBytes = size_t(RhfMaskWords(o.searchHalf)) * Ws * Hs * sizeof(uint32_t);
    if (keptFiltered) {
        run.StageAtEnd("filtered s0", keptFiltered->image);
        run.Plan(
            fmt::format("scale 0 ({}x{}): an earlier run's selection and aggregation of "
                        "this colour",
                        Ws, Hs));
        return keptFiltered->image;
    }
    int strips = 0;
    if (!kept) {
        strips = RecordSelection(run, *work, layout, in, nearest, PoolBoundOf(s, o), o);
        if (made) {
            auto entry = std::make_shared<RhfMaskMemo>();
            entry->mask = vk::Buffer(context, maskBytes, "rhf.mask.memo");
            recorder.Copy(work->mask, entry->mask, maskBytes);
            made->Add(memoKey, std::move(entry));
        }
    }
    // At scale 0 with a memo the aggregation is kept there for later runs of this colour.
    const bool keep = made && s == 0;
    std::shared_ptr<RhfFilteredMemo> entry;
    if (keep)
        entry = std::make_shared<RhfFilteredMemo>(
            RhfFilteredMemo{vk::GpuImage(context, Ws, Hs, 3, "rhf.filtered0")});
    vk::GpuImage &filtered = keep ? entry->image
                                  : scratch.images.emplace_back(
                                        context, Ws, Hs, 3, fmt::format("rhf.filtered{}", s));
    if (keep) made->Add(FilteredKey(memoKey, colorId), std::move(entry));
    // The aggregation only reads the mask: a kept one serves without a copy.
    RecordRhfAggregate(context, recorder, *in.color, kept ? kept->mask : work->mask,
                       o.patchHalf, o.searchHalf, filtered);
    run.StageAtEnd(fmt::format("filtered s{}", s), filtered);
    run.Plan(fmt::format(
        "scale {} ({}x{}): chi-square pixel terms for {} offsets x {} bins, {}x{} patch "
        "distances{}, selection of {} nearest (itself + k_NN) + distance < {}{} {}, "
        "aggregation",
        s, Ws, Hs, offsets, n3, 2 * o.patchHalf + 1, 2 * o.patchHalf + 1,
        o.brightVeto > 0
            ? fmt::format(" with bright veto {} (in the frame's sample counts)", o.brightVeto)
            : std::string(" (no bright veto)"),
        nearest, o.threshold,
        PoolBoundOf(s, o) > 0
            ? fmt::format(", no candidate whose bright samples pooled over the patch (Q) "
                          "differ from the centre's (P) as rates over the boxes' pixels (aQ, "
                          "aP) by (P/aP - Q/aQ)^2 > {} (P/aP^2 + Q/aQ^2)",
                          PoolBoundOf(s, o))
            : std::string(),
        kept ? std::string("(an earlier run's on these histograms)")
             : fmt::format("in {} strip(s)", strips)));
    return filtered;
}

// Scale s below the coarsest: u_s - U(D(u_s)) + U(u_{s+1}) into a new image.
const vk::GpuImage &RecordCombine(StagedRun &run, RhfScratch &scratch,
                                  const vk::GpuImage &filtered, const vk::GpuImage &previous,
                                  int s, const RunSetup &setup) {
    double sigma = SigmaOfScale(1);
    vk::GpuImage &low = scratch.images.emplace_back(run.Context(), previous.width,
                                                    previous.height, 3, "rhf.low");
    RecordDownsample(
        run, scratch, filtered.buffer, filtered.width, filtered.height, 3, 1, sigma,
        DownsampleScratch(run, scratch, filtered.width, filtered.height, 3, 1), low.buffer);
    vk::GpuImage &combined = scratch.images.emplace_back(
        run.Context(), filtered.width, filtered.height, 3, fmt::format("rhf.combined{}", s));
    // Scale s of the whole frame: origin / 2^s, size ceil(size / 2^s).
    RhfCombineWindow window;
    if (setup.frameWidth > 0 && setup.frameHeight > 0)
        window = {setup.frameX0 >> s, setup.frameY0 >> s,
                  (setup.frameWidth + (1 << s) - 1) >> s,
                  (setup.frameHeight + (1 << s) - 1) >> s};
    RecordRhfCombine(run.Context(), run.Recorder(), filtered, low, previous, combined, window);
    run.StageAtEnd(fmt::format("combined s{}", s), combined);
    run.Plan(
        fmt::format("scale {}: u_{} - U(D(u_{})) + U(u_{}) with bicubic U (Keys, a = -0.5)", s,
                    s, s, s + 1));
    return combined;
}

void ClampNegative(StagedRun &run, Image &image) {
    size_t negative = 0;
    for (float &v : image.data)
        if (v < 0) {
            v = 0;
            ++negative;
        }
    run.Plan(fmt::format(
        "clamped {} negative value(s) to 0 (the bicubic recombination overshoots at strong "
        "edges; --keep-negative keeps them)",
        negative));
}

}  // namespace

int RhfScalesUsed(int width, int height, const RhfParams &params) {
    int side = 2 * params.searchHalf + 1, used = 1;
    while (used < params.scales && Shrunk(width, used) >= side && Shrunk(height, used) >= side)
        ++used;
    return used;
}

std::vector<float> RhfHistScales(const Image &color, const Image &hist, int scales) {
    // The count channel's totals as Sanitize would leave them: 0 for a pixel with a NaN/Inf
    // colour, a NaN/Inf/negative count as 0.
    HistogramTotals totals;
    totals.pixel.assign(hist.PixelCount(), 0.0);
    std::vector<char> dark(hist.PixelCount(), 0);
    for (int c = 0; c < 3; ++c)
        for (size_t p = 0; p < color.PixelCount(); ++p)
            if (!std::isfinite(color.Plane(c)[p])) dark[p] = 1;
    const float *count = hist.Plane(hist.channels - 1);
    for (size_t p = 0; p < hist.PixelCount(); ++p)
        if (!dark[p] && std::isfinite(count[p]) && count[p] >= 0) totals.pixel[p] = count[p];
    for (double v : totals.pixel) totals.total += v;
    std::vector<float> out(std::max(scales, 1), 1.f);
    for (int s = 1; s < scales; ++s) out[s] = HistScaleOf(totals, hist.width, hist.height, s);
    return out;
}

int RhfReach(const RhfParams &o, int scales) {
    // In full-resolution pixels. filtered_s reads its scale's colour and histograms 2w + b
    // away (a patch around each centre of a patch, b apart), D_s's taps and one pixel of its
    // grid more. combined_s reads filtered_s through U(D(.)) (bicubic U: coarse pixels x/2 - 1
    // .. x/2 + 2; D: r1 taps) and combined_{s+1} through U; the coarsest is its filtered.
    const int r1 = int(RhfGaussianTaps(SigmaOfScale(1), 2).size() / 2);
    int combined = 0;
    for (int s = scales - 1; s >= 0; --s) {
        int taps = s == 0 ? 0 : int(RhfGaussianTaps(SigmaOfScale(s), 1 << s).size() / 2);
        int filtered = (2 * o.patchHalf + o.searchHalf + 2) * (1 << s) + taps;
        combined = s == scales - 1
                       ? filtered
                       : std::max(filtered + (r1 + 6) * (1 << s), 6 * (1 << s) + combined);
    }
    return combined;
}

std::vector<float> RhfBrightPool(const Image &hist, int patchHalf) {
    const int W = hist.width, H = hist.height, n = (hist.channels - 1) / 3;
    std::vector<float> bright(size_t(W) * H, 0.f), pool(size_t(W) * H, 0.f);
    for (size_t p = 0; p < bright.size(); ++p)
        for (int c = 0; c < 3; ++c)
            for (int b = std::max(0, n - 2); b < n; ++b) bright[p] += hist.Plane(c * n + b)[p];
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            float sum = 0.f;
            for (int ty = std::max(0, y - patchHalf); ty <= std::min(H - 1, y + patchHalf);
                 ++ty)
                for (int tx = std::max(0, x - patchHalf); tx <= std::min(W - 1, x + patchHalf);
                     ++tx)
                    sum += bright[size_t(ty) * W + tx];
            pool[size_t(y) * W + x] = sum;
        }
    return pool;
}

void PrepareRhfKernels(vk::Context &context, int width, int height, int planes,
                       const RhfParams &o, const RunSetup &setup) {
    const RhfLayout layout = RhfLayoutFor(context, width, height, planes, o, setup);
    const int scales =
        setup.scalesUsed > 0 ? setup.scalesUsed : RhfScalesUsed(width, height, o);
    // Each scale's selection (RecordSelection), then its aggregation (RecordFilter); the
    // coarse scales' downsampling and recombination (RecordCoarseInputs, RecordCombine).
    context.PrepareKernel(RhfBlockMaxKernel());
    context.PrepareKernel(
        RhfTermsKernel(o.searchHalf, (planes + layout.perSlot - 1) / layout.perSlot));
    context.PrepareKernel(RhfDistanceKernel(o.searchHalf, o.patchHalf));
    for (int s = 0; s < scales; ++s)
        context.PrepareKernel(RhfSelectKernel(o.searchHalf, PoolBoundOf(s, o) > 0));
    context.PrepareKernel(RhfAggregateKernel(o.searchHalf, o.patchHalf));
    if (scales > 1) {
        context.PrepareKernel(RhfDownsampleKernel());
        context.PrepareKernel(RhfCombineKernel());
    }
}

RhfResult RhfDenoise(vk::Context &context, const Image &colorIn, const Image &histIn,
                     const RhfParams &o, const RunSetup &setup) {
    CheckRhfInputs(colorIn, histIn, o);
    RhfResult result;
    StagedRun run(context, setup.keepStages);
    // A non-finite colour empties its pixel's histogram (Sanitize): the selection then
    // depends on the colour too, and is neither taken from the memo nor left in it.
    RunMemo *memo = setup.memo;
    if (memo && !std::all_of(colorIn.data.begin(), colorIn.data.end(),
                             [](float v) { return std::isfinite(v); }))
        memo = nullptr;
    const std::string histId = !memo                  ? std::string()
                               : setup.histId.empty() ? MemoImageId(histIn)
                                                      : setup.histId;
    const std::string colorId = memo ? MemoImageId(colorIn) : std::string();
    // The inputs are copied only where a value must be replaced: the histograms are most of
    // a frame's memory, and auto's runs of rhf all read the same. With a memo the colour is
    // finite, so what is unusable depends on the histograms alone and is counted once.
    const Unusable found = CountUnusableShared(colorIn, histIn, memo, histId);
    for (std::string &warning : UnusableWarnings(found)) run.Warn(std::move(warning));
    Image colorCopy, histCopy;
    if (found.badColor || found.badHist) {
        colorCopy = colorIn;
        histCopy = histIn;
        Sanitize(colorCopy, histCopy);
    }
    const Image &color = colorCopy.Empty() ? colorIn : colorCopy;
    const Image &hist = histCopy.Empty() ? histIn : histCopy;
    const int W = color.width, H = color.height, planes = hist.channels;
    RhfLayout layout = RhfLayoutFor(context, W, H, planes, o, setup);
    int scales = setup.scalesUsed > 0 ? setup.scalesUsed : RhfScalesUsed(W, H, o);
    result.scalesUsed = scales;
    int side = 2 * o.searchHalf + 1;
    for (int s = scales; s < o.scales; ++s)
        run.Plan(
            fmt::format("left out: scale {} ({}x{} is smaller than the {}x{} search window)", s,
                        Shrunk(W, s), Shrunk(H, s), side, side));
    HistogramTotals totals = TotalsOf(hist);
    // Each scale's histogram scale, and the selection an earlier run left for it in the
    // memo: the histograms are uploaded, and the selection's buffers made, only where a
    // scale selects anew.
    std::vector<float> histScales(scales, 1.f);
    std::vector<const RhfMaskMemo *> kept(scales, nullptr);
    std::vector<std::string> keys(scales);
    bool selects = false;
    for (int s = 0; s < scales; ++s) {
        if (s > 0)
            histScales[s] = size_t(s) < setup.histScales.size() && setup.histScales[s] > 0
                                ? setup.histScales[s]
                                : HistScaleOf(totals, W, H, s);
        if (memo) {
            keys[s] = MaskKey(histId, histScales[s], s, NearestOf(s, o), o);
            kept[s] = memo->Find<RhfMaskMemo>(keys[s]);
        }
        selects = selects || !kept[s];
    }

    // Uploads: colour and, where a scale selects, histograms at full resolution.
    vk::GpuImage colorGpu(context, W, H, 3, "rhf.color");
    colorGpu.Upload(color);
    RhfHistogram full;
    std::optional<RhfWork> work;
    if (selects) {
        full = UploadHistogram(context, hist, layout.perSlot);
        run.Plan(fmt::format(
            "histograms: {} planes ({} bins per colour + the count) in {} buffer(s) of up to "
            "{} planes; distances in strips of up to {} rows",
            planes, (planes - 1) / 3, full.slots.size(), layout.perSlot, layout.stripRows));
        work.emplace(context, layout, o.searchHalf, W, H, planes, o.brightPool > 0);
        if (o.brightPool > 0) work->pool.UploadFloats(RhfBrightPool(hist, o.patchHalf));
    } else {
        run.Plan(
            fmt::format("histograms: {} planes ({} bins per colour + the count), not "
                        "uploaded: every scale's selection is an earlier run's",
                        planes, (planes - 1) / 3));
    }

    // Scale 0's aggregation of this colour, where an earlier run made it on the same
    // selection.
    const RhfFilteredMemo *keptFiltered =
        memo && kept[0] ? memo->Find<RhfFilteredMemo>(FilteredKey(keys[0], colorId)) : nullptr;

    // Coarse to fine: each scale filtered, then recombined with the coarser result. The
    // entries this run makes go to the memo once the GPU has written them: a run that throws
    // on the way (out of memory) leaves none unwritten for auto's next candidate.
    RunMemo made;
    RhfScratch scratch;
    const vk::GpuImage *previous = nullptr;
    for (int s = scales - 1; s >= 0; --s) {
        ScaleInputs in{&colorGpu, &full, 1.f};
        if (s > 0)
            in = RecordCoarseInputs(run, scratch, colorGpu, full, planes, s, histScales[s],
                                    !kept[s]);
        const vk::GpuImage &filtered = RecordFilter(
            run, scratch, work ? &*work : nullptr, layout, in, s, planes, o,
            memo ? &made : nullptr, keys[s], kept[s], s == 0 ? keptFiltered : nullptr, colorId);
        previous =
            previous ? &RecordCombine(run, scratch, filtered, *previous, s, setup) : &filtered;
    }
    run.Submit();
    result.image = previous->Download();
    if (memo) memo->Merge(std::move(made));
    if (!o.keepNegative) ClampNegative(run, result.image);
    run.Finish(result);
    return result;
}

}  // namespace mcd
