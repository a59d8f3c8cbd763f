// `mcdenoise render`: a built-in scene with the layers the methods use, as one EXR frame.
#include <fmt/format.h>
#include <unistd.h>

#include <cstdio>

#include "host/error.h"
#include "host/io/frame.h"
#include "tools/mcdenoise/commands.h"
#include "tools/render/renderer.h"

namespace mcd::tool {

void AddRenderCommand(CLI::App &app) {
    struct Options {
        std::string scene = "cornell", size = "256x256", layers, output, preview;
        int spp = 16, threads = 0;
        uint64_t seed = 1;
    };
    auto opt = std::make_shared<Options>();
    std::string names;
    for (const std::string &n : render::SceneNames()) names += (names.empty() ? "" : ", ") + n;
    CLI::App *cmd = app.add_subcommand(
        "render",
        "Render a built-in scene with the built-in path tracer into a multi-layer EXR");
    cmd->add_option("--scene", opt->scene, "scene: " + names)->capture_default_str();
    cmd->add_option("--spp", opt->spp, "samples per pixel")->capture_default_str();
    cmd->add_option("--size", opt->size, "image size WxH")->capture_default_str();
    cmd->add_option("--seed", opt->seed, "random seed (same seed, same frame)")
        ->capture_default_str();
    cmd->add_option("--layers", opt->layers,
                    "extra layer groups, comma-separated: hist (RHF histograms), split "
                    "(direct, indirect), pivot, gbuffer (albedo, normal, depth, objectId, "
                    "partId), or all; color, variance, spp, min and max are always written");
    cmd->add_option("--threads", opt->threads,
                    "threads (default: all cores; the frame is the same)");
    cmd->add_option("-o,--output", opt->output, "output EXR")->required();
    cmd->add_option("--preview", opt->preview, "also write a tonemapped PNG of the color");
    cmd->callback([opt] {
        render::RenderOptions options;
        ParseSize(opt->size, &options.width, &options.height);
        options.spp = opt->spp;
        options.seed = opt->seed;
        options.threads = opt->threads;
        options.layers = render::ParseLayerGroups(opt->layers);
        CheckOutputPath(opt->output, {".exr"});
        if (!opt->preview.empty()) CheckOutputPath(opt->preview, {".png"});
        render::Scene scene = render::BuildScene(opt->scene);
        bool terminal = isatty(fileno(stderr));
        if (terminal)
            options.progress = [&](int done, int total) {
                std::fprintf(stderr, "\rrender %s %dx%d %d spp: %3d%%", opt->scene.c_str(),
                             options.width, options.height, options.spp, 100 * done / total);
            };
        render::RenderResult result = render::Render(scene, options);
        if (terminal) std::fprintf(stderr, "\n");
        std::vector<std::pair<std::string, const Image *>> layers;
        for (const auto &[name, image] : result.layers) layers.push_back({name, &image});
        io::WriteExr(opt->output, layers, result.metadata);
        if (!opt->preview.empty()) io::WritePng(opt->preview, result.layers[0].second);
        double paths = double(options.width) * options.height * options.spp;
        fmt::print("{}: {} {}x{} at {} spp, {} layers, {:.2f} s ({:.2f} M samples/s)\n",
                   opt->output, opt->scene, options.width, options.height, options.spp,
                   result.layers.size(), result.seconds, paths / result.seconds * 1e-6);
        if (result.nonFiniteSamples)
            fmt::print("  warning: {} samples were NaN/Inf and counted as 0\n",
                       result.nonFiniteSamples);
    });
}

}  // namespace mcd::tool
