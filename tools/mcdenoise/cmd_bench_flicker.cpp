// `mcdenoise bench flicker`: how much a denoised sequence flickers (docs/sequences.md).
// Sequences of one shot, a static and a moving camera, from the built-in renderer (rendered
// here and cached) and from Blender Cycles (scripts/blender/sequences.sh's cache); each
// denoised frame by frame and with the temporal mode, and by Open Image Denoise frame by
// frame where the peer is present. Per row: the temporal variance of the error (output
// minus reference) per pixel and on 8x8 block means, as a ratio to the noisy input's; the
// mean frame-to-frame difference of the error; relMSE (mean over frames, and the worst
// frame's ratio to the frame-by-frame run); and the brightness of the output over the
// reference's. Strips of every frame (noisy, outputs, reference) are written as PNGs.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>

#include "host/error.h"
#include "host/io/frame.h"
#include "host/metrics.h"
#include "mcdenoise/temporal.h"
#include "tools/mcdenoise/bench_real.h"
#include "tools/mcdenoise/commands.h"
#include "tools/mcdenoise/method_options.h"
#include "tools/mcdenoise/reference_cache.h"
#include "tools/render/motion.h"
#include "tools/render/renderer.h"

namespace mcd::tool {
namespace {

namespace fs = std::filesystem;

std::string CacheRoot() {
    const char *xdg = std::getenv("XDG_CACHE_HOME");
    const char *home = std::getenv("HOME");
    return xdg && *xdg ? std::string(xdg) + "/mcdenoise"
                       : std::string(home ? home : ".") + "/.cache/mcdenoise";
}

struct FlickerOptions {
    std::string size = "96x96", scene = "cornell", method = "auto", out = "out/bench-flicker";
    std::string blender = CacheRoot() + "/sequences96";
    std::string oidn = DefaultOidnPeer();
    std::string cache = CacheRoot() + "/flicker";
    int frames = 6, spp = 16, referenceSpp = 2048, cameraReferenceSpp = 1024;
    std::string cameraMove = "0.15,0,0";
    DeviceOptions device;
    MethodOptions methods;  // and the temporal mode's
};

// A sequence: its frames on disk (read whole), and a reference per frame.
struct Sequence {
    std::string name;
    std::vector<std::string> paths;
    std::vector<Frame> frames;
    std::vector<Image> references;
};

// Frame `number` of the built-in renderer's shot: a still camera, or one moved by `step`
// a frame, with the layers every method reads; rendered into `path` unless cached.
void RenderShotFrame(const render::Scene &base, const FlickerOptions &opt,
                     const std::optional<render::Vec3> &step, int number, int spp,
                     uint64_t seed, const std::string &path) {
    if (fs::exists(path)) return;
    render::Scene scene = base;
    if (step) scene.camera = render::CameraAt(base.camera, *step, number);
    render::RenderOptions options;
    ParseSize(opt.size, &options.width, &options.height);
    options.spp = spp;
    options.seed = seed;
    options.layers = render::kLayersAll | render::kLayersHalves;
    render::RenderResult result = render::Render(scene, options);
    if (step)
        result.layers.push_back(
            {"motion", render::MotionVectors(scene, scene.camera,
                                             render::CameraAt(scene.camera, *step, -1),
                                             render::CameraAt(scene.camera, *step, 1),
                                             options.width, options.height)});
    std::vector<std::pair<std::string, const Image *>> layers;
    for (const auto &[name, image] : result.layers) layers.push_back({name, &image});
    std::string temporary = path + ".partial.exr";
    io::WriteExr(temporary, layers, result.metadata);
    fs::rename(temporary, path);
}

render::Vec3 Step(const std::string &text) {
    double v[3];
    char tail = 0;
    if (std::sscanf(text.c_str(), "%lf,%lf,%lf%c", &v[0], &v[1], &v[2], &tail) != 3)
        throw Error(fmt::format("--camera-move takes X,Y,Z, not '{}'", text),
                    ErrorKind::InvalidArgument);
    return {v[0], v[1], v[2]};
}

// The built-in renderer's shot, static or moving: frames with seeds 1..N; the static one's
// reference the cached reference, the moving one's a render per frame at the reference spp.
Sequence OurSequence(const FlickerOptions &opt, bool moving) {
    Sequence s;
    s.name = fmt::format("ours {} {} {}", opt.scene, moving ? "camera" : "static", opt.size);
    // "_h0": frames with half0's own layers (older caches have half0.color alone).
    std::string dir = fmt::format("{}/{}_{}_{}_{}spp_h0", opt.cache, opt.scene,
                                  moving ? "camera" : "static", opt.size, opt.spp);
    fs::create_directories(dir);
    render::Scene scene = render::BuildScene(opt.scene);
    std::optional<render::Vec3> step;
    if (moving) step = Step(opt.cameraMove);
    int width, height;
    ParseSize(opt.size, &width, &height);
    Image still;
    if (!moving)
        still = CachedReference(opt.scene, width, height, opt.referenceSpp).Get("color");
    for (int f = 1; f <= opt.frames; ++f) {
        std::string path = fmt::format("{}/frame.{:04d}.exr", dir, f);
        RenderShotFrame(scene, opt, step, f, opt.spp, uint64_t(f), path);
        s.paths.push_back(path);
        s.frames.push_back(io::ReadFrame(path));
        if (!moving) {
            s.references.push_back(still);
            continue;
        }
        std::string ref = fmt::format("{}/ref{}.{:04d}.exr", dir, opt.cameraReferenceSpp, f);
        RenderShotFrame(scene, opt, step, f, opt.cameraReferenceSpp, 100000 + uint64_t(f), ref);
        s.references.push_back(io::ReadFrame(ref).Get("color"));
    }
    return s;
}

// sequences.sh's cache: DIR/cornell_static (ref.exr for all) or DIR/cornell_camera
// (ref.NNNN.exr); none when the frames or references are not all there.
std::optional<Sequence> BlenderSequence(const FlickerOptions &opt, bool moving) {
    std::string dir = opt.blender + (moving ? "/cornell_camera" : "/cornell_static");
    Sequence s;
    s.name = fmt::format("blender cornell {}", moving ? "camera" : "static");
    for (int f = 1; f <= opt.frames; ++f) {
        std::string path = fmt::format("{}/frame.{:04d}.exr", dir, f);
        std::string ref = moving ? fmt::format("{}/ref.{:04d}.exr", dir, f) : dir + "/ref.exr";
        if (!fs::exists(path) || !fs::exists(ref)) {
            fmt::print(
                "{}: {} or {} missing (scripts/blender/sequences.sh renders them): "
                "left out\n",
                s.name, path, ref);
            return std::nullopt;
        }
        s.paths.push_back(path);
        s.frames.push_back(io::ReadFrame(path));
        s.references.push_back(io::ReadFrame(ref).Get("color"));
    }
    return s;
}

// The sequence's frames denoised one by one, or each gathered with its neighbours first.
std::vector<Image> DenoiseSequence(Device &device, const Method &method, const Sequence &s,
                                   const Temporal *temporal) {
    std::vector<Image> out;
    int n = int(s.frames.size());
    for (int t = 0; t < n; ++t) {
        if (!temporal) {
            out.push_back(method.Run(device, s.frames[t]).image);
            continue;
        }
        std::map<int, const Frame *> window;
        for (int k = std::max(0, t - temporal->Radius());
             k <= std::min(n - 1, t + temporal->Radius()); ++k)
            window[k - t] = &s.frames[k];
        TemporalResult g = temporal->Gather(device, window);
        out.push_back(method.Run(device, g.frame).image);
    }
    return out;
}

// Open Image Denoise on each frame alone (colour, albedo and normal), through the peer's
// script, its outputs cached beside the frames; none when the peer is absent or fails.
std::optional<std::vector<Image>> OidnSequence(const FlickerOptions &opt, const Sequence &s) {
    if (opt.oidn.empty() || !fs::exists(opt.oidn + "/denoise_exr.py")) return std::nullopt;
    std::vector<Image> out;
    for (const std::string &path : s.paths) {
        std::string result = path + ".oidn.exr";
        if (!fs::exists(result)) {
            std::string command =
                fmt::format("/usr/bin/python3 '{}/denoise_exr.py' '{}' '{}' --aux > /dev/null",
                            opt.oidn, path, result);
            if (std::system(command.c_str()) != 0 || !fs::exists(result)) {
                fmt::print("oidn failed on {}: its row is left out\n", path);
                return std::nullopt;
            }
        }
        out.push_back(io::ReadFrame(result).Get("color"));
    }
    return out;
}

// The image averaged over blocks of b x b pixels (the last ones partial).
Image BlockMeans(const Image &image, int b) {
    Image out((image.width + b - 1) / b, (image.height + b - 1) / b, image.channels);
    for (int c = 0; c < image.channels; ++c)
        for (int by = 0; by < out.height; ++by)
            for (int bx = 0; bx < out.width; ++bx) {
                double sum = 0;
                int count = 0;
                for (int y = by * b; y < std::min(image.height, by * b + b); ++y)
                    for (int x = bx * b; x < std::min(image.width, bx * b + b); ++x)
                        sum += image.At(c, y, x), ++count;
                out.At(c, by, bx) = float(sum / count);
            }
    return out;
}

// Per pixel and channel, the variance over the frames of the error (output minus
// reference), averaged over the image.
double TemporalVariance(const std::vector<Image> &out, const std::vector<Image> &ref) {
    size_t size = out[0].data.size();
    double total = 0, n = double(out.size());
    for (size_t i = 0; i < size; ++i) {
        double sum = 0, squares = 0;
        for (size_t t = 0; t < out.size(); ++t) {
            double e = double(out[t].data[i]) - ref[t].data[i];
            sum += e, squares += e * e;
        }
        total += std::max(0.0, squares / n - (sum / n) * (sum / n));
    }
    return total / double(size);
}

struct Row {
    std::string sequence, name;
    double variance = 0, blockVariance = 0, frameDiff = 0, relMse = 0, worst = 0,
           brightness = 0;
};

Row Measure(const std::string &sequence, const std::string &name, const std::vector<Image> &out,
            const std::vector<Image> &noisy, const std::vector<Image> &ref,
            const std::vector<Image> *alone) {
    Row r{sequence, name};
    auto blocks = [](const std::vector<Image> &images) {
        std::vector<Image> b;
        for (const Image &image : images) b.push_back(BlockMeans(image, 8));
        return b;
    };
    r.variance = TemporalVariance(out, ref) / TemporalVariance(noisy, ref);
    r.blockVariance = TemporalVariance(blocks(out), blocks(ref)) /
                      TemporalVariance(blocks(noisy), blocks(ref));
    for (size_t t = 0; t < out.size(); ++t) {
        ErrorMetrics e = CompareImages(out[t], ref[t]);
        r.relMse += e.relMse / double(out.size());
        if (alone)
            r.worst = std::max(r.worst, e.relMse / CompareImages((*alone)[t], ref[t]).relMse);
        double sumOut = 0, sumRef = 0;
        for (size_t i = 0; i < ref[t].data.size(); ++i)
            sumOut += out[t].data[i], sumRef += ref[t].data[i];
        r.brightness += sumOut / sumRef / double(out.size());
        if (t == 0) continue;
        double diff = 0;
        for (size_t i = 0; i < ref[t].data.size(); ++i)
            diff += std::fabs((double(out[t].data[i]) - ref[t].data[i]) -
                              (double(out[t - 1].data[i]) - ref[t - 1].data[i]));
        r.frameDiff += diff / double(ref[t].data.size()) / double(out.size() - 1);
    }
    return r;
}

// Every frame side by side, one row of the strip per output (top to bottom as given).
void WriteStrip(const std::string &path, const std::vector<const std::vector<Image> *> &rows) {
    const Image &first = (*rows[0])[0];
    int w = first.width, h = first.height, n = int(rows[0]->size());
    Image strip(w * n, h * int(rows.size()), 3);
    for (size_t r = 0; r < rows.size(); ++r)
        for (int t = 0; t < n; ++t)
            for (int c = 0; c < 3; ++c)
                for (int y = 0; y < h; ++y)
                    for (int x = 0; x < w; ++x)
                        strip.At(c, int(r) * h + y, t * w + x) =
                            (*rows[r])[t].At(std::min(c, (*rows[r])[t].channels - 1), y, x);
    io::WritePng(path, strip);
}

std::vector<Row> BenchSequence(const FlickerOptions &opt, Device &device, const Method &method,
                               const Temporal &temporal, const Sequence &s) {
    std::vector<Image> noisy;
    for (const Frame &f : s.frames) noisy.push_back(f.Get("color"));
    std::vector<Image> alone = DenoiseSequence(device, method, s, nullptr);
    std::vector<Image> gathered = DenoiseSequence(device, method, s, &temporal);
    std::optional<std::vector<Image>> oidn = OidnSequence(opt, s);
    std::vector<Row> rows = {
        Measure(s.name, "noisy", noisy, noisy, s.references, nullptr),
        Measure(s.name, method.Name() + " frame by frame", alone, noisy, s.references, &alone),
        Measure(s.name, method.Name() + " temporal", gathered, noisy, s.references, &alone)};
    if (oidn)
        rows.push_back(
            Measure(s.name, "oidn 2.4.1 frame by frame", *oidn, noisy, s.references, &alone));
    std::vector<const std::vector<Image> *> strip = {&noisy, &alone, &gathered};
    if (oidn) strip.push_back(&*oidn);
    strip.push_back(&s.references);
    std::string name = s.name;
    std::replace(name.begin(), name.end(), ' ', '_');
    WriteStrip(fmt::format("{}/{}.png", opt.out, name), strip);
    return rows;
}

void PrintRows(const std::vector<Row> &rows, const std::string &csvPath) {
    fmt::print("{:<28} {:<26} {:>9} {:>9} {:>10} {:>10} {:>8} {:>7}\n", "sequence", "output",
               "tvar", "tvar 8x8", "frame diff", "relMSE", "worst", "bright");
    std::ofstream csv(csvPath);
    csv << "sequence,output,tvar,tvar8,framediff,relmse,worst_vs_alone,brightness\n";
    for (const Row &r : rows) {
        fmt::print("{:<28} {:<26} {:>9.4f} {:>9.4f} {:>10.4g} {:>10.4g} {:>8.3f} {:>7.4f}\n",
                   r.sequence, r.name, r.variance, r.blockVariance, r.frameDiff, r.relMse,
                   r.worst, r.brightness);
        csv << fmt::format("{},{},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g}\n", r.sequence,
                           r.name, r.variance, r.blockVariance, r.frameDiff, r.relMse, r.worst,
                           r.brightness);
    }
    fmt::print(
        "tvar, tvar 8x8: the temporal variance of the error per pixel and of 8x8 block "
        "means, over the noisy input's; frame diff: mean |error(t) - error(t-1)|; "
        "worst: the largest ratio of a frame's relMSE to the frame-by-frame run's; "
        "bright: mean output over mean reference. Strips (rows: noisy, frame by frame, "
        "temporal, [oidn], reference) and {}\n",
        csvPath);
}

void RunBenchFlicker(const FlickerOptions &opt) {
    if (opt.frames < 2)
        throw Error("--frames: a sequence needs at least 2", ErrorKind::InvalidArgument);
    fs::create_directories(opt.out);
    Method method = opt.methods.Make(opt.method);
    Temporal temporal;
    opt.methods.Apply(temporal);
    Device device(opt.device.Options());
    std::vector<Sequence> sequences = {OurSequence(opt, false), OurSequence(opt, true)};
    for (bool moving : {false, true})
        if (std::optional<Sequence> s = BlenderSequence(opt, moving)) sequences.push_back(*s);
    std::vector<Row> rows;
    for (const Sequence &s : sequences) {
        fmt::print(stderr, "bench flicker: {} ({} frames)\n", s.name, s.frames.size());
        for (Row &r : BenchSequence(opt, device, method, temporal, s)) rows.push_back(r);
    }
    PrintRows(rows, opt.out + "/flicker.csv");
}

}  // namespace

void AddBenchFlickerCommand(CLI::App *bench) {
    auto opt = std::make_shared<FlickerOptions>();
    CLI::App *cmd = bench->add_subcommand(
        "flicker",
        "Flicker of denoised sequences: a static and a moving camera from the built-in "
        "renderer and from Blender, frame by frame, temporal, and OIDN");
    cmd->add_option("--size", opt->size, "the built-in renderer's frames, WxH")
        ->capture_default_str();
    cmd->add_option("--scene", opt->scene, "the built-in renderer's scene")
        ->capture_default_str();
    cmd->add_option("--frames", opt->frames, "frames of each sequence")->capture_default_str();
    cmd->add_option("--spp", opt->spp, "the built-in renderer's samples per pixel")
        ->capture_default_str();
    cmd->add_option("--reference-spp", opt->referenceSpp,
                    "its static reference's samples per pixel (one render, cached)")
        ->capture_default_str();
    cmd->add_option("--camera-reference-spp", opt->cameraReferenceSpp,
                    "its moving camera's references' samples per pixel (one a frame)")
        ->capture_default_str();
    cmd->add_option("--camera-move", opt->cameraMove, "its moving camera's step a frame, X,Y,Z")
        ->capture_default_str();
    cmd->add_option("--blender", opt->blender,
                    "scripts/blender/sequences.sh's cache (cornell_static, cornell_camera); "
                    "left out where absent")
        ->capture_default_str();
    cmd->add_option("--oidn", opt->oidn,
                    "Open Image Denoise's peer directory (its denoise_exr.py); its row is left "
                    "out where absent or failing")
        ->capture_default_str();
    cmd->add_option("--cache", opt->cache, "where the built-in renderer's frames are cached")
        ->capture_default_str();
    cmd->add_option("--out", opt->out, "strips and flicker.csv")->capture_default_str();
    cmd->add_option("--method", opt->method, "the method")->capture_default_str();
    opt->device.Add(cmd);
    opt->methods.Add(cmd);
    opt->methods.AddParams(cmd, Temporal().Params());
    cmd->callback([opt] { RunBenchFlicker(*opt); });
}

}  // namespace mcd::tool
