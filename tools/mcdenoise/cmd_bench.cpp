// `mcdenoise bench`: speed figures, printed, never asserted. Compare ratios taken in one
// run: these machines are shared and noisy. The method benches run mcd::Method (the
// library API) with the method's own parameters and time it from Result::timings.
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <map>
#include <random>
#include <thread>

#include "host/error.h"
#include "host/vk/gpu_image.h"
#include "host/wavelet/transform.h"
#include "tools/mcdenoise/commands.h"
#include "tools/mcdenoise/method_options.h"
#include "tools/mcdenoise/usage.h"
#include "tools/render/adaptive.h"
#include "tools/render/renderer.h"

namespace mcd::tool {
namespace {

using Clock = std::chrono::steady_clock;

double Ms(Clock::duration d) {
    return std::chrono::duration<double, std::milli>(d).count();
}

double Median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0 : v[v.size() / 2];
}

// PyWavelets' wavedec2 + waverec2 (bior4.4, float32, per channel) on the same work, in
// seconds; negative when python3-pywt is not installed.
double PyWaveletsSeconds(int width, int height, int channels, int levels, int repeats) {
    const char *python =
        std::filesystem::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
    std::string script = fmt::format(
        "import time, numpy as np, pywt\n"
        "x = np.random.default_rng(1).random(({c}, {h}, {w})).astype(np.float32)\n"
        "best = 1e9\n"
        "for r in range({r}):\n"
        "    t = time.perf_counter()\n"
        "    for c in range({c}):\n"
        "        pywt.waverec2(pywt.wavedec2(x[c], 'bior4.4', level={l}), 'bior4.4')\n"
        "    best = min(best, time.perf_counter() - t)\n"
        "print(best)\n",
        fmt::arg("c", channels), fmt::arg("h", height), fmt::arg("w", width),
        fmt::arg("r", repeats), fmt::arg("l", levels));
    std::string command = fmt::format("{} -c \"{}\" 2>/dev/null", python, script);
    FILE *pipe = popen(command.c_str(), "r");
    if (!pipe) return -1;
    double seconds = -1;
    if (std::fscanf(pipe, "%lf", &seconds) != 1) seconds = -1;
    if (pclose(pipe) != 0) return -1;
    return seconds;
}

struct WaveletBenchOptions {
    std::string size = "2048x2048", basis = "cdf97";
    int levels = 5, repeats = 5;
    bool noPywt = false, perDispatch = false;
    DeviceOptions device;
};

// The buffers and transform of the wavelet bench, the image uploaded.
struct WaveletBench {
    WaveletBench(vk::Context &context, const Image &image)
        : in(context, image.width, image.height, image.channels, "image"),
          coef(context, image.width, image.height, image.channels, "coefficients"),
          out(context, image.width, image.height, image.channels, "reconstruction"),
          transform(context, image.width, image.height, image.channels),
          recorder(context) {}
    vk::GpuImage in, coef, out;
    WaveletTransform transform;
    vk::Recorder recorder;
};

// GPU time of the forward and inverse transforms and the submit's wall time, per run.
struct RoundTripTimes {
    std::vector<double> forward, inverse, wall;
};

RoundTripTimes TimeRoundTrips(WaveletBench &b, WaveletBasis basis, int levels, int repeats,
                              bool perDispatch) {
    RoundTripTimes times;
    for (int r = 0; r <= repeats; ++r) {  // run 0 warms up (pipelines, first touch)
        b.transform.RecordAnalysis(b.recorder, basis, levels, b.in, b.coef);
        b.transform.RecordSynthesis(b.recorder, basis, levels, b.coef, b.out);
        Clock::time_point start = Clock::now();
        b.recorder.Submit();
        double wallMs = Ms(Clock::now() - start);
        double forward = 0, inverse = 0;
        for (const vk::DispatchTiming &t : b.recorder.Timings())
            (t.label.find("analyze") != std::string::npos ? forward : inverse) +=
                std::max(t.gpuMs, 0.0);
        if (r == 0) continue;
        times.forward.push_back(forward);
        times.inverse.push_back(inverse);
        times.wall.push_back(wallMs);
        fmt::print("  run {}/{}: {:.1f} ms wall\n", r, repeats, wallMs);
        std::fflush(stdout);
    }
    if (perDispatch)
        for (const vk::DispatchTiming &t : b.recorder.Timings())
            fmt::print("    {:<36} {:8.2f} ms\n", t.label, t.gpuMs);
    return times;
}

// The squared-filter (variance) analysis AWR runs on every frame, same size and levels:
// its median GPU time.
double SqAnalysisMs(WaveletBench &b, WaveletBasis basis, int levels, int repeats) {
    std::vector<double> sqMs;
    for (int r = 0; r <= std::min(repeats, 3); ++r) {
        b.transform.RecordSqAnalysis(b.recorder, basis, levels, b.in, b.coef, 1.05f,
                                     0.70710678f);
        b.recorder.Submit();
        if (r > 0) sqMs.push_back(b.recorder.TotalGpuMs());
    }
    return Median(sqMs);
}

// The device's own streaming rate, in GB/s: buffer copies of the same image.
double CopyGBs(WaveletBench &b) {
    std::vector<double> copyMs;
    for (int r = 0; r < 3; ++r) {
        for (int k = 0; k < 4; ++k)
            b.recorder.Copy(b.in.buffer, k % 2 ? b.coef.buffer : b.out.buffer,
                            b.in.buffer.Bytes());
        Clock::time_point start = Clock::now();
        b.recorder.Submit();
        copyMs.push_back(Ms(Clock::now() - start) / 4);
    }
    return 2 * double(b.in.buffer.Bytes()) / (Median(copyMs) * 1e6);
}

void PrintPyWavelets(int width, int height, int channels, int levels, int repeats,
                     double wallMs) {
    double seconds = PyWaveletsSeconds(width, height, channels, levels, std::min(repeats, 3));
    if (seconds > 0)
        fmt::print(
            "  PyWavelets (wavedec2+waverec2, bior4.4, same CPU): {:.1f} ms: mcdenoise is {} "
            "(wall)\n",
            seconds * 1e3, SpeedText(seconds * 1e3 / wallMs));
    else
        fmt::print("  PyWavelets: not available (install python3-pywt to compare)\n");
}

void RunBenchWavelet(const WaveletBenchOptions &opt) {
    int width = 0, height = 0, channels = 3;
    ParseSize(opt.size, &width, &height);
    std::optional<WaveletBasis> basis = ParseWavelet(opt.basis);
    if (!basis)
        throw Error("unknown wavelet basis '" + opt.basis + "'", ErrorKind::InvalidArgument);
    int levels = opt.levels;
    if (levels < 1 || levels > MaxWaveletLevels(width, height))
        throw Error(fmt::format("--levels {}: a {}x{} image takes 1..{}", levels, width, height,
                                MaxWaveletLevels(width, height)),
                    ErrorKind::InvalidArgument);
    int repeats = std::max(opt.repeats, 1);

    vk::Context context(opt.device.ContextOptions());
    fmt::print(
        "bench wavelet: {}x{} RGB float32, {} levels of {}, forward + inverse, on {} ({})\n",
        width, height, levels, WaveletName(*basis), context.Info().name,
        vk::DeviceTypeName(context.Info().type));
    Image image(width, height, channels);
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> uniform(0.f, 1.f);
    for (float &v : image.data) v = uniform(rng);

    WaveletBench b(context, image);
    Clock::time_point t0 = Clock::now();
    b.in.Upload(image);
    double uploadMs = Ms(Clock::now() - t0);
    RoundTripTimes times = TimeRoundTrips(b, *basis, levels, repeats, opt.perDispatch);
    t0 = Clock::now();
    Image back = b.out.Download();
    double downloadMs = Ms(Clock::now() - t0);
    double maxError = 0;
    for (size_t i = 0; i < image.Size(); ++i)
        maxError = std::max(maxError, double(std::fabs(back.data[i] - image.data[i])));
    double sqMs = SqAnalysisMs(b, *basis, levels, repeats);
    double copyGBs = CopyGBs(b);

    // Nominal traffic: every level reads and writes its region once, in each direction.
    double levelBytes = 0;
    for (int level = 0; level < levels; ++level)
        levelBytes +=
            2.0 * LevelExtent(width, level) * LevelExtent(height, level) * channels * 4;
    double forward = Median(times.forward), inverse = Median(times.inverse);
    double totalGpu = forward + inverse;
    double dwtGBs = 2 * levelBytes / (totalGpu * 1e6);
    fmt::print(
        "  GPU time (timestamps, median of {}): forward {:.2f} ms, inverse {:.2f} ms, total "
        "{:.2f} ms\n",
        repeats, forward, inverse, totalGpu);
    fmt::print("  wall time of the submit: {:.2f} ms; upload {:.2f} ms, download {:.2f} ms\n",
               Median(times.wall), uploadMs, downloadMs);
    fmt::print(
        "  traffic {:.0f} MB at {:.2f} GB/s; buffer copy streams {:.2f} GB/s: {:.0f}% of it\n",
        2 * levelBytes / 1e6, dwtGBs, copyGBs, 100 * dwtGBs / copyGBs);
    fmt::print("  squared-filter analysis (variance, AWR eq. 9-10): {:.2f} ms GPU\n", sqMs);
    fmt::print("  round-trip max |error| {:.3g}\n", maxError);
    if (!opt.noPywt)
        PrintPyWavelets(width, height, channels, levels, repeats, Median(times.wall));
}

// A frame of named layers (rendered or synthetic) for Method::Run.
Frame MakeFrame(const std::string &path, std::vector<std::pair<std::string, Image>> layers) {
    Frame frame;
    frame.path = path;
    for (auto &[name, image] : layers) {
        frame.width = image.width, frame.height = image.height;
        frame.layers[name] = std::move(image);
    }
    return frame;
}

// The method's device and its name and type, for the headers.
std::string DeviceText(Device &device) {
    const vk::DeviceInfo &info = api::ContextOf(device).Info();
    return fmt::format("{} ({})", info.name, vk::DeviceTypeName(info.type));
}

template <typename T>
T Param(const Method &method, const std::string &name) {
    return std::get<T>(method.Get(name));
}

struct AwrBenchOptions {
    std::string size = "1024x1024", samplerScene = "dof-arealight", samplerSize = "256x256";
    int repeats = 5, samplerSpp = 16;
    bool dispatches = false, noSampler = false;
    DeviceOptions device;
    MethodOptions methods;
};

// The reconstruction's GPU time per stage and per dispatch over the timed runs, each beside
// the yardstick DWT's.
struct AwrTimes {
    std::array<std::vector<double>, 4> stageMs;
    std::vector<double> totalMs, wallMs, dwtMs, ratios;
    std::vector<std::string> labels;  // in dispatch order
    std::map<std::string, std::vector<double>> labelMs;
    bool fused = false;  // the shrinkage runs inside the synthesis's dispatches
};

// Add one run's dispatches to `times`, by stage ("sqanalyze", "analyze", "shrink",
// "synthesize").
void AddAwrRun(const Result &result, bool first, AwrTimes &times) {
    const char *stages[] = {"sqanalyze", "analyze", "shrink", "synthesize"};
    double stage[4] = {}, total = 0;
    for (const Timing &t : result.timings) {
        if (first) times.labels.push_back(t.label);
        times.labelMs[t.label].push_back(std::max(t.gpuMs, 0.0));
        // Synthesis first: with the shrinkage fused into it, its label names both.
        int s = t.label.find("synthesize") != std::string::npos ? 3 : 0;
        while (s < 3 && t.label.find(stages[s]) == std::string::npos) ++s;
        times.fused |= t.label.find("synthesize_shrink") != std::string::npos;
        stage[s] += std::max(t.gpuMs, 0.0);
        total += std::max(t.gpuMs, 0.0);
    }
    for (int s = 0; s < 4; ++s) times.stageMs[s].push_back(stage[s]);
    times.totalMs.push_back(total);
    times.wallMs.push_back(result.wallMs);
}

// The reconstruction `repeats` times after a warm-up, each run followed by one forward +
// inverse DWT of the same frame, the yardstick the issue names, so both see the same load
// on a shared machine.
AwrTimes TimeAwr(Method &method, Device &device, const Frame &frame, WaveletBasis basis,
                 int levels, int repeats) {
    vk::Context &context = api::ContextOf(device);
    const Image &color = frame.layers.at("color");
    vk::GpuImage in(context, color.width, color.height, 3, "bench.in"),
        coef(context, color.width, color.height, 3, "bench.coef");
    in.Upload(color);
    WaveletTransform transform(context, color.width, color.height, 3);
    vk::Recorder recorder(context);
    AwrTimes times;
    for (int r = 0; r <= repeats; ++r) {  // the first run warms up pipelines and memory
        Result result = method.Run(device, frame);
        transform.RecordAnalysis(recorder, basis, levels, in, coef);
        transform.RecordSynthesis(recorder, basis, levels, coef, in);
        recorder.Submit();
        if (r == 0) continue;
        AddAwrRun(result, r == 1, times);
        times.dwtMs.push_back(recorder.TotalGpuMs());
        times.ratios.push_back(times.totalMs.back() / times.dwtMs.back());
    }
    return times;
}

void PrintAwrTimes(const AwrTimes &times, int repeats, bool dispatches) {
    const char *names[] = {"squared-filter DWT of the variance", "DWT of the color",
                           "soft shrinkage", "synthesis"};
    fmt::print("  GPU time per stage (timestamps, median of {}):\n", repeats);
    for (int s : {1, 0, 2, 3}) {
        if (s == 2 && times.fused)
            fmt::print("    {:<36} (fused into the synthesis)\n", names[s]);
        else
            fmt::print("    {:<36} {:8.2f} ms\n", names[s], Median(times.stageMs[s]));
    }
    double total = Median(times.totalMs), dwt = Median(times.dwtMs);
    fmt::print("    {:<36} {:8.2f} ms (goal: under 100 ms)\n", "total", total);
    fmt::print("  wall time with upload and download: {:.1f} ms\n", Median(times.wallMs));
    fmt::print(
        "  one forward + inverse DWT of the frame: {:.2f} ms; reconstruction / DWT = {:.2f} "
        "(goal: at most 2; median of the runs' own ratios {:.2f})\n",
        dwt, total / dwt, Median(times.ratios));
    if (!dispatches) return;
    // The fastest run is the least disturbed on a shared machine.
    auto fastest = [](const std::vector<double> &v) {
        return v.empty() ? 0 : *std::min_element(v.begin(), v.end());
    };
    fmt::print("  GPU time per dispatch (median and fastest of {}):\n", repeats);
    for (const std::string &label : times.labels)
        fmt::print("    {:<36} {:8.3f} {:8.3f} ms\n", label, Median(times.labelMs.at(label)),
                   fastest(times.labelMs.at(label)));
    fmt::print("    {:<36} {:8.3f} {:8.3f} ms; DWT fastest {:.3f} ms\n", "total",
               Median(times.totalMs), fastest(times.totalMs), fastest(times.dwtMs));
}

// The adaptive sampler: its own work (transforms, priorities, sorting) against tracing.
void BenchAdaptiveSampler(const AwrBenchOptions &opt, vk::Context &context) {
    render::Scene scene = render::BuildScene(opt.samplerScene);
    render::AdaptiveOptions sampler;
    ParseSize(opt.samplerSize, &sampler.width, &sampler.height);
    sampler.averageSpp = opt.samplerSpp;
    render::AdaptiveResult adaptive = render::RenderAdaptive(context, scene, sampler);
    double samples = double(adaptive.samples);
    fmt::print(
        "  adaptive sampler on {} {}x{} at {} spp: {} rounds, {:.2f} s; tracing {:.3f} us per "
        "sample, the sampler's own work {:.3f} us per sample ({:.1f}% of tracing)\n",
        opt.samplerScene, sampler.width, sampler.height, sampler.averageSpp, adaptive.rounds,
        adaptive.seconds, adaptive.traceSeconds / samples * 1e6,
        adaptive.prioritySeconds / samples * 1e6,
        100 * adaptive.prioritySeconds / adaptive.traceSeconds);
}

// AWR: the reconstruction's stages against one forward + inverse DWT of the same frame,
// then the adaptive sampler's own cost per sample against tracing.
void RunBenchAwr(const AwrBenchOptions &opt) {
    int width = 0, height = 0;
    ParseSize(opt.size, &width, &height);
    int repeats = std::max(opt.repeats, 1);
    Method method = opt.methods.Make("awr");
    Device device(opt.device.Options());
    // The yardstick DWT runs the method's basis and levels (the method refuses too many).
    WaveletBasis basis = *ParseWavelet(Param<std::string>(method, "basis"));
    int levels = Param<int>(method, "levels");
    if (levels < 0) levels = MaxWaveletLevels(width, height);
    const char *basisText = basis == WaveletBasis::Cdf97      ? "CDF 9/7"
                            : basis == WaveletBasis::LeGall53 ? "LeGall 5/3"
                                                              : "Haar";
    fmt::print("bench awr: reconstruction of a {}x{} RGB frame, {} levels of {}, on {}\n",
               width, height, levels, basisText, DeviceText(device));
    Image color(width, height, 3), variance(width, height, 3);
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> uniform(0.f, 1.f);
    for (size_t i = 0; i < color.Size(); ++i)
        color.data[i] = uniform(rng), variance.data[i] = 0.01f * uniform(rng);
    Frame frame =
        MakeFrame("bench awr (synthetic)", {{"color", color}, {"variance", variance}});
    PrintAwrTimes(TimeAwr(method, device, frame, basis, levels, repeats), repeats,
                  opt.dispatches);
    if (!opt.noSampler) BenchAdaptiveSampler(opt, api::ContextOf(device));
}

struct BayesBenchOptions {
    std::string size = "1024x1024";
    int repeats = 3;
    bool noSkimage = false;
    DeviceOptions device;
    MethodOptions methods;
};

// Method bayes on a synthetic frame (smooth picture times log-normal noise, RGB): GPU time
// per stage, median over repeats, and scikit-image's BayesShrink on the same work.
void RunBenchBayes(const BayesBenchOptions &opt) {
    int width = 0, height = 0;
    ParseSize(opt.size, &width, &height);
    int repeats = std::max(opt.repeats, 1);
    Method method = opt.methods.Make("bayes");
    int levels = Param<int>(method, "bayes-levels");
    Device device(opt.device.Options());
    fmt::print("bench bayes: {}x{} RGB float32, {} levels of {} {}, noise {}, on {}\n", width,
               height, levels, Param<std::string>(method, "bayes-wavelet"),
               Param<std::string>(method, "bayes-transform"),
               Param<std::string>(method, "noise"), DeviceText(device));
    Image image(width, height, 3);
    std::mt19937 rng(1);
    std::normal_distribution<float> normal(0.f, 0.4f);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x)
                image.At(c, y, x) = (0.3f + 0.5f * (x > width / 2) +
                                     0.2f * std::sin(0.05f * float(y) + float(c))) *
                                    std::exp(normal(rng));
    Frame frame = MakeFrame("bench bayes (synthetic)", {{"color", std::move(image)}});
    std::map<std::string, std::vector<double>> stages;
    std::vector<double> wall, gpu;
    for (int r = 0; r <= repeats; ++r) {  // run 0 warms up
        Result result = method.Run(device, frame);
        if (r == 0) continue;
        std::map<std::string, double> perStage;
        double total = 0;
        for (const Timing &t : result.timings) {
            std::string stage = t.label.substr(0, t.label.find(".L"));
            perStage[stage] += std::max(t.gpuMs, 0.0);
            total += std::max(t.gpuMs, 0.0);
        }
        for (const auto &[stage, ms] : perStage) stages[stage].push_back(ms);
        gpu.push_back(total);
        wall.push_back(result.wallMs);
    }
    for (const auto &[stage, ms] : stages)
        fmt::print("    {:<28} {:8.2f} ms\n", stage, Median(ms));
    fmt::print(
        "  GPU total {:.2f} ms, wall (upload, run, download) {:.2f} ms (medians of {})\n",
        Median(gpu), Median(wall), repeats);
    if (opt.noSkimage) return;
    const char *python =
        std::filesystem::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
    std::string script = fmt::format(
        "import time, numpy as np\n"
        "from skimage.restoration import denoise_wavelet\n"
        "rng = np.random.default_rng(1)\n"
        "x = rng.random(({h}, {w}, 3)).astype(np.float32)\n"
        "t = time.perf_counter()\n"
        "denoise_wavelet(x, method='BayesShrink', mode='soft', wavelet_levels={l}, "
        "channel_axis=-1, convert2ycbcr=False, rescale_sigma=True)\n"
        "print(time.perf_counter() - t)\n",
        fmt::arg("h", height), fmt::arg("w", width), fmt::arg("l", levels));
    FILE *pipe = popen(fmt::format("{} -c \"{}\" 2>/dev/null", python, script).c_str(), "r");
    double seconds = -1;
    if (pipe) {
        if (std::fscanf(pipe, "%lf", &seconds) != 1) seconds = -1;
        if (pclose(pipe) != 0) seconds = -1;
    }
    if (seconds > 0)
        fmt::print(
            "  scikit-image denoise_wavelet (BayesShrink, same size, same CPU): {:.1f} "
            "ms\n",
            seconds * 1e3);
    else
        fmt::print("  scikit-image: not available (python3-skimage)\n");
}

// Time `run` (one Method::Run) `repeats` times after one untimed warm-up (pipelines, first
// touch; `warmUp` when given, else `run`); print each run, then the last run's GPU time
// per kernel (summed over its dispatches) so the expensive stage is visible. Returns the
// last run's result.
Result TimeMethodRuns(int repeats, const std::function<Result()> &run,
                      const std::function<void()> &warmUp = nullptr) {
    repeats = std::max(repeats, 1);
    if (warmUp) warmUp();
    std::vector<double> gpu, wall;
    std::vector<std::pair<std::string, double>> perKernel;
    Result last;
    for (int r = warmUp ? 1 : 0; r <= repeats; ++r) {
        Result result = run();
        if (r == 0) continue;
        double total = 0;
        perKernel.clear();
        for (const Timing &t : result.timings) {
            total += std::max(t.gpuMs, 0.0);
            auto it = std::find_if(perKernel.begin(), perKernel.end(),
                                   [&](const auto &p) { return p.first == t.label; });
            if (it == perKernel.end())
                perKernel.push_back({t.label, std::max(t.gpuMs, 0.0)});
            else
                it->second += std::max(t.gpuMs, 0.0);
        }
        gpu.push_back(total);
        wall.push_back(result.wallMs);
        fmt::print("  run {}/{}: {:.1f} ms GPU, {:.1f} ms wall with upload/download\n", r,
                   repeats, total, result.wallMs);
        std::fflush(stdout);
        last = std::move(result);
    }
    for (const auto &[label, ms] : perKernel) fmt::print("    {:<20} {:10.2f} ms\n", label, ms);
    fmt::print("  GPU time (timestamps, median of {}): {:.2f} ms; wall {:.2f} ms\n", repeats,
               Median(gpu), Median(wall));
    return last;
}

// A rendered frame with the given layer groups.
Frame RenderFrame(const std::string &size, const std::string &sceneName, int spp, int layers) {
    render::RenderOptions options;
    ParseSize(size, &options.width, &options.height);
    options.spp = spp;
    options.layers = layers;
    render::RenderResult result = render::Render(render::BuildScene(sceneName), options);
    return MakeFrame(fmt::format("{} at {} spp", sceneName, spp), std::move(result.layers));
}

struct MethodBenchOptions {
    std::string size, scene = "cornell";
    int spp = 0, repeats = 1;
    DeviceOptions device;
    MethodOptions methods;
};

// RHF on a rendered frame with histograms.
void RunBenchRhf(const MethodBenchOptions &opt) {
    Method method = opt.methods.Make("rhf");
    Frame frame = RenderFrame(opt.size, opt.scene, opt.spp, render::kLayersHist);
    if (std::string missing = method.Missing(frame); !missing.empty())
        throw Error("bench rhf: the rendered frame has " + missing, ErrorKind::MissingLayer);
    Device device(opt.device.Options());
    fmt::print(
        "bench rhf: {} {}x{} at {} spp, patch half {}, search half {}, kappa {}, kNN {}, "
        "bright veto {}, {} scales, on {}\n",
        opt.scene, frame.width, frame.height, opt.spp, Param<int>(method, "patch-half"),
        Param<int>(method, "search-half"), Param<float>(method, "kappa"),
        Param<int>(method, "knn"), Param<float>(method, "bright-veto"),
        Param<int>(method, "nscales"), DeviceText(device));
    TimeMethodRuns(opt.repeats, [&] { return method.Run(device, frame); });
}

// The grown radius from the planefit plan line ("mean radius M, largest L"; with partial
// images one line each, combined as PivotDenoise combines them): the Result has no field
// for it. False when no line has it (the bilateral filter).
bool PlannedRadius(const Result &result, double *mean, int *largest) {
    double sum = 0;
    int lines = 0;
    *largest = 0;
    for (const std::string &line : result.plan) {
        size_t at = line.find("mean radius ");
        double m = 0;
        int l = 0;
        if (at == std::string::npos ||
            std::sscanf(line.c_str() + at, "mean radius %lf, largest %d", &m, &l) != 2)
            continue;
        sum += m, ++lines;
        *largest = std::max(*largest, l);
    }
    *mean = lines ? sum / lines : 0;
    return lines > 0;
}

// The pivot filter on a rendered frame with every layer it uses (pivot, variance,
// normals, ids), and the radius the squares grew to.
void RunBenchPivot(const MethodBenchOptions &opt) {
    Method method = opt.methods.Make("pivot");
    Frame frame = RenderFrame(opt.size, opt.scene, opt.spp, render::kLayersAll);
    if (std::string missing = method.Missing(frame); !missing.empty())
        throw Error("bench pivot: the rendered frame has " + missing, ErrorKind::MissingLayer);
    Device device(opt.device.Options());
    int maxRadius = Param<int>(method, "max-radius");
    fmt::print("bench pivot: {} {}x{} at {} spp, {} filter, max radius {}, on {}\n", opt.scene,
               frame.width, frame.height, opt.spp, Param<std::string>(method, "filter"),
               maxRadius, DeviceText(device));
    std::fflush(stdout);
    // Above 256x256, warm up on a 16x16 crop: a full-size warm-up would double minutes of
    // work. (lavapipe may then compile a kernel variant for the full size's buffers in the
    // timed run: tens of ms, negligible there.)
    Frame small = frame;
    small.width = std::min(16, frame.width), small.height = std::min(16, frame.height);
    for (auto &[name, layer] : small.layers)
        layer = layer.Crop(0, 0, small.width, small.height);
    Result last = TimeMethodRuns(
        opt.repeats, [&] { return method.Run(device, frame); },
        frame.width * frame.height > 256 * 256
            ? std::function<void()>([&] { method.Run(device, small); })
            : nullptr);
    double meanRadius = 0;
    int largestRadius = 0;
    if (PlannedRadius(last, &meanRadius, &largestRadius))
        fmt::print("  grown radius: mean {:.2f}, largest {} (of at most {})\n", meanRadius,
                   largestRadius, maxRadius);
}

struct RenderBenchOptions {
    std::string size = "256x256";
    int spp = 4, threads = 0;
};

// Samples per second of the path tracer per scene, plain and with every layer group.
void RunBenchRender(const RenderBenchOptions &opt) {
    render::RenderOptions options;
    ParseSize(opt.size, &options.width, &options.height);
    options.spp = opt.spp;
    options.threads = opt.threads;
    fmt::print(
        "bench render: {}x{} at {} spp, {} threads; time without, then with, every layer "
        "group\n",
        options.width, options.height, options.spp,
        options.threads > 0 ? options.threads : int(std::thread::hardware_concurrency()));
    for (const std::string &name : render::SceneNames()) {
        render::Scene scene = render::BuildScene(name);
        options.layers = 0;
        render::RenderResult plain = render::Render(scene, options);
        options.layers = render::kLayersAll;
        render::RenderResult all = render::Render(scene, options);
        double samples = double(options.width) * options.height * options.spp;
        fmt::print("  {:<16} {:7.2f} M samples/s ({:.2f} s); with every layer group {:.2f} s\n",
                   name, samples / plain.seconds * 1e-6, plain.seconds, all.seconds);
        std::fflush(stdout);
    }
}

void AddBenchWaveletCommand(CLI::App *bench) {
    auto opt = std::make_shared<WaveletBenchOptions>();
    CLI::App *wavelet = bench->add_subcommand(
        "wavelet",
        "Time forward + inverse DWT of an RGB float image on the device\n\nWith its fraction "
        "of the device's copy bandwidth and PyWavelets beside it.");
    wavelet->add_option("--size", opt->size, "image size WxH")->capture_default_str();
    wavelet->add_option("--levels", opt->levels, "decomposition levels")->capture_default_str();
    wavelet->add_option("--basis", opt->basis, "haar, legall53 or cdf97")
        ->capture_default_str();
    wavelet->add_option("--repeat", opt->repeats, "timed runs (after one warm-up)")
        ->capture_default_str();
    wavelet->add_flag("--no-pywt", opt->noPywt, "skip the PyWavelets comparison");
    wavelet->add_flag("--per-dispatch", opt->perDispatch, "print each dispatch's GPU time");
    opt->device.Add(wavelet);
    wavelet->callback([opt] { RunBenchWavelet(*opt); });
}

void AddBenchRenderCommand(CLI::App *bench) {
    auto opt = std::make_shared<RenderBenchOptions>();
    CLI::App *cmd = bench->add_subcommand(
        "render", "Samples per second of the built-in path tracer, per scene");
    cmd->add_option("--size", opt->size, "image size WxH")->capture_default_str();
    cmd->add_option("--spp", opt->spp, "samples per pixel")->capture_default_str();
    cmd->add_option("--threads", opt->threads, "threads (default: all cores)");
    cmd->callback([opt] { RunBenchRender(*opt); });
}

// The method benches take the method's own parameters (--<name>, the library's defaults)
// beside their bench-only options.
void AddBenchAwrCommand(CLI::App *bench) {
    auto opt = std::make_shared<AwrBenchOptions>();
    CLI::App *awr = bench->add_subcommand(
        "awr",
        "AWR: reconstruction time per stage against one DWT, and the sampler's overhead\n\n"
        "The adaptive sampler's overhead is per sample, against tracing.");
    awr->add_option("--size", opt->size, "frame size WxH for the reconstruction")
        ->capture_default_str();
    awr->add_option("--repeat", opt->repeats, "timed runs (after one warm-up)")
        ->capture_default_str();
    awr->add_option("--sampler-scene", opt->samplerScene, "scene for the sampler run")
        ->capture_default_str();
    awr->add_option("--sampler-size", opt->samplerSize, "image size of the sampler run")
        ->capture_default_str();
    awr->add_option("--sampler-spp", opt->samplerSpp, "average spp of the sampler run")
        ->capture_default_str();
    awr->add_flag("--dispatches", opt->dispatches,
                  "also print the reconstruction's GPU time per dispatch");
    awr->add_flag("--no-sampler", opt->noSampler, "time the reconstruction only");
    opt->device.Add(awr);
    opt->methods.Add(awr, "awr");
    awr->callback([opt] { RunBenchAwr(*opt); });
}

void AddBenchBayesCommand(CLI::App *bench) {
    auto opt = std::make_shared<BayesBenchOptions>();
    CLI::App *bayes = bench->add_subcommand(
        "bayes",
        "Time method bayes per stage on an RGB frame, scikit-image's BayesShrink beside it");
    bayes->add_option("--size", opt->size, "image size WxH")->capture_default_str();
    bayes->add_option("--repeat", opt->repeats, "timed runs (after one warm-up)")
        ->capture_default_str();
    bayes->add_flag("--no-skimage", opt->noSkimage, "skip the scikit-image comparison");
    opt->device.Add(bayes);
    opt->methods.Add(bayes, "bayes");
    bayes->callback([opt] { RunBenchBayes(*opt); });
}

// `bench rhf` and `bench pivot`: a rendered frame of `size` at `spp`, timed.
void AddBenchRenderedCommand(CLI::App *bench, const char *name, const char *description,
                             std::shared_ptr<MethodBenchOptions> opt, const char *sizeHelp,
                             void (*run)(const MethodBenchOptions &)) {
    CLI::App *cmd = bench->add_subcommand(name, description);
    cmd->add_option("--size", opt->size, sizeHelp)->capture_default_str();
    cmd->add_option("--scene", opt->scene, "scene to render")->capture_default_str();
    cmd->add_option("--spp", opt->spp, "samples per pixel")->capture_default_str();
    cmd->add_option("--repeat", opt->repeats, "timed runs (after one warm-up)")
        ->capture_default_str();
    opt->device.Add(cmd);
    opt->methods.Add(cmd, name);
    cmd->callback([opt, run] { run(*opt); });
}

}  // namespace

void AddBenchCommand(CLI::App &app) {
    CLI::App *bench =
        app.add_subcommand("bench", "Speed and quality benchmarks (print figures)");
    bench->require_subcommand(1);
    AddBenchWaveletCommand(bench);
    AddBenchRenderCommand(bench);
    AddBenchAwrCommand(bench);
    AddBenchBayesCommand(bench);
    auto rhf = std::make_shared<MethodBenchOptions>();
    rhf->size = "512x512", rhf->spp = 8;
    AddBenchRenderedCommand(bench, "rhf",
                            "Time Ray Histogram Fusion on a rendered frame, per kernel", rhf,
                            "image size WxH", RunBenchRhf);
    auto pivot = std::make_shared<MethodBenchOptions>();
    pivot->size = "256x256", pivot->spp = 16;
    AddBenchRenderedCommand(bench, "pivot",
                            "Time the pivot filter on a rendered frame with all its layers\n\n"
                            "Per stage, with the mean grown radius.",
                            pivot, "image size WxH (the issue's figure: 1024x1024)",
                            RunBenchPivot);
    AddBenchQualityCommand(bench);
    AddBenchTracingCommand(bench);
    AddBenchReadCommand(bench);
    AddBenchFlickerCommand(bench);
    AddBenchRealCommand(bench);
    AddBenchAutoCommand(bench);
    AddBenchKernelsCommand(bench);
}

}  // namespace mcd::tool
