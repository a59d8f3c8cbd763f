// `mcdenoise compare`: the error of an image against a reference (ARCHITECTURE.md metrics).
#include <fmt/format.h>

#include <cmath>

#include "host/error.h"
#include "host/io/frame.h"
#include "host/metrics.h"
#include "tools/mcdenoise/commands.h"

namespace mcd::tool {
namespace {

struct CompareOptions {
    std::string image, reference, layer = "color";
};

// An image with NaN/Inf values has no error to speak of (the metrics would call it
// infinite, or measure another image than the one given): refused, naming the first.
void RefuseNonFinite(const Image &image, const std::string &path, const std::string &layer) {
    size_t count = 0;
    int first[3] = {};
    for (int c = 0; c < image.channels; ++c)
        for (int y = 0; y < image.height; ++y)
            for (int x = 0; x < image.width; ++x)
                if (!std::isfinite(image.At(c, y, x)) && count++ == 0)
                    first[0] = x, first[1] = y, first[2] = c;
    if (count)
        throw Error(
            fmt::format(
                "'{}' has {} NaN/Inf value{} in layer {} (the first at pixel ({}, {}), channel "
                "{}): its error against a reference is not defined; replace them first "
                "(denoise "
                "--non-finite zero does)",
                path, count, count == 1 ? "" : "s", layer, first[0], first[1], first[2]),
            ErrorKind::NonFiniteInput);
}

void RunCompare(const CompareOptions &opt) {
    CheckInputFile(opt.image, "image");
    CheckInputFile(opt.reference, "reference");
    Image image = io::ReadImage(opt.image, opt.layer);
    Image reference = io::ReadImage(opt.reference, opt.layer);
    RefuseNonFinite(image, opt.image, opt.layer);
    ErrorMetrics m = CompareImages(image, reference);
    fmt::print("{} vs {}: relMSE {:.6g}, PSNR {:.2f} dB, SSIM {:.4f}\n", opt.image,
               opt.reference, m.relMse, m.psnr, m.ssim);
}

}  // namespace

void AddCompareCommand(CLI::App &app) {
    auto opt = std::make_shared<CompareOptions>();
    CLI::App *cmd = app.add_subcommand(
        "compare", "Error of an image against a reference: relMSE, PSNR (clamped sRGB), SSIM");
    cmd->add_option("image", opt->image, "image or frame to measure")->required();
    cmd->add_option("reference", opt->reference, "reference image or frame")->required();
    cmd->add_option("--layer", opt->layer, "layer of both files")->capture_default_str();
    cmd->callback([opt] { RunCompare(*opt); });
}

}  // namespace mcd::tool
