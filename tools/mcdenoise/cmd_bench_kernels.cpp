// `mcdenoise bench kernels`: each method's main kernels against the device's limits. The
// device's streaming bandwidth and arithmetic rate are measured first, in the same run, by
// the calibration kernels (shaders/bench/); then each method runs on a rendered frame and
// every dispatch's traffic (the recorder's count of its bound buffers, or the bytes touched
// where kernel_ops.h knows a kernel touches part of them: the wavelet passes), operations
// (kernel_ops.h's formulas, some of them bounds: '<=') and GPU time (timestamps) are summed
// per kernel and printed per pixel, with the rates reached and the fraction of the roofline
// bound max(bytes / bandwidth, operations / rate) that the measured time reaches.
#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>

#include "host/api/device.h"
#include "host/error.h"
#include "host/kernels/bench_calibrate.h"
#include "host/vk/context.h"
#include "host/vk/dispatch_count.h"
#include "tools/mcdenoise/commands.h"
#include "tools/mcdenoise/kernel_ops.h"
#include "tools/mcdenoise/method_options.h"
#include "tools/render/renderer.h"

namespace mcd::tool {
namespace {

struct KernelsBenchOptions {
    std::string size = "256x256", scene = "cornell", methods = "awr,bayes,nfor,pivot,rhf,auto";
    std::string csv;
    int spp = 8, repeats = 2, calibMb = 64;
    double share = 0.05;
    DeviceOptions device;
    MethodOptions methodOptions;
};

// The device's limits as the calibration kernels reach them.
struct Peaks {
    double gbs = 0, gflops = 0;
};

// Submit what `recorder` holds; its fastest dispatch, as (ms, dispatch).
std::pair<double, vk::DispatchTiming> Fastest(vk::Recorder &recorder) {
    recorder.Submit();
    vk::DispatchTiming best = recorder.Timings().at(0);
    for (const vk::DispatchTiming &t : recorder.Timings())
        if (t.gpuMs > 0 && (best.gpuMs <= 0 || t.gpuMs < best.gpuMs)) best = t;
    if (best.gpuMs <= 0)
        throw Error(
            "bench kernels: the device gave no GPU timestamps to time the calibration "
            "with",
            ErrorKind::Device);
    return {best.gpuMs, best};
}

// Streaming copies of `mb` MiB: bytes from the recorder's accounting over the fastest
// dispatch's time.
double StreamGBs(vk::Context &context, int mb) {
    uint32_t count = uint32_t(size_t(mb) * (1 << 20) / 16);
    vk::Buffer src(context, size_t(count) * 16, "bench.stream.src"),
        dst(context, size_t(count) * 16, "bench.stream.dst");
    src.UploadFloats(std::vector<float>(size_t(count) * 4, 1.f));
    vk::Recorder recorder(context);
    for (int warm = 0; warm < 2; ++warm) {
        for (int i = 0; i < 6; ++i) RecordBenchStream(context, recorder, src, dst, count);
        auto [ms, t] = Fastest(recorder);
        if (warm == 1) return double(t.bytesRead + t.bytesWritten) / (ms * 1e6);
    }
    return 0;
}

// The FMA loop over 2^20 invocations, its iterations raised until a dispatch takes at
// least 20 ms (timestamps resolve it well then on any device).
double FmaGFlops(vk::Context &context) {
    const uint32_t count = 1 << 20;
    vk::Buffer src(context, size_t(count) * 16, "bench.fma.src"),
        dst(context, size_t(count) * 16, "bench.fma.dst");
    src.UploadFloats(std::vector<float>(size_t(count) * 4, 0.5f));
    vk::Recorder recorder(context);
    for (uint32_t iterations = 16;; iterations *= 4) {
        for (int i = 0; i < 3; ++i)
            RecordBenchFma(context, recorder, src, dst, count, iterations, 0.75f, 0.25f);
        auto [ms, t] = Fastest(recorder);
        if (ms >= 20 || iterations >= (1u << 20))
            return BenchFmaFlops(count, iterations) / (ms * 1e6);
    }
}

struct KernelFigures {
    std::string kernel;
    int dispatches = 0;
    double bytes = 0, flops = 0, ms = 0;
    bool counted = true;  // every dispatch had an operation formula
    OpsBound bound = OpsBound::Exact;
};

// "<=" or ">=" before a figure from an operation count that bounds the work, else "".
const char *BoundMark(OpsBound bound) {
    return bound == OpsBound::AtMost ? "<=" : bound == OpsBound::AtLeast ? ">=" : "";
}

// The kept dispatches summed per kernel, the most expensive first.
std::vector<KernelFigures> ByKernel(const std::vector<vk::KeptDispatch> &kept) {
    std::map<std::string, KernelFigures> byName;
    for (const vk::KeptDispatch &d : kept) {
        KernelFigures &f = byName[d.timing.kernel];
        f.kernel = d.timing.kernel;
        ++f.dispatches;
        // The bytes touched where the buffers bound are more than the kernel reads.
        std::optional<double> touched = KernelTouchedBytes(d);
        f.bytes += touched ? *touched : double(d.timing.bytesRead + d.timing.bytesWritten);
        f.ms += std::max(d.timing.gpuMs, 0.0);
        f.bound = KernelFlopsBound(d.timing.kernel);
        if (std::optional<double> flops = KernelFlops(d))
            f.flops += *flops;
        else
            f.counted = false;
    }
    std::vector<KernelFigures> figures;
    for (auto &[name, f] : byName) figures.push_back(f);
    std::sort(figures.begin(), figures.end(),
              [](const KernelFigures &a, const KernelFigures &b) { return a.ms > b.ms; });
    return figures;
}

// The roofline's time for `f`: its bytes at the bandwidth or its operations at the rate,
// whichever takes longer (bytes alone where the operations are not counted).
double BoundMs(const KernelFigures &f, const Peaks &peaks) {
    double memory = f.bytes / (peaks.gbs * 1e6);
    double compute = f.counted ? f.flops / (peaks.gflops * 1e6) : 0;
    return std::max(memory, compute);
}

void PrintKernelRow(const KernelFigures &f, double pixels, const Peaks &peaks, FILE *out) {
    double bound = BoundMs(f, peaks);
    bool compute = f.counted && f.flops / peaks.gflops > f.bytes / peaks.gbs;
    const char *mark = BoundMark(f.bound);
    std::string flops = f.counted ? fmt::format("{}{:.0f}", mark, f.flops / pixels) : "-";
    std::string gflops =
        f.counted ? fmt::format("{}{:.2f}", mark, f.flops / (f.ms * 1e6)) : "-";
    // Without an operation count the bound is the bytes' alone: the fraction is at least it;
    // where a bounding count sets it, the fraction is bounded the same way.
    std::string fraction = fmt::format("{}{:.1f}%",
                                       !f.counted ? ">="
                                       : compute  ? mark
                                                  : "",
                                       100 * bound / f.ms);
    fmt::print(out, "    {:<26} {:5} {:9.0f} {:>10} {:9.2f} {:7.2f} {:>8} {:>7} {:>8}\n",
               f.kernel, f.dispatches, f.bytes / pixels, flops, f.ms, f.bytes / (f.ms * 1e6),
               gflops, f.counted ? (compute ? "compute" : "memory") : "bytes", fraction);
}

// One method's kernels: those of at least `share` of its GPU time, then the rest summed.
void PrintMethodKernels(const std::string &method, const std::vector<KernelFigures> &figures,
                        double pixels, const Peaks &peaks, double share, std::ofstream *csv) {
    double total = 0, boundTotal = 0;
    for (const KernelFigures &f : figures) total += f.ms, boundTotal += BoundMs(f, peaks);
    fmt::print(
        "  {}: {:.2f} ms GPU in {} kernels; roofline bound {:.2f} ms ({:.1f}% of it "
        "reached; bytes alone where a kernel has no operation formula, a bounding count's "
        "where one has)\n",
        method, total, figures.size(), boundTotal, total > 0 ? 100 * boundTotal / total : 0.0);
    fmt::print("    {:<26} {:>5} {:>9} {:>10} {:>9} {:>7} {:>8} {:>7} {:>8}\n", "kernel",
               "calls", "bytes/px", "flop/px", "GPU ms", "GB/s", "GFLOP/s", "bound", "reached");
    KernelFigures rest{"(other kernels)"};
    int others = 0;
    for (const KernelFigures &f : figures) {
        if (csv) {
            const char *bound = f.bound == OpsBound::AtMost    ? "at_most"
                                : f.bound == OpsBound::AtLeast ? "at_least"
                                                               : "exact";
            *csv << fmt::format("{},{},{},{:.1f},{},{:.4f},{:.3f},{},{:.4f},{}\n", method,
                                f.kernel, f.dispatches, f.bytes / pixels,
                                f.counted ? fmt::format("{:.1f}", f.flops / pixels) : "", f.ms,
                                f.bytes / (f.ms * 1e6),
                                f.counted ? fmt::format("{:.3f}", f.flops / (f.ms * 1e6)) : "",
                                BoundMs(f, peaks) / f.ms, f.counted ? bound : "");
        }
        if (f.ms >= share * total && f.ms > 0) {
            PrintKernelRow(f, pixels, peaks, stdout);
            continue;
        }
        ++others;
        rest.dispatches += f.dispatches, rest.bytes += f.bytes, rest.ms += f.ms;
        rest.flops += f.flops, rest.counted = rest.counted && f.counted;
        // Counts bounded in different ways sum to no bound: bytes alone then.
        if (others > 1 && f.bound != rest.bound) rest.counted = false;
        rest.bound = f.bound;
    }
    if (others > 0 && rest.ms > 0) {
        rest.kernel = fmt::format("({} others)", others);
        PrintKernelRow(rest, pixels, peaks, stdout);
    }
}

// `repeats` runs of `method` after a warm-up, its dispatches kept; the run of least GPU
// time (the least disturbed on a shared machine) summed per kernel.
std::vector<KernelFigures> RunKept(Method &method, Device &device, const Frame &frame,
                                   int repeats) {
    method.Run(device, frame);
    std::vector<KernelFigures> best;
    double bestMs = 0;
    for (int r = 0; r < std::max(repeats, 1); ++r) {
        vk::KeepDispatches(true);
        method.Run(device, frame);
        vk::KeepDispatches(false);
        std::vector<KernelFigures> figures = ByKernel(vk::KeptDispatches());
        double ms = 0;
        for (const KernelFigures &f : figures) ms += f.ms;
        if (best.empty() || ms < bestMs) best = std::move(figures), bestMs = ms;
    }
    return best;
}

void BenchKernels(const KernelsBenchOptions &opt) {
    render::RenderOptions options;
    ParseSize(opt.size, &options.width, &options.height);
    options.spp = opt.spp;
    options.layers = render::kLayersAll;
    render::RenderResult rendered = render::Render(render::BuildScene(opt.scene), options);
    Frame frame;
    frame.path = fmt::format("{} {} at {} spp", opt.scene, opt.size, opt.spp);
    frame.width = options.width, frame.height = options.height;
    for (auto &[name, image] : rendered.layers) frame.layers[name] = std::move(image);
    const double pixels = double(frame.width) * frame.height;

    Device device(opt.device.Options());
    vk::Context &context = api::ContextOf(device);
    Peaks peaks{StreamGBs(context, opt.calibMb), FmaGFlops(context)};
    fmt::print("bench kernels: {} on {}\n", frame.path, device.Name());
    fmt::print(
        "  device limits measured now: streaming copy {:.2f} GB/s (bench_stream, {} MiB), "
        "FMA loop {:.2f} GFLOP/s (bench_fma); ridge {:.1f} flop/byte\n",
        peaks.gbs, opt.calibMb, peaks.gflops, peaks.gflops / peaks.gbs);
    fmt::print(
        "  per kernel, the fastest of {} runs after a warm-up: bytes of the buffers "
        "bound (touched: wavelet passes), operations by kernel_ops.h ('-': no "
        "formula, bound by the bytes alone; '<=': a count that takes no data-dependent "
        "shortcut); reached: the roofline's time over the measured one\n",
        std::max(opt.repeats, 1));
    std::unique_ptr<std::ofstream> csv;
    if (!opt.csv.empty()) {
        csv = std::make_unique<std::ofstream>(opt.csv);
        if (!*csv) throw Error("bench kernels: cannot write " + opt.csv, ErrorKind::Io);
        *csv << fmt::format("# device {}, {:.3f} GB/s, {:.3f} GFLOP/s, {}x{}\n", device.Name(),
                            peaks.gbs, peaks.gflops, frame.width, frame.height);
        *csv << "method,kernel,dispatches,bytes_per_px,flops_per_px,gpu_ms,gbs,gflops,"
                "roofline_fraction,flops_bound\n";
    }
    std::string list = opt.methods;
    for (size_t at = 0; at <= list.size();) {
        size_t comma = std::min(list.find(',', at), list.size());
        std::string name = list.substr(at, comma - at);
        at = comma + 1;
        if (name.empty()) continue;
        Method method = opt.methodOptions.Make(name);
        if (std::string missing = method.Missing(frame); !missing.empty()) {
            fmt::print("  {}: left out: the frame has {}\n", name, missing);
            continue;
        }
        std::vector<KernelFigures> figures = RunKept(method, device, frame, opt.repeats);
        PrintMethodKernels(name, figures, pixels, peaks, opt.share, csv.get());
        std::fflush(stdout);
    }
}

}  // namespace

void AddBenchKernelsCommand(CLI::App *bench) {
    auto opt = std::make_shared<KernelsBenchOptions>();
    CLI::App *command = bench->add_subcommand(
        "kernels",
        "Each method's main kernels against the device's limits: bytes and operations per "
        "pixel, GPU time, GB/s and GFLOP/s reached, and the fraction of the roofline bound, "
        "the limits measured in the same run by a streaming copy and an FMA loop");
    command->add_option("--size", opt->size, "rendered frame's size WxH")
        ->capture_default_str();
    command->add_option("--scene", opt->scene, "scene to render")->capture_default_str();
    command->add_option("--spp", opt->spp, "samples per pixel")->capture_default_str();
    command->add_option("--methods", opt->methods, "methods, comma-separated")
        ->capture_default_str();
    command->add_option("--repeat", opt->repeats, "timed runs per method after a warm-up")
        ->capture_default_str();
    command
        ->add_option("--share", opt->share,
                     "a kernel's row is printed from this share of its method's GPU time")
        ->capture_default_str();
    command
        ->add_option("--calibration-mb", opt->calibMb,
                     "the streaming copy's buffer size in MiB (at most the device's storage "
                     "buffer range)")
        ->check(CLI::Range(1, 4095))
        ->capture_default_str();
    command->add_option("--csv", opt->csv, "also write every kernel's figures here");
    opt->device.Add(command);
    opt->methodOptions.Add(command, "auto");
    command->callback([opt] { BenchKernels(*opt); });
}

}  // namespace mcd::tool
