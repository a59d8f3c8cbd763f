// `mcdenoise denoise`: run a method of the library (include/mcdenoise/mcdenoise.h) on a
// frame, measure it against a reference when given one, and write the result; or the
// same for every frame of a sequence (tools/mcdenoise/sequence.h) on one device.
#include <fmt/format.h>

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <future>
#include <map>
#include <new>
#include <optional>
#include <set>
#include <type_traits>
#include <variant>

#include "host/error.h"
#include "host/io/conventions.h"
#include "host/io/frame.h"
#include "host/metrics.h"
#include "tools/mcdenoise/commands.h"
#include "tools/mcdenoise/method_options.h"
#include "tools/mcdenoise/path_guard.h"
#include "tools/mcdenoise/sequence.h"

namespace mcd::tool {
namespace {

// The result written over its own input frame (--overwrite-input): every layer kept, the
// noisy color under kNoisyColorLayer (a second run keeps the first's, the render's own),
// the file's metadata with the provenance on top. A link to the frame stays one: the
// file it names is replaced.
void WriteOverInput(const io::Frame &frame, const Image &denoised,
                    const std::map<std::string, std::string> &provenance) {
    const Image &noisy =
        frame.Has(kNoisyColorLayer) ? frame.Get(kNoisyColorLayer) : frame.Get("color");
    std::vector<std::pair<std::string, const Image *>> layers = {{"color", &denoised},
                                                                 {kNoisyColorLayer, &noisy}};
    for (const auto &[name, image] : frame.layers)
        if (name != "color" && name != kNoisyColorLayer) layers.push_back({name, &image});
    std::map<std::string, std::string> metadata = frame.metadata;
    for (const auto &[key, value] : provenance) metadata[key] = value;
    io::WriteExr(std::filesystem::canonical(frame.path).string(), layers, metadata);
}

// The GPU buffers a run allocated, by name with their sizes, and its peak.
std::string LedgerText(const Result &result) {
    std::map<std::string, std::pair<int, double>> byName;
    for (const Allocation &a : result.allocations) {
        auto &[count, total] = byName[a.name];
        ++count, total += double(a.bytes);
    }
    std::string text = fmt::format(
        "  GPU buffers: {} allocations, peak {:.2f} MB (staging for transfers not counted):",
        result.allocations.size(), double(result.peakBytes) / 1e6);
    for (const auto &[name, entry] : byName)
        text += fmt::format(" {}{} {:.2f} MB;", name,
                            entry.first > 1 ? fmt::format(" x{}", entry.first) : "",
                            entry.second / 1e6);
    if (result.allocations.empty()) text += " none";
    return text + "\n";
}

// The pipelines the device built so far and what the pipeline cache gave (--explain).
std::string PipelinesText(Device &device) {
    const vk::Context::PipelineStats &p = api::ContextOf(device).Pipelines();
    return fmt::format(
        "  pipelines: {} built in {:.3f} s{}\n", p.built, p.seconds,
        p.loadedBytes ? fmt::format(" (pipeline cache: {} bytes read)", p.loadedBytes) : "");
}

// Every parameter of the method that ran, and those all methods share, as
// "name=value ..." with the values the run used (defaults included), so the output says
// how it was made.
std::string OptionsText(const Method &method, const std::string &ran) {
    std::string text;
    for (const ParamInfo &info : method.Params()) {
        // auto ran every candidate: all their options count.
        if (!info.method.empty() && info.method != ran && ran != "auto") continue;
        std::string value = std::visit(
            [](const auto &v) {
                if constexpr (std::is_same_v<std::decay_t<decltype(v)>, bool>)
                    return std::string(v ? "true" : "false");
                else
                    return fmt::format("{}", v);
            },
            method.Get(info.name));
        // Quoted when empty or spaced, so the string splits back into its parameters.
        if (value.empty() || value.find(' ') != std::string::npos) value = "\"" + value + "\"";
        text += fmt::format("{}{}={}", text.empty() ? "" : " ", info.name, value);
    }
    return text;
}

// The error before and after against a reference, as the line printed under a frame's.
std::string ErrorLine(const Image &noisy, const Image &denoised, const Image &reference,
                      const std::string &referencePath) {
    ErrorMetrics before = CompareImages(noisy, reference);
    ErrorMetrics after = CompareImages(denoised, reference);
    return fmt::format(
        "  error vs {}: relMSE {:.5g} -> {:.5g}, PSNR {:.2f} -> {:.2f} dB, SSIM {:.4f} -> "
        "{:.4f}{}\n",
        referencePath, before.relMse, after.relMse, before.psnr, after.psnr, before.ssim,
        after.ssim,
        after.nonFinite ? fmt::format(" ({} non-finite output values)", after.nonFinite) : "");
}

// The reference image at `path`, refused unless it has the frame's size.
Image ReadReference(const std::string &path, const Image &color) {
    Image reference = io::ReadImage(path);
    if (reference.width != color.width || reference.height != color.height)
        throw Error(fmt::format("reference {} is {}x{}, the frame {}x{}", path, reference.width,
                                reference.height, color.width, color.height));
    return reference;
}

std::map<std::string, std::string> Provenance(const Method &method, const Result &result,
                                              const std::string &input) {
    return {{"mcd:method", result.method},
            {"mcd:source", input},
            {"mcd:options", OptionsText(method, result.method)},
            {"mcd:version", Version()}};
}

std::string FrameLine(const std::string &output, const Result &result) {
    return fmt::format("{}: {} in {:.1f} ms ({:.1f} ms GPU, {} dispatches)\n", output,
                       result.method, result.wallMs, result.GpuMs(), result.timings.size());
}

std::string Seconds(double s) {
    if (s < 60) return fmt::format("{:.1f} s", s);
    if (s < 3600) return fmt::format("{}m{:02d}s", int(s) / 60, int(s) % 60);
    return fmt::format("{}h{:02d}m", int(s) / 3600, int(s) / 60 % 60);
}

// Frames done out of the total and the time left, on stderr: one line redrawn on a
// terminal, one line per frame otherwise (a log file or a farm's job output).
class SequenceProgress {
  public:
    explicit SequenceProgress(int total) : total(total), terminal(isatty(fileno(stderr))) {
        if (terminal) Draw();
    }

    // A long stage of the frame being denoised (terminal only).
    void Stage(const std::string &input, const std::string &stage, int done, int count) {
        if (!terminal) return;
        current = fmt::format(" [{}: {} {}%]", input, stage, 100 * done / std::max(count, 1));
        Draw();
    }
    // Before a line on stdout or stderr: the redrawn line would run into it.
    void Clear() {
        if (terminal && drawn) std::fprintf(stderr, "\r\033[K");
        drawn = false;
    }
    // `setupSeconds`: what the frames so far spent building pipelines, which the next
    // frames will not.
    void FrameDone(const SequenceFrame &frame, bool failed, double setupSeconds) {
        ++done;
        failures += failed;
        current.clear();
        if (done == 1) firstDone = std::chrono::steady_clock::now(), setup = setupSeconds;
        if (terminal) {
            Draw();
            if (done == total) std::fprintf(stderr, "\n"), drawn = false;
        } else {
            std::fprintf(stderr, "denoise: frame %d/%d (%s) %s, %s left\n", done, total,
                         frame.input.c_str(), failed ? "FAILED" : "written", Left().c_str());
        }
    }

  private:
    // From the frames after the first, which also built the pipelines; after the first
    // alone, from its time less the pipelines'.
    std::string Left() const {
        auto now = std::chrono::steady_clock::now();
        double perFrame =
            done >= 2
                ? std::chrono::duration<double>(now - firstDone).count() / (done - 1)
                : std::max(0.0, std::chrono::duration<double>(now - start).count() - setup);
        return Seconds(perFrame * (total - done));
    }
    void Draw() {
        std::fprintf(stderr, "\r\033[Kdenoise: %d/%d frames%s, %s left%s", done, total,
                     failures ? fmt::format(", {} failed", failures).c_str() : "",
                     done ? Left().c_str() : "?", current.c_str());
        std::fflush(stderr);
        drawn = true;
    }

    int total, done = 0, failures = 0;
    double setup = 0;
    bool terminal, drawn = false;
    std::string current;
    std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now(), firstDone;
};

// --auto-map: write the map of auto's largest weights, which the run returned as stage
// "auto.map" (RunOptions::stages), and say so in the plan. A run that combined nothing
// (another method, or auto picking one for --demodulate) has no map: a warning says so.
void WriteAutoMap(const std::string &path, Result &result) {
    if (path.empty()) return;
    for (const Stage &stage : result.stages)
        if (stage.name == "auto.map") {
            io::WritePng(path, stage.image);
            result.plan.push_back("auto: wrote the map of the largest weights to " + path);
            return;
        }
    result.warnings.push_back(fmt::format(
        "--auto-map: {} ran alone, not auto's combination, so no map was written to {}",
        result.method, path));
}

// A frame and its reference, read on the loader thread.
struct LoadedFrame {
    io::Frame frame;
    Image reference;
};

LoadedFrame LoadFrame(const SequenceFrame &f, const mcd::ReadOptions &read) {
    LoadedFrame loaded;
    loaded.frame = io::ReadFrame(f.input, read);
    if (!f.reference.empty())
        loaded.reference = ReadReference(f.reference, loaded.frame.Get("color"));
    return loaded;
}

// Denoise every frame of a sequence on one device, the pipelines built by the first frame
// and kept, the next frame read while this one runs. A frame that fails is reported and
// the others go on; the command fails at the end when any did.
void RunSequence(const std::vector<SequenceFrame> &frames, const Method &method,
                 const mcd::DeviceOptions &deviceOptions, bool explain) {
    std::vector<RolePath> inputs, outputs;
    for (const SequenceFrame &f : frames) {
        inputs.push_back({"input", f.input, "write the sequence elsewhere"});
        inputs.push_back({"--reference", f.reference});
        outputs.push_back({"-o", f.output});
        outputs.push_back({"--preview", f.preview});
        outputs.push_back({"--auto-map", f.map});
    }
    RefuseOverwritingInputs(inputs, outputs);
    // The output directories are made (a farm task may be the first to write there), once
    // nothing is refused.
    std::set<std::string> dirs;
    for (const RolePath &out : outputs)
        if (!out.path.empty()) dirs.insert(std::filesystem::path(out.path).parent_path());
    for (const std::string &dir : dirs)
        if (!dir.empty()) PrepareDirectory(dir);
    for (const SequenceFrame &f : frames) {
        CheckOutputPath(f.output, {".exr", ".png"});
        if (!f.preview.empty()) CheckOutputPath(f.preview, {".png"});
        if (!f.map.empty()) CheckOutputPath(f.map, {".png"});
    }

    auto start = std::chrono::steady_clock::now();
    Device device(deviceOptions);
    SequenceProgress progress(int(frames.size()));
    std::vector<std::string> failed;
    // A frame between its run and the end of its write: what it prints once written.
    struct Pending {
        const SequenceFrame *frame = nullptr;
        std::string out, warnings, error;
        std::future<void> written;
    };
    auto failure = [](const SequenceFrame &f, const std::exception &e) {
        bool known = dynamic_cast<const Error *>(&e) ||
                     dynamic_cast<const std::bad_alloc *>(&e) ||
                     dynamic_cast<const std::filesystem::filesystem_error *>(&e);
        return fmt::format("mcdenoise: error: frame {} ({}): {}{}\n", f.number, f.input,
                           known ? "" : "internal error: ", e.what());
    };
    auto finish = [&](Pending &p) {
        if (p.written.valid()) try {
                p.written.get();
            } catch (const std::exception &e) {
                p.error = failure(*p.frame, e);
            }
        progress.Clear();
        fmt::print(stderr, "{}", p.warnings);
        if (p.error.empty()) {
            fmt::print("{}", p.out);
            std::fflush(stdout);
        } else {
            fmt::print(stderr, "{}", p.error);
            failed.push_back(p.frame->input);
        }
        progress.FrameDone(*p.frame, !p.error.empty(),
                           api::ContextOf(device).Pipelines().seconds);
    };

    // Three frames in flight: the next one read, this one denoised, the last one written.
    // Only the layers the method reads.
    const mcd::ReadOptions read{method.Uses()};
    std::future<LoadedFrame> next =
        std::async(std::launch::async, LoadFrame, frames.front(), std::cref(read));
    Pending previous;
    for (size_t i = 0; i < frames.size(); ++i) {
        const SequenceFrame &f = frames[i];
        Pending current;
        current.frame = &f;
        try {
            LoadedFrame loaded = next.get();
            if (i + 1 < frames.size())
                next =
                    std::async(std::launch::async, LoadFrame, frames[i + 1], std::cref(read));
            RunOptions run;
            run.progress = [&](const std::string &stage, int done, int total) {
                progress.Stage(f.input, stage, done, total);
            };
            if (!f.map.empty()) run.stages = {"auto.map"};
            Result result = method.Run(device, loaded.frame, run);
            WriteAutoMap(f.map, result);
            if (explain) {
                current.out +=
                    fmt::format("{} on {} ({}):\n", result.method, f.input, device.Name());
                for (const std::string &step : result.plan) current.out += "  " + step + "\n";
                current.out += LedgerText(result);
                current.out += PipelinesText(device);
            }
            for (const std::string &warning : result.warnings)
                current.warnings += fmt::format("warning: {}: {}\n", f.input, warning);
            current.out += FrameLine(f.output, result);
            if (!loaded.reference.Empty())
                current.out += ErrorLine(loaded.frame.Get("color"), result.image,
                                         loaded.reference, f.reference);
            std::optional<Image> alpha;
            if (loaded.frame.Has("alpha")) alpha = std::move(loaded.frame.layers.at("alpha"));
            current.written =
                std::async(std::launch::async,
                           [&f, image = std::move(result.image), alpha = std::move(alpha),
                            provenance = Provenance(method, result, f.input)] {
                               const Image *a = alpha ? &*alpha : nullptr;
                               WriteImage(f.output, image, provenance, a);
                               if (!f.preview.empty())
                                   io::WritePngWithAlpha(f.preview, image, a);
                           });
        } catch (const std::exception &e) {
            // The next frame is read even when this one could not be.
            if (i + 1 < frames.size() && !next.valid())
                next =
                    std::async(std::launch::async, LoadFrame, frames[i + 1], std::cref(read));
            current.error = failure(f, e);
        }
        if (previous.frame) finish(previous);
        previous = std::move(current);
    }
    finish(previous);
    double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    fmt::print("{} frames in {:.2f} s ({:.2f} frames/s): {} written, {} failed\n",
               frames.size(), seconds, double(frames.size()) / seconds,
               frames.size() - failed.size(), failed.size());
    if (!failed.empty()) {
        std::string names;
        for (size_t i = 0; i < failed.size() && i < 10; ++i)
            names += (i ? ", " : "") + failed[i];
        if (failed.size() > 10) names += fmt::format(" and {} more", failed.size() - 10);
        throw Error(
            fmt::format("{} of {} frames failed: {}", failed.size(), frames.size(), names));
    }
}

}  // namespace

void AddDenoiseCommand(CLI::App &app) {
    struct Options {
        std::vector<std::string> inputs;
        std::string input, output, method = "auto", reference, preview, frames, autoMap;
        bool explain = false, overwriteInput = false;
        DeviceOptions device;
        MethodOptions methods;
    };
    auto opt = std::make_shared<Options>();
    CLI::App *cmd = app.add_subcommand(
        "denoise", "Denoise a frame, or a sequence of frames, with one method:" +
                       MethodOptions::Summaries());
    cmd->add_option("input", opt->inputs,
                    "noisy frame (EXR with the layers the method needs); for a sequence, "
                    "several frames or one pattern (frame.####.exr or frame.%04d.exr)")
        ->required();
    cmd->add_option("-o,--output", opt->output,
                    "denoised image (.exr or .png); for a sequence, a pattern "
                    "(out.####.exr) or a directory (out/)")
        ->required();
    cmd->add_option("--frames", opt->frames,
                    "the frames of a sequence to denoise: N, FIRST-LAST or a list of those "
                    "(1-50,60); a pattern's frame missing on disk fails that frame");
    cmd->add_option("--method", opt->method,
                    "auto (" + Method("auto").Summary() + "), " + MethodOptions::Names())
        ->capture_default_str();
    cmd->add_option("--reference", opt->reference,
                    "converged image to measure the error against, before and after (for a "
                    "sequence, a pattern or one image for every frame)");
    cmd->add_option("--preview", opt->preview,
                    "also write a tonemapped PNG (for a sequence, a pattern or a directory)");
    cmd->add_option("--auto-map", opt->autoMap,
                    "auto: write the map of the largest weights as a PNG here, each pixel "
                    "coloured by the candidate with the largest weight (--explain gives the "
                    "colours); for a sequence, a pattern (map.####.png) or a directory");
    cmd->add_flag("--explain", opt->explain, "print what runs and what is left out, and why");
    cmd->add_flag("--overwrite-input", opt->overwriteInput,
                  "let -o be the input frame (.exr): the result becomes its color, the noisy "
                  "color is kept as layer " +
                      std::string(kNoisyColorLayer) + " and every other layer as it was");
    opt->device.Add(cmd);
    opt->methods.Add(cmd);

    cmd->callback([opt] {
        Method method = opt->methods.Make(opt->method);
        if (IsSequence(opt->inputs)) {
            if (opt->overwriteInput)
                throw Error(
                    "--overwrite-input is for one frame; a sequence is written to an "
                    "output pattern or directory");
            RunSequence(PlanSequence({opt->inputs, opt->output, opt->preview, opt->reference,
                                      opt->frames, opt->autoMap}),
                        method, opt->device.Options(), opt->explain);
            return;
        }
        if (!opt->frames.empty())
            throw Error(
                fmt::format("--frames selects frames of a sequence; '{}' is one frame "
                            "(give a pattern such as frame.####.exr, or several files)",
                            opt->inputs.front()));
        opt->input = opt->inputs.front();
        CheckOutputPath(opt->output, {".exr", ".png"});
        if (!opt->preview.empty()) CheckOutputPath(opt->preview, {".png"});
        if (!opt->autoMap.empty()) CheckOutputPath(opt->autoMap, {".png"});
        // No output may be a file this run reads, unless the user says so for -o.
        bool inPlace = opt->overwriteInput && SameFile(opt->output, opt->input);
        if (inPlace && std::filesystem::path(opt->output).extension() != ".exr")
            throw Error(fmt::format(
                "--overwrite-input: '{}' would lose the frame's other layers; it needs an .exr "
                "output",
                opt->output));
        RefuseOverwritingInputs(
            {{"input", inPlace ? "" : opt->input,
              "write elsewhere, or pass --overwrite-input to replace the frame's color and "
              "keep its other layers"},
             {"--reference", opt->reference}},
            {{"-o", opt->output}, {"--preview", opt->preview}, {"--auto-map", opt->autoMap}});
        if (inPlace)
            RefuseOverwritingInputs({{"input", opt->input}}, {{"--preview", opt->preview},
                                                              {"--auto-map", opt->autoMap}});
        // Only the layers the method reads; an in-place write keeps every layer.
        auto readStart = std::chrono::steady_clock::now();
        io::Frame frame = io::ReadFrame(
            opt->input, inPlace ? mcd::ReadOptions{} : mcd::ReadOptions{method.Uses()});
        double readMs = std::chrono::duration<double, std::milli>(
                            std::chrono::steady_clock::now() - readStart)
                            .count();
        const Image &color = frame.Get("color");
        Image reference;
        if (!opt->reference.empty()) reference = ReadReference(opt->reference, color);

        Device device(opt->device.Options());
        RunOptions run;
        // Planefit takes seconds to minutes on a CPU device: show how far it is on a
        // terminal (the line is overwritten, then ended).
        bool terminal = isatty(fileno(stderr));
        bool progressShown = false;
        if (terminal)
            run.progress = [&](const std::string &stage, int done, int total) {
                std::fprintf(stderr, "\r%s: %-6s %3d%%",
                             method.Name() == "auto" ? "denoise" : method.Name().c_str(),
                             stage.c_str(), 100 * done / total);
                progressShown = true;
            };
        if (!opt->autoMap.empty()) run.stages = {"auto.map"};
        Result result = method.Run(device, frame, run);
        if (progressShown) std::fprintf(stderr, "\n");
        WriteAutoMap(opt->autoMap, result);
        if (opt->explain) {
            fmt::print("{} on {} ({}):\n", result.method, opt->input, device.Name());
            // How another renderer's layers were converted: the split and noise depend on it.
            if (auto it = frame.metadata.find(io::kConventionKey); it != frame.metadata.end())
                fmt::print("  frame {}\n", it->second);
            std::string read;
            for (const auto &[name, image] : frame.layers)
                read += (read.empty() ? "" : ", ") + name;
            fmt::print("  frame read in {:.0f} ms (layers {})\n", readMs, read);
            for (const std::string &step : result.plan) fmt::print("  {}\n", step);
            fmt::print("{}", LedgerText(result));
            fmt::print("{}", PipelinesText(device));
            // The process's own peak: the frame's layers, the copies and, on a CPU device,
            // the GPU buffers too.
            rusage usage{};
            getrusage(RUSAGE_SELF, &usage);
            fmt::print("  peak memory of the process (RSS): {:.0f} MB\n",
                       double(usage.ru_maxrss) * 1024 / 1e6);
        }
        for (const std::string &warning : result.warnings)
            fmt::print(stderr, "warning: {}\n", warning);
        // Measure before writing: a failure here must not leave a file behind.
        std::string errorLine;
        if (!reference.Empty())
            errorLine = ErrorLine(color, result.image, reference, opt->reference);
        std::map<std::string, std::string> provenance = Provenance(method, result, opt->input);
        const Image *alpha = frame.Has("alpha") ? &frame.Get("alpha") : nullptr;
        if (inPlace)
            WriteOverInput(frame, result.image, provenance);
        else
            WriteImage(opt->output, result.image, provenance, alpha);
        if (!opt->preview.empty()) io::WritePngWithAlpha(opt->preview, result.image, alpha);
        fmt::print("{}{}", FrameLine(opt->output, result), errorLine);
    });
}

}  // namespace mcd::tool
