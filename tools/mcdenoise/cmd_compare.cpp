// `mcdenoise compare`: the error of an image against a reference (ARCHITECTURE.md metrics).
#include <fmt/format.h>

#include <cmath>

#include "host/common/non_finite.h"
#include "host/error.h"
#include "host/io/conventions.h"
#include "host/io/frame.h"
#include "host/metrics.h"
#include "tools/mcdenoise/commands.h"

namespace mcd::tool {
namespace {

struct CompareOptions {
    std::string image, reference, layer = "color";
};

// An image or a reference with NaN/Inf values has no error to speak of (the metrics would
// call it infinite, or measure another image than the one given): refused, naming the count
// and the first in raster order (row by row, a pixel's channels together).
void RefuseNonFinite(const Image &image, const std::string &path, const std::string &layer,
                     const char *what) {
    const NonFiniteCount bad = CountNonFinite(image);
    if (bad.count)
        throw Error(
            fmt::format("{} '{}' has {} NaN/Inf value{} in layer {} (the first at pixel "
                        "({}, {}), channel {}): the error is not defined; replace them "
                        "first (denoise --non-finite zero does)",
                        what, path, bad.count, bad.count == 1 ? "" : "s", layer, bad.x, bad.y,
                        bad.channel),
            ErrorKind::NonFiniteInput);
}

// The layer of a file that compare measures: `layer` as the conventions read it, except the
// colour of a frame denoised in place. Its "color" is the noisy colour kept beside the result
// (Blender's Noisy Image, else kNoisyColorLayer: the input a denoiser wants), but the image
// the file shows, the one to measure, is the result that the reader names in
// kShownColorKey: Blender's Combined under its own name, else kDenoisedColorLayer.
std::string MeasuredLayer(const io::Frame &frame, const std::string &layer) {
    auto shown = frame.metadata.find(io::kShownColorKey);
    if (layer != "color" || shown == frame.metadata.end() || !frame.Has(shown->second))
        return layer;
    return shown->second;
}

// The image's name as the result line gives it: its path, and the layer where that is not
// the one asked for.
std::string Named(const std::string &path, const std::string &layer, const std::string &asked) {
    return layer == asked ? path : fmt::format("{} ({})", path, layer);
}

void RunCompare(const CompareOptions &opt) {
    CheckInputFile(opt.image, "image");
    CheckInputFile(opt.reference, "reference");
    io::Frame imageFrame = io::ReadFrame(opt.image);
    io::Frame referenceFrame = io::ReadFrame(opt.reference);
    const std::string imageLayer = MeasuredLayer(imageFrame, opt.layer);
    const std::string referenceLayer = MeasuredLayer(referenceFrame, opt.layer);
    const Image &image = imageFrame.Get(imageLayer);
    const Image &reference = referenceFrame.Get(referenceLayer);
    RefuseNonFinite(image, opt.image, imageLayer, "image");
    RefuseNonFinite(reference, opt.reference, referenceLayer, "reference");
    ErrorMetrics m = CompareImages(image, reference);
    fmt::print(
        "{} vs {}: relMSE {:.6g}, PSNR {:.2f} dB, SSIM {:.4f}, mean brightness {:.4f} of the "
        "reference's\n",
        Named(opt.image, imageLayer, opt.layer),
        Named(opt.reference, referenceLayer, opt.layer), m.relMse, m.psnr, m.ssim,
        m.brightness);
}

}  // namespace

void AddCompareCommand(CLI::App &app) {
    auto opt = std::make_shared<CompareOptions>();
    CLI::App *cmd = app.add_subcommand(
        "compare",
        "Error of an image against a reference: relMSE, PSNR, SSIM, mean brightness\n\n"
        "PSNR on [0, 1]-clamped sRGB values, SSIM on their luminance, the mean brightness as "
        "the image's mean linear luminance over the reference's.");
    cmd->add_option("image", opt->image, "image or frame to measure")->required();
    cmd->add_option("reference", opt->reference, "reference image or frame")->required();
    cmd->add_option("--layer", opt->layer, "layer of both files")->capture_default_str();
    cmd->callback([opt] { RunCompare(*opt); });
}

}  // namespace mcd::tool
