#include "tools/mcdenoise/reference_cache.h"

#include <fmt/format.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "host/error.h"
#include "tools/mcdenoise/progress.h"
#include "tools/render/renderer.h"

namespace mcd::tool {

namespace {
constexpr uint64_t kReferenceSeed = 0x5eed5eed;
}

std::string ReferenceCachePath(const std::string &scene, int width, int height, int spp) {
    const char *xdg = std::getenv("XDG_CACHE_HOME"), *home = std::getenv("HOME");
    std::filesystem::path dir =
        xdg && *xdg ? std::filesystem::path(xdg)
                    : std::filesystem::path(home && *home ? home : "/tmp") / ".cache";
    return (dir / "mcdenoise" / "references" /
            fmt::format("{}-{}x{}-{}spp-{}.exr", scene, width, height, spp,
                        render::kRendererVersion))
        .string();
}

io::Frame CachedReference(const std::string &scene, int width, int height, int spp, int threads,
                          bool *rendered) {
    std::string cached = ReferenceCachePath(scene, width, height, spp);
    if (rendered) *rendered = false;
    if (std::filesystem::exists(cached)) return io::ReadFrame(cached);
    render::RenderOptions options;
    options.width = width, options.height = height, options.spp = spp;
    options.seed = kReferenceSeed;
    options.threads = threads;
    Progress progress(fmt::format("reference {} {}x{} at {} spp", scene, width, height, spp));
    options.progress = [&](int done, int total) { progress.Update("", done, total); };
    render::RenderResult result = render::Render(render::BuildScene(scene), options);
    progress.Done();
    if (rendered) *rendered = true;
    std::vector<std::pair<std::string, const Image *>> layers;
    for (const auto &[name, image] : result.layers) layers.push_back({name, &image});
    std::error_code ec;
    std::filesystem::create_directories(std::filesystem::path(cached).parent_path(), ec);
    try {
        io::WriteExr(cached, layers, result.metadata);
    } catch (const Error &e) {
        fmt::print("  note: reference not cached: {}\n", e.what());
    }
    io::Frame frame;
    frame.path = cached;
    frame.width = width, frame.height = height;
    frame.metadata = result.metadata;
    for (auto &[name, image] : result.layers) frame.layers[name] = std::move(image);
    return frame;
}

}  // namespace mcd::tool
