// `mcdenoise denoise --method rhf`: Ray Histogram Fusion (host/methods/rhf.h). Needs the
// colour and the histograms (Bin_0000..Bin_{3n}, the renderer's `--layers hist` or any
// renderer writing the authors' layout).
#include <fmt/format.h>

#include <memory>

#include "host/error.h"
#include "host/methods/rhf.h"
#include "tools/mcdenoise/denoise_method.h"

namespace mcd::tool {

DenoiseMethod RhfMethod() {
    auto opt = std::make_shared<RhfOptions>();
    DenoiseMethod method;
    method.name = "rhf";
    method.summary = "Ray Histogram Fusion (needs the Bin_* histogram channels)";
    method.addOptions = [opt](CLI::App *cmd) {
        cmd->add_option("--patch-half", opt->patchHalf,
                        "rhf: patch half-size w (patches are "
                        "(2w+1)^2)")
            ->capture_default_str()
            ->check(CLI::Range(0, 20));
        cmd->add_option("--search-half", opt->searchHalf,
                        "rhf: search half-window b (the window is (2b+1)^2)")
            ->capture_default_str()
            ->check(CLI::Range(0, 20));
        cmd->add_option("--kappa", opt->threshold,
                        "rhf: threshold on the normalised chi-square patch distance")
            ->capture_default_str()
            ->check(CLI::Range(0.f, 1e30f));
        cmd->add_option("--knn", opt->knn,
                        "rhf: nearest patches always averaged (finest scale)")
            ->capture_default_str()
            ->check(CLI::Range(0, 1681));
        cmd->add_option("--nscales", opt->scales,
                        "rhf: scales (fewer when a scale would be smaller than the search "
                        "window)")
            ->capture_default_str()
            ->check(CLI::Range(1, 8));
    };
    method.run = [opt](vk::Context &context, const io::Frame &frame) {
        if (!frame.Has("hist"))
            throw Error(
                fmt::format("{}: rhf needs the histogram channels Bin_0000..Bin_{{3n}} "
                            "(render with --layers hist); the frame has none",
                            frame.path));
        RhfResult rhf = RhfDenoise(context, frame.Get("color"), frame.Get("hist"), *opt);
        DenoiseResult result;
        result.image = std::move(rhf.image);
        result.plan = std::move(rhf.plan);
        result.warnings = std::move(rhf.warnings);
        result.timings = std::move(rhf.timings);
        return result;
    };
    return method;
}

}  // namespace mcd::tool
