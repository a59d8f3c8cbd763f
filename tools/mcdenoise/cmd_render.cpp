// `mcdenoise render`: a built-in scene with the layers the methods use, as one EXR frame.
#include <fmt/format.h>
#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "host/error.h"
#include "host/io/frame.h"
#include "host/kernels/tracing_gather.h"
#include "tools/mcdenoise/commands.h"
#include "tools/mcdenoise/path_guard.h"
#include "tools/mcdenoise/progress.h"
#include "tools/mcdenoise/reference_cache.h"
#include "tools/mcdenoise/usage.h"
#include "tools/render/adaptive.h"
#include "tools/render/motion.h"
#include "tools/render/renderer.h"

namespace mcd::tool {
namespace {

struct RenderCommandOptions {
    std::string scene = "cornell", size = "256x256", layers, output, preview;
    int spp = 16, threads = 0;
    bool sppGiven = false;  // else --reference renders 4096
    uint64_t seed = 1;
    bool reference = false;
    std::string adaptive, denoised, density;
    AwrSamplerParams sampler;
    bool tracingFilter = false, tfCpu = false;
    TracingParams tf;
    double tfMemoryMb = double(render::TracingFilterOptions().memoryBudget) / (1 << 20);
    int tfPartials = render::TracingFilterOptions().partials;
    DeviceOptions device;
    std::string cameraMove;  // "X,Y,Z": the camera's step a frame (world units)
    int frame = 0;
};

// --camera-move's step; throws naming the text when it is not three numbers.
render::Vec3 ParseStep(const std::string &text) {
    double v[3];
    char tail = 0;
    if (std::sscanf(text.c_str(), "%lf,%lf,%lf%c", &v[0], &v[1], &v[2], &tail) != 3 ||
        !std::isfinite(v[0] + v[1] + v[2]))
        throw Error(fmt::format("--camera-move takes X,Y,Z (three numbers), not '{}'", text),
                    ErrorKind::InvalidArgument);
    return {v[0], v[1], v[2]};
}

void RenderAdaptiveFrame(const render::Scene &scene, const RenderCommandOptions &opt,
                         const render::RenderOptions &base) {
    render::AdaptiveOptions options;
    options.width = base.width;
    options.height = base.height;
    options.averageSpp = base.spp;
    options.seed = base.seed;
    options.sampler = opt.sampler;
    options.threads = base.threads;
    Progress progress(fmt::format("render {} {}x{} adaptive at {} spp", scene.name,
                                  options.width, options.height, options.averageSpp));
    options.progress = [&](uint64_t done, uint64_t total) {
        progress.Update("", double(done), double(total));
    };
    vk::Context context(opt.device.ContextOptions());
    render::AdaptiveResult result = render::RenderAdaptive(context, scene, options);
    progress.Done();
    std::vector<std::pair<std::string, const Image *>> layers;
    for (const auto &[name, image] : result.layers) layers.push_back({name, &image});
    const Image &color = result.layers[0].second, &spp = result.layers[2].second;
    Image denoised;
    // Method awr with the library's defaults, as `denoise --method awr` runs it on the file.
    if (!opt.denoised.empty()) {
        Frame frame;
        frame.path = opt.output;
        frame.width = options.width, frame.height = options.height;
        for (const auto &[name, image] : result.layers) frame.layers[name] = image;
        Device device = api::BorrowDevice(context);
        denoised = Method("awr").Run(device, frame).image;
    }
    io::WriteExr(opt.output, layers, result.metadata);
    if (!opt.preview.empty()) io::WritePng(opt.preview, color);
    if (!denoised.Empty()) WriteImage(opt.denoised, denoised, {{"mcd:method", "awr"}});
    float most = *std::max_element(spp.data.begin(), spp.data.end());
    float least = *std::min_element(spp.data.begin(), spp.data.end());
    if (!opt.density.empty()) io::WritePng(opt.density, spp, 1.f / most);
    fmt::print(
        "{}: {} {}x{} adaptive (awr) at {} spp on average, {} rounds, {:.2f} s; "
        "samples per pixel {:.0f}..{:.0f}\n",
        opt.output, scene.name, options.width, options.height, options.averageSpp,
        result.rounds, result.seconds, least, most);
}

// The converged reference, from the cache or rendered into it.
void RenderReference(const RenderCommandOptions &opt, const render::RenderOptions &options) {
    bool rendered = false;
    io::Frame frame = CachedReference(opt.scene, options.width, options.height, options.spp,
                                      options.threads, &rendered);
    std::vector<std::pair<std::string, const Image *>> layers;
    for (const auto &[name, image] : frame.layers) layers.push_back({name, &image});
    io::WriteExr(opt.output, layers, frame.metadata);
    if (!opt.preview.empty()) io::WritePng(opt.preview, frame.Get("color"));
    fmt::print("{}: reference {} {}x{} at {} spp {} ({})\n", opt.output, opt.scene,
               options.width, options.height, options.spp,
               rendered ? "rendered and cached" : "from the cache",
               ReferenceCachePath(opt.scene, options.width, options.height, options.spp));
}

// The tracing filter's figures: where the time went, the bands, the memory.
void PrintTracingStats(const RenderCommandOptions &opt, const render::TracingStats &t) {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    fmt::print(
        "  tracing filter ({} gather, {} partial image(s){}): render {:.2f} s, gather "
        "{:.2f} s ({:.0f}%); {} bands of {} rows; records peak {:.1f} MiB, process "
        "peak "
        "(RSS) {:.0f} MB\n",
        opt.tfCpu ? "CPU reference" : "GPU", t.partials,
        t.partials < opt.tfPartials ? ", the scene has no mirror" : "", t.renderSeconds,
        t.gatherSeconds,
        100 * t.gatherSeconds / std::max(1e-9, t.renderSeconds + t.gatherSeconds), t.bands,
        t.bandRows, double(t.peakRecordBytes) / (1 << 20),
        double(usage.ru_maxrss) * 1024 / 1e6);
    if (t.overBudget)
        fmt::print(
            "  warning: one row and {} rows above and below take more than "
            "--tf-memory {} MiB; the band is one row\n",
            2 * opt.tf.radius, opt.tfMemoryMb);
}

// A frame of the path tracer, with the tracing filter when asked (its gather on the GPU
// unless --tf-cpu).
void RenderFrame(const render::Scene &scene, const RenderCommandOptions &opt,
                 render::RenderOptions options) {
    Progress progress(fmt::format("render {} {}x{} at {} spp", opt.scene, options.width,
                                  options.height, options.spp));
    options.progress = [&](int done, int total) { progress.Update("", done, total); };
    if (opt.tracingFilter) {
        options.tracing.enabled = true;
        options.tracing.params = opt.tf;
        options.tracing.memoryBudget = size_t(opt.tfMemoryMb * (1 << 20));
        options.tracing.partials = opt.tfPartials;
    }
    std::unique_ptr<vk::Context> context;
    std::unique_ptr<TracingGather> gather;
    if (opt.tracingFilter && !opt.tfCpu) {
        context = std::make_unique<vk::Context>(opt.device.ContextOptions());
        gather = std::make_unique<TracingGather>(*context);
        options.tracing.maxWindowRows = gather->MaxRecordRows(options.width, options.spp);
        options.tracing.gather = [&gather](const TracingRecords &records,
                                           const TracingParams &params, int y0, int rows) {
            return gather->Run(records, params, y0, rows);
        };
    }
    render::RenderResult result = render::Render(scene, options);
    progress.Done();
    // A frame of a camera move: its motion vectors, as Blender's Vector pass.
    if (!opt.cameraMove.empty()) {
        render::Vec3 step = ParseStep(opt.cameraMove);
        result.layers.push_back(
            {"motion", render::MotionVectors(scene, scene.camera,
                                             render::CameraAt(scene.camera, step, -1),
                                             render::CameraAt(scene.camera, step, 1),
                                             options.width, options.height)});
        result.metadata["mcd:cameraMove"] =
            fmt::format("{} x frame {}", opt.cameraMove, opt.frame);
    }
    std::vector<std::pair<std::string, const Image *>> layers;
    for (const auto &[name, image] : result.layers) layers.push_back({name, &image});
    io::WriteExr(opt.output, layers, result.metadata);
    if (!opt.preview.empty()) io::WritePng(opt.preview, result.layers[0].second);
    double paths = double(options.width) * options.height * options.spp;
    fmt::print("{}: {} {}x{} at {} spp, {} layers, {:.2f} s ({:.2f} M samples/s)\n", opt.output,
               opt.scene, options.width, options.height, options.spp, result.layers.size(),
               result.seconds, paths / result.seconds * 1e-6);
    if (result.nonFiniteSamples)
        fmt::print("  warning: {} samples were NaN/Inf and counted as 0\n",
                   result.nonFiniteSamples);
    if (opt.tracingFilter) PrintTracingStats(opt, result.tracing);
}

void RunRender(const RenderCommandOptions &opt) {
    render::RenderOptions options;
    ParseSize(opt.size, &options.width, &options.height);
    options.spp = opt.reference && !opt.sppGiven ? 4096 : opt.spp;
    options.seed = opt.seed;
    options.threads = opt.threads;
    options.layers = render::ParseLayerGroups(opt.layers);
    CheckOutputPath(opt.output, {".exr"});
    if (!opt.preview.empty()) CheckOutputPath(opt.preview, {".png"}, "--preview");
    // The outputs apart from each other and from the cached reference this run reads.
    RefuseOverwritingInputs({{"the cached reference",
                              opt.reference ? ReferenceCachePath(opt.scene, options.width,
                                                                 options.height, options.spp)
                                            : ""}},
                            {{"-o", opt.output},
                             {"--preview", opt.preview},
                             {"--denoised", opt.denoised},
                             {"--density", opt.density}});
    render::Scene scene = render::BuildScene(opt.scene);
    if (!opt.cameraMove.empty()) {
        if (opt.reference || !opt.adaptive.empty())
            throw Error(
                "--camera-move renders a frame of a move: drop --reference and --adaptive "
                "(a moving frame's reference is a render at many --spp)",
                ErrorKind::InvalidArgument);
        scene.camera = render::CameraAt(scene.camera, ParseStep(opt.cameraMove), opt.frame);
    } else if (opt.frame != 0) {
        throw Error("--frame numbers a frame of a --camera-move", ErrorKind::InvalidArgument);
    }
    if (!opt.adaptive.empty()) {
        if (opt.adaptive != "awr")
            throw Error("--adaptive takes awr, not '" + opt.adaptive + "'",
                        ErrorKind::InvalidArgument);
        if (opt.reference || !opt.layers.empty())
            throw Error("--adaptive writes its own layers; drop --reference and --layers",
                        ErrorKind::InvalidArgument);
        if (!opt.denoised.empty())
            CheckOutputPath(opt.denoised, {".exr", ".png"}, "--denoised");
        if (!opt.density.empty()) CheckOutputPath(opt.density, {".png"}, "--density");
        RenderAdaptiveFrame(scene, opt, options);
    } else if (opt.reference) {
        RenderReference(opt, options);
    } else {
        RenderFrame(scene, opt, options);
    }
}

void AddFrameOptions(CLI::App *cmd, RenderCommandOptions &opt) {
    std::string names;
    for (const std::string &n : render::SceneNames()) names += (names.empty() ? "" : ", ") + n;
    cmd->add_option("-o,--output", opt.output, "output EXR")->required();
    cmd->add_option("--scene", opt.scene, "scene: " + names)->capture_default_str();
    CheckRange(cmd->add_option("--spp", opt.spp,
                               "samples per pixel (default 16; 4096 with --reference)"),
               1, 1e30, true);
    // A malformed or empty size is a command-line mistake, refused by the parse.
    cmd->add_option("--size", opt.size, "image size WxH")
        ->capture_default_str()
        ->check(CLI::Validator(
            [](std::string &text) -> std::string {
                int width = 0, height = 0;
                try {
                    ParseSize(text, &width, &height);
                } catch (const Error &e) {
                    return e.what();
                }
                return "";
            },
            ""));
    // A negative seed would wrap to a huge one: refused, not taken.
    cmd->add_option("--seed", opt.seed, "random seed (same seed, same frame)")
        ->capture_default_str()
        ->check(CLI::Validator(
            [](std::string &value) -> std::string {
                return value.starts_with('-')
                           ? value + " is out of range (a whole number, 0 or more)"
                           : "";
            },
            ""));
    cmd->add_option("--layers", opt.layers,
                    "extra layer groups, comma-separated: hist (RHF histograms), split "
                    "(direct, indirect and the variances of their means), pivot, gbuffer "
                    "(albedo, normal, depth, objectId, "
                    "partId), or all; not in all: partials (Ershov section 8: "
                    "partial<k>.color, .pivot and .variance per number k < 2 of mirror bounces "
                    "before the first diffuse/glossy hit, and the remainder) and zhist "
                    "(histograms of color / pivot, with the pivot, for denoise --method rhf "
                    "--demodulate pivot) and halves (half0.color, half1.color: the means of "
                    "the even and of the odd samples, for auto's error estimate; from 3 spp on "
                    "also half0.<layer> for variance, spp, min, max and each group's hist, "
                    "split and gbuffer layers but the ids, of the even samples alone); color, "
                    "variance, spp, min and max are always written");
    CheckRange(cmd->add_option("--threads", opt.threads,
                               "threads (default 0: all cores; the frame is the same)"),
               0, 4096, true);
    cmd->add_option("--preview", opt.preview, "also write a tonemapped PNG of the color");
    cmd->add_option("--camera-move", opt.cameraMove,
                    "a frame of a camera move: X,Y,Z, the camera's step a frame in world units "
                    "(eye and target move together); writes the layer motion (motion vectors "
                    "as Blender's Vector pass) for denoise's temporal mode");
    cmd->add_option("--frame", opt.frame,
                    "with --camera-move: the frame's number (the camera moved by it x the "
                    "step)")
        ->capture_default_str();
    cmd->add_flag(
        "--reference", opt.reference,
        "a converged reference (the always-written layers, its own fixed seed), cached under "
        "$XDG_CACHE_HOME/mcdenoise (else ~/.cache/mcdenoise) by scene, size, spp and "
        "renderer version, so tests and benchmarks render it once");
    // The reference has its own seed and layers: refuse options it would ignore.
    cmd->get_option("--reference")->excludes("--layers")->excludes("--seed");
}

void AddAdaptiveOptions(CLI::App *cmd, RenderCommandOptions &opt) {
    const char *group = "Adaptive sampling (--adaptive awr)";
    cmd->add_option("--adaptive", opt.adaptive,
                    "adaptive sampler: awr (Overbeck et al. 4.1; --spp is then the average, "
                    "at least 4; writes color, variance, spp = the sample density, min, max)")
        ->group(group);
    cmd->add_option("--denoised", opt.denoised,
                    "with --adaptive awr: also write the AWR reconstruction of the frame here")
        ->group(group);
    cmd->add_option(
           "--density", opt.density,
           "with --adaptive: also write the sample density as a PNG (brightest = most)")
        ->group(group);
    CheckRange(cmd->add_option("--sampler-renorm", opt.sampler.lowSum,
                               "with --adaptive awr: sum of the squared 1D low-pass filter in "
                               "the priorities' variance DWT (eq. 9); above 1 favours coarse "
                               "levels")
                   ->capture_default_str()
                   ->group(group),
               0.5, 4, false);
    CheckRange(
        cmd->add_option("--contrast-floor", opt.sampler.contrastFloor,
                        "with --adaptive awr: luminance f under the mean in the "
                        "sampler's Mitchell contrast, (Imax - Imin)^2 / ((Imax + Imin)^2 "
                        "+ 4 f^2); 0 is the paper's contrast, which spends samples on "
                        "near-black pixels; 0.1 matches relMSE's 0.01")
            ->capture_default_str()
            ->group(group),
        0, 1e6, false);
    // These mean nothing without the sampler: say so rather than ignore them.
    for (const char *name : {"--denoised", "--density", "--sampler-renorm", "--contrast-floor"})
        cmd->get_option(name)->needs("--adaptive");
}

void AddTracingOptions(CLI::App *cmd, RenderCommandOptions &opt) {
    const char *group = "Tracing filter (--tracing-filter)";
    CLI::Option *tracingFlag =
        cmd->add_flag("--tracing-filter", opt.tracingFilter,
                      "Ershov's tracing filter (section 5): the light after each pixel's first "
                      "diffuse/glossy hit gathered from its neighbours' samples, re-weighted "
                      "for its surface; color is the filtered frame, color.unfiltered the "
                      "plain one")
            ->group(group);
    auto ranged = [&](CLI::Option *option, double min, double max, bool integer) {
        CheckRange(option->capture_default_str()->group(group), min, max, integer);
    };
    ranged(cmd->add_option("--tf-radius", opt.tf.radius,
                           "tracing filter: neighbourhood radius in pixels (a disk)"),
           0, 1000, true);
    ranged(
        cmd->add_option("--tf-alpha", opt.tf.alpha,
                        "tracing filter: eq. 17's exp(-alpha |p - p'|^2), per squared pixel"),
        0, 1e6, false);
    ranged(cmd->add_option("--tf-beta", opt.tf.beta,
                           "tracing filter: eq. 17's exp(-beta (1 - n.n')) on the normals"),
           0, 1e6, false);
    ranged(
        cmd->add_option("--tf-gamma", opt.tf.gamma,
                        "tracing filter: eq. 17's exp(-gamma F^2), F the larger ratio of the "
                        "two surfaces' BSDF x cosine along the neighbour's direction"),
        0, 1e6, false);
    ranged(cmd->add_option("--tf-self-floor", opt.tf.selfFloor,
                           "tracing filter: the neighbours' fixed weights sum to at most this, "
                           "so a pixel's own samples keep at least 1 - it (the paper: 0.5)"),
           0, 1, false);
    ranged(cmd->add_option("--tf-memory", opt.tfMemoryMb,
                           "tracing filter: MiB for the records of a band and its halo (40 B "
                           "per sample and filtered partial image); the band height follows"),
           1, 1e7, false);
    ranged(cmd->add_option("--tf-partials", opt.tfPartials,
                           "tracing filter: how many partial images are filtered, each on its "
                           "own (Ershov section 8; 1: the first hit only, 2: also the light "
                           "seen after one mirror bounce); each takes its own records"),
           1, render::kPartialTypes, true);
    cmd->add_flag("--tf-cpu", opt.tfCpu,
                  "tracing filter: gather with the CPU reference instead of the GPU kernel")
        ->group(group);
    // The --tf-* options mean nothing without the filter: say so rather than ignore them.
    for (const char *name : {"--tf-radius", "--tf-alpha", "--tf-beta", "--tf-gamma",
                             "--tf-self-floor", "--tf-memory", "--tf-partials", "--tf-cpu"})
        cmd->get_option(name)->needs(tracingFlag);
}

}  // namespace

void AddRenderCommand(CLI::App &app) {
    auto opt = std::make_shared<RenderCommandOptions>();
    CLI::App *cmd = app.add_subcommand(
        "render",
        "Render a built-in scene with the built-in path tracer into a multi-layer EXR");
    AddFrameOptions(cmd, *opt);
    opt->device.Add(cmd);
    AddAdaptiveOptions(cmd, *opt);
    AddTracingOptions(cmd, *opt);
    // The tracing filter renders its own frame: refuse the options that make another.
    cmd->get_option("--tracing-filter")->excludes("--reference")->excludes("--adaptive");
    cmd->callback([opt, cmd] {
        opt->sppGiven = cmd->get_option("--spp")->count() > 0;
        RunRender(*opt);
    });
}

}  // namespace mcd::tool
