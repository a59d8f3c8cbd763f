#include "tools/mcdenoise/denoise_frames.h"

#include <fmt/format.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <future>
#include <map>
#include <optional>
#include <type_traits>
#include <variant>

#include "host/error.h"
#include "host/io/conventions.h"
#include "host/io/frame.h"
#include "host/metrics.h"
#include "tools/mcdenoise/commands.h"
#include "tools/mcdenoise/exit_status.h"
#include "tools/mcdenoise/progress.h"

namespace mcd::tool {
namespace {

using Clock = std::chrono::steady_clock;

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

std::map<std::string, std::string> Provenance(const Method &method, const Result &result,
                                              const std::string &input) {
    return {{"mcd:method", result.method},
            {"mcd:source", input},
            {"mcd:options", OptionsText(method, result.method)},
            {"mcd:version", Version()}};
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

std::string FrameLine(const std::string &output, const Result &result) {
    return fmt::format("{}: {} in {:.1f} ms ({:.1f} ms GPU, {} dispatches)\n", output,
                       result.method, result.wallMs, result.GpuMs(), result.timings.size());
}

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
    double readMs = 0;  // the frame's read
};

LoadedFrame LoadFrame(const SequenceFrame &f, const mcd::ReadOptions &read) {
    LoadedFrame loaded;
    CheckInputFile(f.input);
    Clock::time_point start = Clock::now();
    loaded.frame = io::ReadFrame(f.input, read);
    loaded.readMs = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    if (f.reference.empty()) return loaded;
    CheckInputFile(f.reference, "--reference");
    const Image &color = loaded.frame.Get("color");
    loaded.reference = io::ReadImage(f.reference);
    if (loaded.reference.width != color.width || loaded.reference.height != color.height)
        throw Error(fmt::format("reference {} is {}x{}, the frame {}x{}", f.reference,
                                loaded.reference.width, loaded.reference.height, color.width,
                                color.height),
                    ErrorKind::InvalidArgument);
    return loaded;
}

// --explain: what was read, what ran and was left out, the GPU buffers, the pipelines and
// the process's peak memory.
std::string ExplainText(const std::string &input, const LoadedFrame &loaded,
                        const Result &result, Device &device) {
    const io::Frame &frame = loaded.frame;
    std::string text = fmt::format("{} on {} ({}):\n", result.method, input, device.Name());
    // How another renderer's layers were converted: the split and noise depend on it.
    if (auto it = frame.metadata.find(io::kConventionKey); it != frame.metadata.end())
        text += fmt::format("  frame {}\n", it->second);
    std::string layers;
    for (const auto &[name, image] : frame.layers)
        layers += (layers.empty() ? "" : ", ") + name;
    text += fmt::format("  frame read in {:.0f} ms (layers {})\n", loaded.readMs, layers);
    for (const std::string &step : result.plan) text += "  " + step + "\n";
    text += LedgerText(result);
    text += PipelinesText(device);
    // The process's own peak: the frames' layers, the copies and, on a CPU device, the GPU
    // buffers too.
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return text + fmt::format("  peak memory of the process (RSS): {:.0f} MB\n",
                              double(usage.ru_maxrss) * 1024 / 1e6);
}

// The run's warnings, each once (a method run twice within auto repeats its own), each
// line naming the frame unless it is the command's only one.
std::string WarningsText(const std::vector<std::string> &warnings, const std::string &label) {
    std::string text;
    for (size_t i = 0; i < warnings.size(); ++i)
        if (std::find(warnings.begin(), warnings.begin() + i, warnings[i]) ==
            warnings.begin() + i)
            text += fmt::format("warning: {}{}\n", label, warnings[i]);
    return text;
}

// What a frame writes, handed to the writer thread: the denoised color, and the frame's
// alpha, or with --overwrite-input the whole frame.
struct FrameOutput {
    Image image;
    std::optional<Image> alpha;
    std::optional<io::Frame> whole;
    std::map<std::string, std::string> provenance;
};

std::future<void> StartWrite(const SequenceFrame &f, FrameOutput output) {
    return std::async(std::launch::async, [&f, output = std::move(output)] {
        const Image *alpha = output.alpha ? &*output.alpha : nullptr;
        if (output.whole) {
            alpha = output.whole->Has("alpha") ? &output.whole->Get("alpha") : nullptr;
            WriteOverInput(*output.whole, output.image, output.provenance);
        } else {
            WriteImage(f.output, output.image, output.provenance, alpha);
        }
        if (!f.preview.empty()) io::WritePngWithAlpha(f.preview, output.image, alpha);
    });
}

// Frames done out of the total and the time left, on stderr, and the stage of the frame
// being denoised: for a sequence on a terminal one line redrawn, elsewhere a line per frame
// and the stage's lines every few seconds; for one frame, the stage alone.
class FramesProgress {
  public:
    FramesProgress(int total, bool single, const std::string &method)
        : total(total), single(single), stages(method == "auto" ? "denoise" : method) {
        if (Redrawn()) Draw();
    }

    // A long stage of the frame being denoised.
    void Stage(const std::string &input, const std::string &stage, int done, int count) {
        if (!Redrawn())
            return stages.Update(single ? stage : input + ": " + stage, done, count);
        current = fmt::format(" [{}: {} {}%]", input, stage, 100 * done / std::max(count, 1));
        Draw();
    }
    // A frame's run starts: its stages are timed from here.
    void RunStarts() { stages.Begin(); }
    // The frame's run ended: one frame's progress line stays, ended.
    void RunDone() {
        if (single) stages.Done();
    }
    // Before a line on stdout or stderr: the redrawn line would run into it.
    void Clear() {
        stages.Clear();
        if (Redrawn() && drawn) std::fprintf(stderr, "\r\033[K");
        drawn = false;
    }
    // `setupSeconds`: what the frames so far spent building pipelines, which the next
    // frames will not.
    void FrameDone(const SequenceFrame &frame, bool failed, double setupSeconds) {
        ++done;
        failures += failed;
        current.clear();
        if (done == 1) firstDone = Clock::now(), setup = setupSeconds;
        if (single) return;
        if (Redrawn()) {
            Draw();
            if (done == total) std::fprintf(stderr, "\n"), drawn = false;
            return;
        }
        std::fprintf(stderr, "denoise: frame %d/%d (%s) %s, %s left\n", done, total,
                     frame.input.c_str(), failed ? "FAILED" : "written", Left().c_str());
    }

  private:
    bool Redrawn() const { return !single && stages.Terminal(); }
    // From the frames after the first, which also built the pipelines; after the first
    // alone, from its time less the pipelines'.
    std::string Left() const {
        Clock::time_point now = Clock::now();
        double perFrame =
            done >= 2
                ? std::chrono::duration<double>(now - firstDone).count() / (done - 1)
                : std::max(0.0, std::chrono::duration<double>(now - start).count() - setup);
        return DurationText(perFrame * (total - done));
    }
    void Draw() {
        std::fprintf(stderr, "\r\033[Kdenoise: %d/%d frames%s, %s left%s", done, total,
                     failures ? fmt::format(", {} failed", failures).c_str() : "",
                     done ? Left().c_str() : "?", current.c_str());
        std::fflush(stderr);
        drawn = true;
    }

    int total, done = 0, failures = 0;
    bool single, drawn = false;
    double setup = 0;
    std::string current;
    Progress stages;
    Clock::time_point start = Clock::now(), firstDone;
};

// A frame between its run and the end of its write: what it prints once written.
struct Pending {
    const SequenceFrame *frame = nullptr;
    std::string out, warnings, error;
    ErrorKind errorKind = ErrorKind::Internal;  // the kind of `error`
    std::future<void> written;
};

class DenoiseRun {
  public:
    DenoiseRun(const std::vector<SequenceFrame> &frames, const Method &method,
               const DenoiseSettings &settings)
        : frames(frames),
          method(method),
          settings(settings),
          // Only the layers the method reads; an in-place write keeps every layer.
          read(settings.inPlace ? mcd::ReadOptions{} : mcd::ReadOptions{method.Uses()}),
          progress(int(frames.size()), settings.single, method.Name()) {}

    void Run();

  private:
    std::future<LoadedFrame> Load(size_t i) {
        return std::async(std::launch::async, LoadFrame, std::cref(frames[i]), std::cref(read));
    }
    Pending Denoise(const SequenceFrame &f, LoadedFrame loaded);
    void Finish(Pending &p);
    void Summarize(double seconds) const;

    const std::vector<SequenceFrame> &frames;
    const Method &method;
    const DenoiseSettings &settings;
    const mcd::ReadOptions read;
    std::optional<Device> device;
    FramesProgress progress;
    std::vector<std::string> failed;
    ErrorKind firstFailure = ErrorKind::Internal;  // the run's kind when frames failed
};

// Three frames in flight: the next one read, this one denoised, the last one written.
void DenoiseRun::Run() {
    Clock::time_point start = Clock::now();
    std::future<LoadedFrame> next = Load(0);
    // One frame is read before the device starts: a bad input fails at once.
    std::optional<LoadedFrame> first;
    if (settings.single) first = next.get();
    device.emplace(settings.device);
    Pending previous;
    for (size_t i = 0; i < frames.size(); ++i) {
        Pending current;
        try {
            LoadedFrame loaded = first ? std::move(*first) : next.get();
            first.reset();
            if (i + 1 < frames.size()) next = Load(i + 1);
            current = Denoise(frames[i], std::move(loaded));
        } catch (...) {
            if (settings.single) throw;
            // The next frame is read even when this one could not be.
            if (i + 1 < frames.size() && !next.valid()) next = Load(i + 1);
            current.error =
                fmt::format("mcdenoise: error: frame {} ({}): {}\n", frames[i].number,
                            frames[i].input, DescribeFailure(std::current_exception()).message);
            current.errorKind = KindOf(std::current_exception());
        }
        current.frame = &frames[i];
        if (previous.frame) Finish(previous);
        previous = std::move(current);
    }
    Finish(previous);
    if (!settings.single)
        Summarize(std::chrono::duration<double>(Clock::now() - start).count());
}

// Run the method, put its lines together and start the write. Measured before writing: a
// failure here must not leave a file behind.
Pending DenoiseRun::Denoise(const SequenceFrame &f, LoadedFrame loaded) {
    RunOptions run;
    run.progress = [&](const std::string &stage, int done, int total) {
        progress.Stage(f.input, stage, done, total);
    };
    if (!f.map.empty()) run.stages = {"auto.map"};
    progress.RunStarts();
    Result result = method.Run(*device, loaded.frame, run);
    progress.RunDone();
    // Before the lines: the map's own goes into the plan, or a warning that there is none.
    WriteAutoMap(f.map, result);
    Pending p;
    if (settings.explain) p.out += ExplainText(f.input, loaded, result, *device);
    p.warnings = WarningsText(result.warnings, settings.single ? "" : f.input + ": ");
    p.out += FrameLine(f.output, result);
    if (!loaded.reference.Empty())
        p.out +=
            ErrorLine(loaded.frame.Get("color"), result.image, loaded.reference, f.reference);
    FrameOutput output;
    output.provenance = Provenance(method, result, f.input);
    output.image = std::move(result.image);
    if (settings.inPlace)
        output.whole = std::move(loaded.frame);
    else if (loaded.frame.Has("alpha"))
        output.alpha = std::move(loaded.frame.layers.at("alpha"));
    p.written = StartWrite(f, std::move(output));
    return p;
}

// Wait for the frame's write, then print what it says: its lines once it is on disk.
void DenoiseRun::Finish(Pending &p) {
    if (p.written.valid()) try {
            p.written.get();
        } catch (...) {
            if (settings.single) throw;
            p.error =
                fmt::format("mcdenoise: error: frame {} ({}): {}\n", p.frame->number,
                            p.frame->input, DescribeFailure(std::current_exception()).message);
            p.errorKind = KindOf(std::current_exception());
        }
    progress.Clear();
    fmt::print(stderr, "{}", p.warnings);
    if (p.error.empty()) {
        fmt::print("{}", p.out);
        std::fflush(stdout);
    } else {
        fmt::print(stderr, "{}", p.error);
        if (failed.empty()) firstFailure = p.errorKind;
        failed.push_back(p.frame->input);
    }
    progress.FrameDone(*p.frame, !p.error.empty(), api::ContextOf(*device).Pipelines().seconds);
}

void DenoiseRun::Summarize(double seconds) const {
    fmt::print("{} frames in {:.2f} s ({:.2f} frames/s): {} written, {} failed\n",
               frames.size(), seconds, double(frames.size()) / seconds,
               frames.size() - failed.size(), failed.size());
    if (failed.empty()) return;
    std::string names;
    for (size_t i = 0; i < failed.size() && i < 10; ++i) names += (i ? ", " : "") + failed[i];
    if (failed.size() > 10) names += fmt::format(" and {} more", failed.size() - 10);
    // The first failed frame's kind is the run's: its exit status.
    throw Error(fmt::format("{} of {} frames failed: {}", failed.size(), frames.size(), names),
                firstFailure);
}

}  // namespace

void DenoiseFrames(const std::vector<SequenceFrame> &frames, const Method &method,
                   const DenoiseSettings &settings) {
    DenoiseRun(frames, method, settings).Run();
}

}  // namespace mcd::tool
