// `mcdenoise compare`: the error of an image against a reference (ARCHITECTURE.md metrics).
#include <fmt/format.h>

#include "host/io/frame.h"
#include "host/metrics.h"
#include "tools/mcdenoise/commands.h"

namespace mcd::tool {

void AddCompareCommand(CLI::App &app) {
    auto image = std::make_shared<std::string>(), reference = std::make_shared<std::string>();
    auto layer = std::make_shared<std::string>("color");
    CLI::App *cmd = app.add_subcommand(
        "compare", "Error of an image against a reference: relMSE, PSNR (clamped sRGB), SSIM");
    cmd->add_option("image", *image, "image or frame to measure")->required();
    cmd->add_option("reference", *reference, "reference image or frame")->required();
    cmd->add_option("--layer", *layer, "layer of both files")->capture_default_str();
    cmd->callback([image, reference, layer] {
        ErrorMetrics m =
            CompareImages(io::ReadImage(*image, *layer), io::ReadImage(*reference, *layer));
        fmt::print(
            "{} vs {}: relMSE {:.6g}, PSNR {:.2f} dB, SSIM {:.4f}{}\n", *image, *reference,
            m.relMse, m.psnr, m.ssim,
            m.nonFinite ? fmt::format(" ({} non-finite values left out)", m.nonFinite) : "");
    });
}

}  // namespace mcd::tool
