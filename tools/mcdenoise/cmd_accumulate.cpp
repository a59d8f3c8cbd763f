// `mcdenoise accumulate`: N renders of one view become one frame (host/io/accumulate.h).
#include <fmt/format.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>

#include "host/error.h"
#include "host/io/accumulate.h"
#include "host/io/frame.h"
#include "host/io/image_file.h"
#include "host/io/layer_names.h"
#include "tools/mcdenoise/commands.h"
#include "tools/mcdenoise/path_guard.h"
#include "tools/mcdenoise/progress.h"
#include "tools/mcdenoise/usage.h"

namespace mcd::tool {
namespace {

// ARCHITECTURE.md's order, then the half-buffers.
constexpr const char *kOutputOrder[] = {"color",
                                        "variance",
                                        "spp",
                                        "min",
                                        "max",
                                        "hist",
                                        "direct",
                                        "indirect",
                                        "pivot",
                                        "albedo",
                                        "normal",
                                        "depth",
                                        "objectId",
                                        "partId",
                                        "alpha",
                                        "direct.variance",
                                        "indirect.variance",
                                        "half0.color",
                                        "half1.color"};

struct AccumulateOptions {
    std::vector<std::string> inputs;
    std::string output;
    int histBins = io::AccumulateOptions().histBins;
    bool noHalf0Layers = false;
};

// What the frames' headers say before any pixels are read: a mismatched file is refused at
// once, and repeated seeds or differing sample counts are warned about.
struct Headers {
    std::vector<io::FrameHeader> headers;
    int spp = 0;          // the first frame's, from its metadata (0: unknown)
    bool sameSpp = true;  // every frame states the same
};

Headers ReadHeaders(const std::vector<std::string> &inputs) {
    Headers h;
    std::map<std::string, std::string> seeds;
    for (const std::string &path : inputs) {
        h.headers.push_back(io::ReadFrameHeader(path));
        io::CheckSameLayout(h.headers.front(), h.headers.back());
        if (auto it = h.headers.back().metadata.find("mcd:seed");
            it != h.headers.back().metadata.end()) {
            if (!seeds.emplace(it->second, path).second)
                fmt::print(stderr,
                           "warning: '{}' and '{}' were rendered with the same seed {}: "
                           "they are one frame twice, not independent\n",
                           seeds[it->second], path, it->second);
        }
    }
    const io::FrameHeader &first = h.headers.front();
    if (!first.layers.count("color") || first.layers.at("color") != 3)
        throw Error(fmt::format("'{}' has no R, G, B color layer", inputs.front()),
                    ErrorKind::MissingLayer);
    h.spp = io::SppFromMetadata(first.metadata);
    for (const io::FrameHeader &header : h.headers) {
        if (io::SppFromMetadata(header.metadata) == h.spp) continue;
        h.sameSpp = false;
        fmt::print(stderr,
                   "warning: '{}' states {} spp but '{}' states {}: accumulate "
                   "weights frames equally\n",
                   header.path, io::SppFromMetadata(header.metadata), first.path, h.spp);
    }
    // No count anywhere (every frame has the first's layers): say what is assumed, once.
    if (h.spp == 0 && h.sameSpp && !first.layers.count("spp"))
        fmt::print(stderr,
                   "warning: the frames state no sample count (no spp layer, no mcd:spp, "
                   "samplesPerPixel or cycles.<view layer>.samples attribute): accumulate "
                   "weights them equally and counts 1 spp per frame, so the spp layer is {} "
                   "(awr reads it); state each frame's count in its header, e.g. oiiotool "
                   "f.exr --attrib:type=int mcd:spp 16 -o f.exr\n",
                   h.headers.size());
    return h;
}

// The frames' sums, read one at a time; the bytes read go to *bytes.
io::Frame Accumulate(io::Accumulator &accumulator, const std::vector<std::string> &inputs,
                     double *bytes) {
    int total = int(inputs.size());
    Progress progress(fmt::format("accumulate {} frames", total));
    for (int i = 0; i < total; ++i) {
        progress.Update("", i, total);
        std::error_code ec;
        *bytes += double(std::filesystem::file_size(inputs[i], ec));
        // Only the layers it reads: a frame's histograms and partials are most of it.
        accumulator.Add(io::ReadFrame(inputs[i], {io::AccumulatorReads()}));
    }
    progress.Update("", total, total);
    progress.Done();
    return accumulator.Finish();
}

// Whether the frames shared their camera rays (accumulate --help), said when it matters.
void PrintCameraRays(const io::Accumulator &accumulator, int total, const Headers &h) {
    std::string rayLayers;
    for (const std::string &name : accumulator.RayLayers())
        rayLayers += (rayLayers.empty() ? "" : ", ") + name;
    switch (accumulator.SharedCameraRays()) {
        case io::CameraRays::Shared:
            fmt::print(
                "  warning: the {} frames share their camera rays ({} the same at every "
                "pixel, the color not): their mean is point-sampled (aliased at edges), "
                "not pixel-filtered like a many-spp render. Blender Cycles traces a "
                "pixel's sample 0 through the pixel centre whatever the seed; shift the "
                "camera per frame by a sub-pixel offset drawn from the pixel filter (as "
                "scripts/blender/common.py --jitter does), or render one frame of {} spp\n",
                total, rayLayers,
                h.spp > 0 && h.sameSpp ? std::to_string(h.spp * total)
                                       : fmt::format("{} x the frames'", total));
            break;
        case io::CameraRays::Identical:
            fmt::print(
                "  warning: the {} frames are identical (color{}{} the same at every "
                "pixel): one render repeated, not independent seeds; the variance is "
                "0\n",
                total, rayLayers.empty() ? "" : ", ", rayLayers);
            break;
        case io::CameraRays::Unknown:
            fmt::print(
                "  note: no albedo, normal or depth layer: cannot check whether the "
                "frames share their camera rays\n");
            break;
        case io::CameraRays::Distinct:
            break;
    }
}

// The values left out, the layers not carried and the camera rays' check.
void PrintAccumulateNotes(const io::Accumulator &accumulator, int total, const Headers &h) {
    for (const auto &[layer, count] : accumulator.NonFinite())
        fmt::print("  warning: {} NaN/Inf pixel values in layer {} were left out\n", count,
                   layer);
    // The layers not read, and the renderer passes read but not kept.
    std::set<std::string> notCarried(accumulator.Dropped().begin(),
                                     accumulator.Dropped().end());
    for (const auto &[name, channels] : h.headers.front().layers)
        if (!io::AccumulatorKeeps(name)) notCarried.insert(name);
    std::string dropped;
    for (const std::string &name : notCarried) dropped += (dropped.empty() ? "" : ", ") + name;
    if (!dropped.empty()) fmt::print("  not carried: {}\n", dropped);
    PrintCameraRays(accumulator, total, h);
}

void RunAccumulate(const AccumulateOptions &opt) {
    CheckOutputPath(opt.output, {".exr"});
    std::vector<RolePath> inputs;
    for (const std::string &path : opt.inputs) {
        CheckInputFile(path);
        inputs.push_back({"input", path, ""});
    }
    RefuseOverwritingInputs(inputs, {{"-o", opt.output}});
    if (opt.inputs.size() < 2)
        throw Error("accumulate needs two or more frames (the variance is their spread)",
                    ErrorKind::InvalidArgument);
    Headers h = ReadHeaders(opt.inputs);

    auto start = std::chrono::steady_clock::now();
    io::Accumulator accumulator({opt.histBins, !opt.noHalf0Layers});
    double bytes = 0;
    int total = int(opt.inputs.size());
    io::Frame frame = Accumulate(accumulator, opt.inputs, &bytes);
    // The total the metadata states; an spp layer may vary per pixel (adaptive inputs).
    if (h.spp > 0 && h.sameSpp) frame.metadata["mcd:spp"] = std::to_string(h.spp * total);
    // The first frame's windows too (the frames share the data window).
    for (const char *key : {"mcd:scene", "mcd:size", io::kDataWindowKey, io::kDisplayWindowKey})
        if (auto it = h.headers.front().metadata.find(key);
            it != h.headers.front().metadata.end())
            frame.metadata[key] = it->second;
    std::vector<std::pair<std::string, const Image *>> layers;
    for (const char *name : kOutputOrder)
        if (frame.Has(name)) layers.push_back({name, &frame.Get(name)});
    // Then half0's own layers, in the same order.
    for (const char *name : kOutputOrder)
        if (std::string half = fmt::format("half0.{}", name);
            io::IsHalf0LayerName(half) && frame.Has(half))
            layers.push_back({half, &frame.Get(half)});
    io::WriteExr(opt.output, layers, frame.metadata);
    double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

    fmt::print("{}: {} frames {}x{}, {} layers, {:.2f} s ({:.2f} frames/s, {:.0f} MB/s read)\n",
               opt.output, total, frame.width, frame.height, layers.size(), seconds,
               total / seconds, bytes / seconds * 1e-6);
    PrintAccumulateNotes(accumulator, total, h);
}

}  // namespace

void AddAccumulateCommand(CLI::App &app) {
    auto opt = std::make_shared<AccumulateOptions>();
    CLI::App *cmd = app.add_subcommand(
        "accumulate",
        "Combine N renders of one view (independent seeds) into one frame with statistics\n\n"
        "color = their mean; variance = the unbiased variance of the N frame "
        "means / N; spp = N x the inputs' spp (from an spp layer or the metadata, else N); "
        "min/max over the frames (of their min/max layers when present); hist = RHF "
        "histograms of the frame means binned as the renderer bins samples (with 1-spp "
        "inputs exactly the per-sample histograms; otherwise histograms of the frame "
        "means, which are narrower); albedo, normal, depth, pivot, direct, indirect and "
        "alpha averaged over the frames, objectId and partId from the first frame; "
        "direct.variance and indirect.variance the variances of the direct and indirect means "
        "(as variance: for auto's estimate of bayes's split output); "
        "half0.color and half1.color the means of the even and odd frames, and "
        "half0.<layer> for each of the layers above but objectId and partId, made from the "
        "even frames alone (auto's runs on half0 read them, so that no layer of those runs "
        "carries half1's samples; --no-half0-layers leaves them out); other layers are "
        "not carried (it lists them). NaN/Inf values "
        "are left out and counted per layer. The frames should have equal spp each (it weighs "
        "frames equally and warns where their stated counts differ) and may "
        "come from any renderer.\n\n"
        "It cannot check the seeds themselves (frames "
        "from one seed give variance 0; frames identical bit for bit are warned about). "
        "When the frames have albedo, normal or depth it checks whether they share their "
        "camera rays: those layers the same bits in every frame while the color differs, "
        "as in Blender Cycles' unjittered 1-spp frames (sample 0 goes through the pixel "
        "centre whatever the seed), whose mean is point-sampled, aliased at edges; it warns "
        "and writes mcd:sharedCameraRays = 1 on the output (0 when the rays differ). Blender "
        "Cycles frames made with sample_offset are pieces of one stratified sequence, not "
        "independent: the variance across them over-estimates.");
    // A missing frame is an I/O error (status 8) named by the reader, not a usage error.
    cmd->add_option("inputs", opt->inputs, "input frames (EXR), two or more")->required();
    cmd->add_option("-o,--output", opt->output, "output EXR")->required();
    CheckRange(cmd->add_option("--hist-bins", opt->histBins, "histogram bins per channel")
                   ->capture_default_str(),
               3, 1000, true);
    cmd->add_flag("--no-half0-layers", opt->noHalf0Layers,
                  "write half0.color alone for half0, not half0's own variance, hist, "
                  "albedo, ... (half the accumulator's memory and the file's size)");
    cmd->callback([opt] { RunAccumulate(*opt); });
}

}  // namespace mcd::tool
