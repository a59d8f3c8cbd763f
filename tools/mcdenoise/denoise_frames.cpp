#include "tools/mcdenoise/denoise_frames.h"

#include <fmt/format.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <future>
#include <map>
#include <optional>
#include <type_traits>
#include <variant>

#include "host/common/non_finite.h"
#include "host/error.h"
#include "host/io/conventions.h"
#include "host/io/frame.h"
#include "host/io/image_file.h"
#include "host/metrics.h"
#include "tools/mcdenoise/commands.h"
#include "tools/mcdenoise/exit_status.h"
#include "tools/mcdenoise/progress.h"

namespace mcd::tool {
namespace {

using Clock = std::chrono::steady_clock;

// The result written over its own input frame (--overwrite-input): every channel kept under
// the renderer's name, the noisy colour added (io::WriteDenoisedOver), the provenance added
// to the header. A link to the frame stays one: the file it names is replaced.
void WriteOverInput(const std::string &path, const Image &denoised,
                    const std::map<std::string, std::string> &provenance) {
    io::WriteDenoisedOver(std::filesystem::canonical(path).string(), denoised, provenance);
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
        "{:.4f}, mean brightness {:.4f} -> {:.4f} of the reference's{}\n",
        referencePath, before.relMse, after.relMse, before.psnr, after.psnr, before.ssim,
        after.ssim, before.brightness, after.brightness,
        after.nonFinite ? fmt::format(" ({} non-finite output values)", after.nonFinite) : "");
}

std::string FrameLine(const std::string &output, const Result &result,
                      const TemporalResult *temporal) {
    std::string gathered;
    if (temporal)
        gathered = fmt::format(", gathered with {} neighbours ({})", temporal->offsets.size(),
                               temporal->frame.metadata.at("mcd:temporalOffsets"));
    return fmt::format("{}: {} in {:.1f} ms ({:.1f} ms GPU, {} dispatches){}\n", output,
                       result.method, result.wallMs, result.GpuMs(), result.timings.size(),
                       gathered);
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
    // An error measured against NaN is no figure: refuse it, saying where.
    if (const NonFiniteCount bad = CountNonFinite(loaded.reference); bad.count)
        throw Error(fmt::format("--reference {}: {} NaN/Inf value{}, the first at pixel ({}, "
                                "{}), channel {}",
                                f.reference, bad.count, bad.count == 1 ? "" : "s", bad.x, bad.y,
                                bad.channel),
                    ErrorKind::NonFiniteInput);
    if (loaded.reference.width != color.width || loaded.reference.height != color.height)
        throw Error(fmt::format("reference {} is {}x{}, the frame {}x{}", f.reference,
                                loaded.reference.width, loaded.reference.height, color.width,
                                color.height),
                    ErrorKind::InvalidArgument);
    return loaded;
}

// The frames read ahead and kept: each frame's window (itself and, in the temporal mode,
// the frames whose numbers lie within the radius of its own) and the next frame's, read on
// loader threads; the others dropped.
class FrameCache {
  public:
    FrameCache(const std::vector<SequenceFrame> &frames, const mcd::ReadOptions &read,
               int radius)
        : frames(frames), read(read), radius(radius) {}

    // Frame i's window: i first, then its neighbours by number.
    std::vector<size_t> Window(size_t i) const {
        std::vector<size_t> window = {i};
        for (size_t j = 0; j < frames.size() && radius > 0; ++j)
            if (j != i && std::abs(frames[j].number - frames[i].number) <= radius)
                window.push_back(j);
        return window;
    }

    // Start reading frame i's window and the next frame's; drop every other frame. With
    // `here`, frame i (not read yet) is read on this thread, after the others are started:
    // its planes then come from this thread's heap (the main one, on huge pages: heap.h),
    // where a loader thread's own arena faults fresh memory in 4 KiB pages.
    void Keep(size_t i, bool here = false) {
        std::vector<size_t> keep = Window(i);
        if (i + 1 < frames.size())
            for (size_t j : Window(i + 1)) keep.push_back(j);
        for (auto it = slots.begin(); it != slots.end();)
            it = std::count(keep.begin(), keep.end(), it->first) ? std::next(it)
                                                                 : slots.erase(it);
        here = here && !slots.count(i);
        for (size_t j : keep)
            if (!slots.count(j) && !(here && j == i))
                slots[j].pending = std::async(std::launch::async, LoadFrame,
                                              std::cref(frames[j]), std::cref(read));
        if (!here) return;
        Slot &slot = slots[i];
        try {
            slot.frame = LoadFrame(frames[i], read);
        } catch (...) {
            slot.error = std::current_exception();
        }
    }

    // Frame j, once read (Keep started it); throws what its read threw.
    LoadedFrame &Get(size_t j) {
        Slot &slot = slots.at(j);
        if (slot.pending.valid()) try {
                slot.frame = slot.pending.get();
            } catch (...) {
                slot.error = std::current_exception();
            }
        if (slot.error) std::rethrow_exception(slot.error);
        return *slot.frame;
    }

  private:
    struct Slot {
        std::future<LoadedFrame> pending;
        std::optional<LoadedFrame> frame;
        std::exception_ptr error;
    };
    const std::vector<SequenceFrame> &frames;
    const mcd::ReadOptions &read;
    int radius;
    std::map<size_t, Slot> slots;
};

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

// What a frame writes, handed to the writer thread: the denoised color and the frame's
// alpha, into the input itself with --overwrite-input.
struct FrameOutput {
    Image image;
    std::optional<Image> alpha;
    bool overInput = false;
    std::map<std::string, std::string> provenance;
};

std::future<void> StartWrite(const SequenceFrame &f, FrameOutput output) {
    return std::async(std::launch::async, [&f, output = std::move(output)] {
        const Image *alpha = output.alpha ? &*output.alpha : nullptr;
        if (output.overInput)
            WriteOverInput(f.input, output.image, output.provenance);
        else
            WriteImage(f.output, output.image, output.provenance, alpha);
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

// The layers a run reads: the method's, and the temporal mode's too; every layer for an
// in-place write, which keeps them all.
// Only the layers the method and the temporal gather read; an in-place write copies the
// others from the file.
mcd::ReadOptions ReadLayers(const Method &method, const DenoiseSettings &settings) {
    mcd::ReadOptions read{method.Uses()};
    if (settings.temporal)
        for (const std::string &layer : settings.temporal->Uses())
            if (std::find(read.layers.begin(), read.layers.end(), layer) == read.layers.end())
                read.layers.push_back(layer);
    return read;
}

// The temporal mode's gather of a frame: with neighbours in its window, the frame gathered
// with them, which the method runs on (else none: the frame itself).
struct Gathered {
    std::optional<TemporalResult> temporal;
    std::vector<std::string> warnings;  // neighbours that could not be read
};

class DenoiseRun {
  public:
    DenoiseRun(const std::vector<SequenceFrame> &frames, const Method &method,
               const DenoiseSettings &settings)
        : frames(frames),
          method(method),
          settings(settings),
          read(ReadLayers(method, settings)),
          cache(frames, read, settings.temporal ? settings.temporal->Radius() : 0),
          progress(int(frames.size()), settings.single, method.Name()) {}

    void Run();

  private:
    Gathered Gather(size_t i, LoadedFrame &loaded);
    Pending Denoise(size_t i, LoadedFrame &loaded);
    void Finish(Pending &p);
    void Summarize(double seconds) const;

    const std::vector<SequenceFrame> &frames;
    const Method &method;
    const DenoiseSettings &settings;
    const mcd::ReadOptions read;
    FrameCache cache;
    std::optional<Device> device;
    FramesProgress progress;
    std::vector<std::string> failed;
    ErrorKind firstFailure = ErrorKind::Internal;  // the run's kind when frames failed
};

// Frames in flight: the next ones read (a window's), this one denoised, the last one
// written.
void DenoiseRun::Run() {
    Clock::time_point start = Clock::now();
    // The device starts on a helper thread while this one reads the first frame. A single
    // frame that cannot be read is still the error reported, before any of the device's.
    std::future<void> opening =
        std::async(std::launch::async, [this] { device.emplace(settings.device); });
    cache.Keep(0, true);
    std::exception_ptr deviceError;
    try {
        opening.get();
    } catch (...) {
        deviceError = std::current_exception();
    }
    if (settings.single) cache.Get(0);
    if (deviceError) std::rethrow_exception(deviceError);
    Pending previous;
    for (size_t i = 0; i < frames.size(); ++i) {
        Pending current;
        try {
            // The next frames are read even when this one could not be.
            cache.Keep(i);
            current = Denoise(i, cache.Get(i));
        } catch (...) {
            if (settings.single) throw;
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

// Whether the frame's color has a NaN or an infinity.
bool HasNonFinite(const Frame &frame) {
    const Image &color = frame.Get("color");
    return std::any_of(color.data.begin(), color.data.end(),
                       [](float v) { return !std::isfinite(v); });
}

// Frame i gathered with the neighbours of its window that could be read, each side up to
// its first missing frame (the gather follows the frames in turn). A frame with a
// non-finite value that the method refuses runs alone, so that it is refused: the gather
// would fill the value from the neighbours without a word.
Gathered DenoiseRun::Gather(size_t i, LoadedFrame &loaded) {
    Gathered g;
    std::vector<size_t> window = cache.Window(i);
    if (!settings.temporal || window.size() < 2) return g;
    if (std::get<std::string>(method.Get("non-finite")) == "refuse" &&
        HasNonFinite(loaded.frame))
        return g;
    std::map<int, size_t> byOffset;
    for (size_t k = 1; k < window.size(); ++k)
        byOffset[frames[window[k]].number - frames[i].number] = window[k];
    std::map<int, const Frame *> frameAt = {{0, &loaded.frame}};
    for (int direction : {-1, 1})
        for (int offset = direction;; offset += direction) {
            auto it = byOffset.find(offset);
            if (it == byOffset.end()) break;
            const SequenceFrame &f = frames[it->second];
            std::string why;
            try {
                const Frame &neighbour = cache.Get(it->second).frame;
                // A frame of another size (a resized shot) is no neighbour: it cannot align.
                if (neighbour.width == loaded.frame.width &&
                    neighbour.height == loaded.frame.height)
                    frameAt[offset] = &neighbour;
                else
                    why =
                        fmt::format("it is {}x{}, this frame {}x{}", neighbour.width,
                                    neighbour.height, loaded.frame.width, loaded.frame.height);
            } catch (...) {
                why = DescribeFailure(std::current_exception()).message;
            }
            if (!why.empty()) {
                g.warnings.push_back(
                    fmt::format("temporal: neighbour {} ({}) left out, and those beyond it: {}",
                                f.number, f.input, why));
                break;
            }
        }
    if (frameAt.size() < 2) return g;
    g.temporal = settings.temporal->Gather(*device, frameAt);
    // No neighbour could be folded (their warnings say why): the frame alone.
    if (g.temporal->offsets.empty()) {
        g.warnings.insert(g.warnings.end(), g.temporal->warnings.begin(),
                          g.temporal->warnings.end());
        g.temporal.reset();
    }
    return g;
}

// Run the method, put its lines together and start the write. Measured before writing: a
// failure here must not leave a file behind.
Pending DenoiseRun::Denoise(size_t i, LoadedFrame &loaded) {
    const SequenceFrame &f = frames[i];
    RunOptions run;
    run.progress = [&](const std::string &stage, int done, int total) {
        progress.Stage(f.input, stage, done, total);
    };
    if (!f.map.empty()) run.stages = {"auto.map"};
    progress.RunStarts();
    Gathered g = Gather(i, loaded);
    Result result = method.Run(*device, g.temporal ? g.temporal->frame : loaded.frame, run);
    progress.RunDone();
    if (g.temporal) {
        result.plan.insert(result.plan.begin(), g.temporal->plan.begin(),
                           g.temporal->plan.end());
        g.warnings.insert(g.warnings.end(), g.temporal->warnings.begin(),
                          g.temporal->warnings.end());
        result.timings.insert(result.timings.begin(), g.temporal->timings.begin(),
                              g.temporal->timings.end());
        result.wallMs += g.temporal->wallMs;
    }
    result.warnings.insert(result.warnings.begin(), g.warnings.begin(), g.warnings.end());
    // Before the lines: the map's own goes into the plan, or a warning that there is none.
    WriteAutoMap(f.map, result);
    Pending p;
    if (settings.explain) p.out += ExplainText(f.input, loaded, result, *device);
    p.warnings = WarningsText(result.warnings, settings.single ? "" : f.input + ": ");
    p.out += FrameLine(f.output, result, g.temporal ? &*g.temporal : nullptr);
    if (!loaded.reference.Empty())
        p.out +=
            ErrorLine(loaded.frame.Get("color"), result.image, loaded.reference, f.reference);
    FrameOutput output;
    output.provenance = Provenance(method, result, f.input);
    // The input's EXR windows, which io::WriteExr keeps in the output.
    for (const char *key : {io::kDataWindowKey, io::kDisplayWindowKey})
        if (auto it = loaded.frame.metadata.find(key); it != loaded.frame.metadata.end())
            output.provenance[key] = it->second;
    if (g.temporal)
        output.provenance["mcd:temporal"] = g.temporal->frame.metadata["mcd:temporalOffsets"];
    output.image = std::move(result.image);
    output.overInput = settings.inPlace;
    // The result's alpha: the frame's, with --alpha-rim's shares moved.
    if (!result.alpha.Empty()) output.alpha = std::move(result.alpha);
    // A frame of a window stays for the next frames' windows: its alpha is copied.
    else if (loaded.frame.Has("alpha"))
        output.alpha = settings.temporal ? loaded.frame.layers.at("alpha")
                                         : std::move(loaded.frame.layers.at("alpha"));
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
