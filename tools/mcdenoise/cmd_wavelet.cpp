// `mcdenoise wavelet`: a round trip of an image through the GPU DWT, with the bands
// dumped as images on request.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "host/common/non_finite.h"
#include "host/error.h"
#include "host/io/frame.h"
#include "host/vk/gpu_image.h"
#include "host/wavelet/transform.h"
#include "tools/mcdenoise/commands.h"
#include "tools/mcdenoise/gpu_wavelet.h"
#include "tools/mcdenoise/path_guard.h"
#include "tools/mcdenoise/usage.h"

namespace mcd::tool {

WaveletRoundTrip RunWaveletRoundTrip(vk::Context &context, const Image &image,
                                     WaveletBasis basis, int levels) {
    vk::GpuImage in(context, image.width, image.height, image.channels, "image");
    vk::GpuImage coef(context, image.width, image.height, image.channels, "coefficients");
    vk::GpuImage out(context, image.width, image.height, image.channels, "reconstruction");
    in.Upload(image);
    WaveletTransform transform(context, image.width, image.height, image.channels);
    vk::Recorder recorder(context);
    transform.RecordAnalysis(recorder, basis, levels, in, coef);
    transform.RecordSynthesis(recorder, basis, levels, coef, out);
    recorder.Submit();
    WaveletRoundTrip result;
    for (const vk::DispatchTiming &t : recorder.Timings())
        (t.label.find("analyze") != std::string::npos ? result.analysisMs
                                                      : result.synthesisMs) +=
            std::max(t.gpuMs, 0.0);
    result.coefficients = coef.Download();
    result.reconstruction = out.Download();
    return result;
}

namespace {

// A procedural test image for runs without a file: a zone plate (every frequency and
// orientation) in red, hard-edged squares in green, a smooth ramp with sparse bright
// speckles in blue. "builtin:rings" or "builtin:rings@WxH" (default 512x512).
Image BuiltinImage(const std::string &spec) {
    std::string name = spec.substr(std::string("builtin:").size());
    int width = 512, height = 512;
    if (size_t at = name.find('@'); at != std::string::npos) {
        ParseSize(name.substr(at + 1), &width, &height);
        name = name.substr(0, at);
    }
    if (name != "rings")
        throw Error("unknown built-in image '" + spec + "' (builtin:rings)",
                    ErrorKind::InvalidArgument);
    if (size_t(width) * size_t(height) > (size_t(1) << 26))
        throw Error(fmt::format("built-in image of {}x{} is too large (at most 64 Mpixels)",
                                width, height),
                    ErrorKind::InvalidArgument);
    Image image(width, height, 3);
    uint32_t state = 12345;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            double u = (x + 0.5) / width - 0.5, v = (y + 0.5) / height - 0.5;
            double r2 = u * u + v * v;
            image.At(0, y, x) = float(0.5 + 0.5 * std::cos(600.0 * r2));
            image.At(1, y, x) = float((((x * 8) / width) + ((y * 8) / height)) % 2 ? 0.9 : 0.1);
            state = state * 1664525u + 1013904223u;
            bool speckle = (state >> 8) % 997 == 0;
            image.At(2, y, x) = float(0.2 + 0.6 * (u + 0.5) + (speckle ? 20.0 : 0.0));
        }
    return image;
}

// Write one band as EXR (raw coefficients) and PNG (|c| scaled so the mean is mid-grey).
void DumpBand(const std::filesystem::path &dir, const std::string &name, const Image &band) {
    io::WriteExr((dir / (name + ".exr")).string(), {{"color", &band}});
    Image magnitude = band;
    double sum = 0;
    size_t count = 0;
    for (float &v : magnitude.data) {
        v = std::fabs(v);
        if (std::isfinite(v)) sum += v, ++count;
    }
    double mean = count ? sum / count : 0;
    io::WritePng((dir / (name + ".png")).string(), magnitude,
                 mean > 0 ? float(0.25 / mean) : 1.f);
}

// One coefficient band: its file name (without extension) and its region.
struct Band {
    std::string name;
    int x0, y0, x1, y1;
};

// The bands of a `levels`-level DWT of a width x height image, as --dump writes them.
std::vector<Band> Bands(int width, int height, int levels) {
    std::vector<Band> bands;
    for (int level = 0; level < levels; ++level) {
        int lw = LevelExtent(width, level), lh = LevelExtent(height, level);
        int hw = lw > 1 ? (lw + 1) / 2 : lw, hh = lh > 1 ? (lh + 1) / 2 : lh;
        // Paper numbering: level 1 is the finest.
        std::string prefix = fmt::format("L{}_", level + 1);
        if (lw > 1) bands.push_back({prefix + "HL", hw, 0, lw, hh});
        if (lh > 1) bands.push_back({prefix + "LH", 0, hh, hw, lh});
        if (lw > 1 && lh > 1) bands.push_back({prefix + "HH", hw, hh, lw, lh});
    }
    bands.push_back({fmt::format("L{}_LL", levels), 0, 0, LevelExtent(width, levels),
                     LevelExtent(height, levels)});
    return bands;
}

void DumpBands(const std::filesystem::path &dir, const Image &coef, int levels) {
    for (const Band &b : Bands(coef.width, coef.height, levels))
        DumpBand(dir, b.name, coef.Crop(b.x0, b.y0, b.x1, b.y1));
}

struct WaveletCommandOptions {
    std::string input, output, layer = "color", basis = "cdf97", dump, nonFinite = "refuse";
    int levels = -1;
    DeviceOptions device;
};

// The first NaN/Inf value of a count, as messages name it.
std::string FirstNonFinite(const NonFiniteCount &bad) {
    return fmt::format("pixel ({}, {}), channel {}", bad.x, bad.y, bad.channel);
}

// NaN/Inf in the input, as denoise's --non-finite has it: refused (the default), or replaced
// by 0 with a warning; either way the message names the layer, the count and the first pixel.
void ApplyNonFinitePolicy(const WaveletCommandOptions &opt, Image &image) {
    const NonFiniteCount bad = CountNonFinite(image);
    if (bad.count == 0) return;
    std::string where =
        fmt::format("layer '{}' of {} has {} NaN/Inf value{}, the first at {}", opt.layer,
                    opt.input, bad.count, bad.count == 1 ? "" : "s", FirstNonFinite(bad));
    if (opt.nonFinite == "refuse")
        throw Error(fmt::format("wavelet: {} (--non-finite zero replaces them with 0)", where),
                    ErrorKind::NonFiniteInput);
    for (float &v : image.data)
        if (!std::isfinite(v)) v = 0.f;
    fmt::print(stderr, "warning: {}: replaced by 0 (--non-finite zero)\n", where);
}

// The round trip's error and times, printed.
void PrintRoundTrip(const WaveletCommandOptions &opt, const Image &image, int levels,
                    WaveletBasis basis, const WaveletRoundTrip &trip, vk::Context &context) {
    // A finite input that comes back NaN/Inf is a failure of the transform, not a figure.
    if (const NonFiniteCount bad = CountNonFinite(trip.reconstruction); bad.count)
        throw Error(
            fmt::format("wavelet: the round trip of {} gave {} NaN/Inf value{} from a "
                        "finite input, the first at {}",
                        opt.input, bad.count, bad.count == 1 ? "" : "s", FirstNonFinite(bad)),
            ErrorKind::Internal);
    double maxError = 0, maxValue = 0;
    for (size_t i = 0; i < image.Size(); ++i) {
        maxError =
            std::max(maxError, double(std::fabs(trip.reconstruction.data[i] - image.data[i])));
        maxValue = std::max(maxValue, double(std::fabs(image.data[i])));
    }
    fmt::print("{}: {}x{}x{}, {} levels of {} on {}\n", opt.input, image.width, image.height,
               image.channels, levels, WaveletName(basis), context.Info().name);
    fmt::print("  analysis {:.3f} ms, synthesis {:.3f} ms (GPU)\n", trip.analysisMs,
               trip.synthesisMs);
    fmt::print("  round trip: max |error| {:.3g}, {:.3g} of the largest |value| {:.3g}\n",
               maxError, maxValue > 0 ? maxError / maxValue : 0.0, maxValue);
}

void RunWavelet(const WaveletCommandOptions &opt) {
    std::optional<WaveletBasis> basis = ParseWavelet(opt.basis);
    if (!basis)
        throw Error("unknown wavelet basis '" + opt.basis + "' (haar, legall53, cdf97)",
                    ErrorKind::InvalidArgument);
    // Refuse bad destinations before any work.
    if (!opt.output.empty()) CheckOutputPath(opt.output, {".exr", ".png"});
    bool builtin = opt.input.rfind("builtin:", 0) == 0;
    std::vector<RolePath> inputs = {{"input", builtin ? "" : opt.input}};
    RefuseOverwritingInputs(inputs, {{"-o", opt.output}});
    if (!opt.dump.empty()) CheckDirectory(opt.dump, "--dump");
    if (!builtin) CheckInputFile(opt.input);
    Image image = builtin ? BuiltinImage(opt.input) : io::ReadImage(opt.input, opt.layer);
    ApplyNonFinitePolicy(opt, image);
    int maxLevels = MaxWaveletLevels(image.width, image.height);
    int levels = opt.levels < 0 ? maxLevels : opt.levels;
    if (levels > maxLevels)
        throw Error(fmt::format("{} levels requested; a {}x{} image allows 0..{}", levels,
                                image.width, image.height, maxLevels),
                    ErrorKind::InvalidArgument);
    // The band files --dump will write, known once the size is.
    std::vector<RolePath> outputs = {{"-o", opt.output}};
    if (!opt.dump.empty())
        for (const Band &b : Bands(image.width, image.height, levels))
            for (const char *ext : {".exr", ".png"})
                outputs.push_back(
                    {"--dump", (std::filesystem::path(opt.dump) / (b.name + ext)).string()});
    RefuseOverwritingInputs(inputs, outputs);
    vk::Context context(opt.device.ContextOptions());
    WaveletRoundTrip trip = RunWaveletRoundTrip(context, image, *basis, levels);
    PrintRoundTrip(opt, image, levels, *basis, trip, context);
    if (!opt.dump.empty()) {
        PrepareDirectory(opt.dump);
        DumpBands(opt.dump, trip.coefficients, levels);
        fmt::print("  bands written to {}\n", opt.dump);
    }
    if (!opt.output.empty()) {
        WriteImage(opt.output, trip.reconstruction);
        fmt::print("  wrote {}\n", opt.output);
    }
}

}  // namespace

void AddWaveletCommand(CLI::App &app) {
    auto opt = std::make_shared<WaveletCommandOptions>();
    CLI::App *cmd = app.add_subcommand(
        "wavelet",
        "Round-trip an image through the GPU wavelet transform and report the error\n\n"
        "Analysis, then synthesis; --dump writes every band as EXR and PNG.");
    cmd->add_option("input", opt->input,
                    "input image (EXR, PFM, HDR, PNG), or builtin:rings[@WxH] for the "
                    "procedural test image")
        ->required();
    cmd->add_option("-o,--output", opt->output, "reconstructed image (.exr or .png)");
    cmd->add_option("--layer", opt->layer, "layer of the input to transform")
        ->capture_default_str();
    cmd->add_option("--basis", opt->basis, "haar, legall53 or cdf97")->capture_default_str();
    CheckRange(cmd->add_option("--levels", opt->levels,
                               "decomposition levels (default: as many as fit)"),
               0, 64, true);
    cmd->add_option("--dump", opt->dump, "directory for the coefficient bands");
    cmd->add_option("--non-finite", opt->nonFinite,
                    "NaN/Inf input values: refuse (stop, naming the layer, the count and the "
                    "first pixel) or zero (replace them with 0 and warn so)")
        ->capture_default_str()
        ->check(CLI::IsMember({"refuse", "zero"}));
    opt->device.Add(cmd);
    cmd->callback([opt] { RunWavelet(*opt); });
}

}  // namespace mcd::tool
